// Copyright wild_mvs authors. A fixed worker pool.
//
// Used over reference views and over image tiles inside one view. Tasks must
// not block on other tasks of the same pool. No global pool: owners create
// one and pass it down.
#pragma once

#include <condition_variable>
#include <functional>
#include <future>
#include <mutex>
#include <queue>
#include <thread>
#include <vector>

namespace wild_mvs {

class ThreadPool {
 public:
  // How the workers compete for the CPU with the process's other threads.
  enum class Priority {
    kNormal,
    // The lowest scheduling priority (Linux: nice 19 on each worker
    // thread; elsewhere as kNormal): work that must yield the cores to the
    // process's normal threads whenever they have work, such as a stream's
    // revisions beside its first matches.
    kBackground,
  };
  // num_threads <= 0 means std::thread::hardware_concurrency().
  explicit ThreadPool(int num_threads = 0,
                      Priority priority = Priority::kNormal);
  ~ThreadPool();
  ThreadPool(const ThreadPool&) = delete;
  ThreadPool& operator=(const ThreadPool&) = delete;

  int size() const { return static_cast<int>(workers_.size()); }

  // Queues a task; the future carries its result or exception.
  template <typename F>
  auto Submit(F&& f) -> std::future<decltype(f())> {
    using R = decltype(f());
    auto task = std::make_shared<std::packaged_task<R()>>(std::forward<F>(f));
    std::future<R> fut = task->get_future();
    {
      std::lock_guard<std::mutex> lock(mutex_);
      tasks_.emplace([task] { (*task)(); });
    }
    cv_.notify_one();
    return fut;
  }

  // Runs body(i) for i in [0, n) on the pool and the calling thread; returns
  // when all are done; rethrows the first exception. Safe to call from a
  // thread outside the pool only (the caller helps, so it never deadlocks
  // even with a one-thread pool).
  void ParallelFor(int n, const std::function<void(int)>& body);

 private:
  void Loop(Priority priority);
  std::vector<std::thread> workers_;
  std::queue<std::function<void()>> tasks_;
  std::mutex mutex_;
  std::condition_variable cv_;
  bool stop_ = false;
};

}  // namespace wild_mvs
