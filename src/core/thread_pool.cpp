// Copyright wild_mvs authors.
#include "wild_mvs/core/thread_pool.h"

#include <atomic>
#include <exception>

#ifdef __linux__
#include <sys/resource.h>
#include <sys/syscall.h>
#include <unistd.h>
#endif

namespace wild_mvs {

ThreadPool::ThreadPool(int num_threads, Priority priority) {
  if (num_threads <= 0)
    num_threads = std::max(1u, std::thread::hardware_concurrency());
  for (int i = 0; i < num_threads; ++i)
    workers_.emplace_back([this, priority] { Loop(priority); });
}

ThreadPool::~ThreadPool() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stop_ = true;
  }
  cv_.notify_all();
  for (auto& w : workers_) w.join();
}

void ThreadPool::Loop(Priority priority) {
#ifdef __linux__
  // Per thread on Linux (the nice value of a thread id); raising it needs
  // no privilege. Failure leaves the normal priority: only slower.
  if (priority == Priority::kBackground)
    (void)setpriority(PRIO_PROCESS, static_cast<id_t>(syscall(SYS_gettid)), 19);
#else
  (void)priority;
#endif
  for (;;) {
    std::function<void()> task;
    {
      std::unique_lock<std::mutex> lock(mutex_);
      cv_.wait(lock, [this] { return stop_ || !tasks_.empty(); });
      if (stop_ && tasks_.empty()) return;
      task = std::move(tasks_.front());
      tasks_.pop();
    }
    task();
  }
}

void ThreadPool::ParallelFor(int n, const std::function<void(int)>& body) {
  if (n <= 0) return;
  std::atomic<int> next{0};
  std::exception_ptr error;
  std::mutex error_mutex;
  auto run = [&] {
    for (int i = next++; i < n; i = next++) {
      try {
        body(i);
      } catch (...) {
        std::lock_guard<std::mutex> lock(error_mutex);
        if (!error) error = std::current_exception();
      }
    }
  };
  const int helpers = std::min(n - 1, size());
  std::vector<std::future<void>> futures;
  futures.reserve(helpers);
  for (int i = 0; i < helpers; ++i) futures.push_back(Submit(run));
  run();
  for (auto& f : futures) f.wait();
  if (error) std::rethrow_exception(error);
}

}  // namespace wild_mvs
