// Copyright wild_mvs authors.
#include "wild_mvs/stream/periodic_worker.h"

#include <algorithm>

#include "wild_mvs/core/error.h"

namespace wild_mvs {

PeriodicWorker::~PeriodicWorker() { Stop(); }

void PeriodicWorker::Every(double period, std::function<void()> job) {
  Require(period > 0, "PeriodicWorker: period ", period, " must be > 0");
  std::lock_guard<std::mutex> lock(mutex_);
  Require(!started_, "PeriodicWorker: Every() after Start()");
  Job j;
  j.period = std::chrono::duration_cast<Clock::duration>(
      std::chrono::duration<double>(period));
  j.fn = std::move(job);
  jobs_.push_back(std::move(j));
}

void PeriodicWorker::Start() {
  std::lock_guard<std::mutex> lock(mutex_);
  if (started_) return;
  started_ = true;
  const Clock::time_point now = Clock::now();
  for (Job& j : jobs_) j.due = now + j.period;
  thread_ = std::thread([this] { Run(); });
}

std::future<void> PeriodicWorker::Post(std::function<void()> task) {
  std::packaged_task<void()> t(std::move(task));
  std::future<void> f = t.get_future();
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (started_ && !stopping_) {
      tasks_.push_back(std::move(t));
      cv_.notify_all();
      return f;
    }
  }
  t();  // not running: on the caller's thread
  return f;
}

void PeriodicWorker::Stop() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (stopping_) return;
    stopping_ = true;
  }
  cv_.notify_all();
  if (thread_.joinable()) thread_.join();
  // Tasks posted while the worker stopped.
  std::deque<std::packaged_task<void()>> left;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    left.swap(tasks_);
  }
  for (auto& t : left) t();
}

void PeriodicWorker::Run() {
  std::unique_lock<std::mutex> lock(mutex_);
  while (!stopping_) {
    if (!tasks_.empty()) {
      std::packaged_task<void()> t = std::move(tasks_.front());
      tasks_.pop_front();
      lock.unlock();
      t();
      lock.lock();
      continue;
    }
    // The job due first.
    Job* next = nullptr;
    for (Job& j : jobs_)
      if (!next || j.due < next->due) next = &j;
    if (!next) {
      cv_.wait(lock, [this] { return stopping_ || !tasks_.empty(); });
      continue;
    }
    if (Clock::now() < next->due) {
      const Clock::time_point due = next->due;
      cv_.wait_until(lock, due,
                     [this] { return stopping_ || !tasks_.empty(); });
      continue;
    }
    // Due: run it, then schedule the next run a period after it ended
    // (a slow job delays, never stacks).
    std::function<void()>& fn = next->fn;
    lock.unlock();
    try {
      fn();
    } catch (...) {
      // A job reports its own errors; the worker goes on.
    }
    lock.lock();
    next->due = Clock::now() + next->period;
  }
}

}  // namespace wild_mvs
