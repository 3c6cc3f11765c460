// Copyright wild_mvs authors. A bounded input queue with its own worker
// thread (ROS-free): the nodes' callbacks only Push, the worker hands the
// items to `process` one at a time in arrival order. When the queue is
// full, Push drops the oldest item and says so (the caller counts it), so
// a callback never waits for the processing.
#pragma once

#include <condition_variable>
#include <cstddef>
#include <cstdint>
#include <deque>
#include <functional>
#include <mutex>
#include <thread>
#include <utility>

namespace wild_mvs {

template <class T>
class WorkQueue {
 public:
  using Process = std::function<void(T)>;

  // `capacity` >= 1 items waiting. The worker starts with Start().
  WorkQueue(int capacity, Process process)
      : capacity_(capacity < 1 ? 1 : static_cast<size_t>(capacity)),
        process_(std::move(process)) {}
  ~WorkQueue() { Stop(); }
  WorkQueue(const WorkQueue&) = delete;
  WorkQueue& operator=(const WorkQueue&) = delete;

  // Starts the worker thread (once; call when `process` may run).
  void Start() {
    std::lock_guard<std::mutex> lock(mutex_);
    if (worker_.joinable() || stop_) return;
    worker_ = std::thread([this] { Run(); });
  }

  // Queues an item. Returns false when the queue was full and its oldest
  // item was dropped to make room.
  bool Push(T item) {
    bool dropped = false;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      ++received_;
      if (queue_.size() >= capacity_) {
        queue_.pop_front();
        dropped = true;
      }
      queue_.push_back(std::move(item));
    }
    cv_.notify_all();
    return !dropped;
  }

  // Stops the worker once the item it is processing is done (later items
  // are not processed) and returns the items still queued, oldest first.
  std::deque<T> Stop() {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      stop_ = true;
    }
    cv_.notify_all();
    if (worker_.joinable()) worker_.join();
    std::lock_guard<std::mutex> lock(mutex_);
    return std::exchange(queue_, {});
  }

  size_t size() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return queue_.size();
  }
  size_t capacity() const { return capacity_; }
  // Items pushed so far (dropped ones included).
  uint64_t received() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return received_;
  }

 private:
  void Run() {
    for (;;) {
      T item;
      {
        std::unique_lock<std::mutex> lock(mutex_);
        cv_.wait(lock, [this] { return stop_ || !queue_.empty(); });
        if (stop_) return;
        item = std::move(queue_.front());
        queue_.pop_front();
      }
      process_(std::move(item));
    }
  }

  const size_t capacity_;
  const Process process_;
  mutable std::mutex mutex_;
  std::condition_variable cv_;
  std::deque<T> queue_;
  uint64_t received_ = 0;
  bool stop_ = false;
  std::thread worker_;
};

}  // namespace wild_mvs
