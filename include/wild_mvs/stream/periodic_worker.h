// Copyright wild_mvs authors. One thread of its own that runs periodic jobs
// (publish the cloud, mesh it) and one-off tasks (save, reset) in order, so
// that the nodes' callback threads never do slow work or disk I/O and never
// wait on a lock that a slow job holds (ROS-free).
//
// Tasks posted with Post() run before the periodic jobs that are due; a
// periodic job runs at most once per period (a slow job delays, never
// stacks). Stop() lets the running job finish and runs nothing more; tasks
// still posted are run first (their futures are always satisfied).
#pragma once

#include <chrono>
#include <condition_variable>
#include <deque>
#include <functional>
#include <future>
#include <mutex>
#include <thread>
#include <vector>

namespace wild_mvs {

class PeriodicWorker {
 public:
  PeriodicWorker() = default;
  ~PeriodicWorker();
  PeriodicWorker(const PeriodicWorker&) = delete;
  PeriodicWorker& operator=(const PeriodicWorker&) = delete;

  // Adds a job run every `period` s (> 0) from Start() on; before Start().
  void Every(double period, std::function<void()> job);
  void Start();
  // Runs `task` on the worker thread as soon as the current job is done.
  // The future holds the task's exception, if any. After Stop() the task
  // is run on the calling thread.
  std::future<void> Post(std::function<void()> task);
  void Stop();

 private:
  using Clock = std::chrono::steady_clock;
  struct Job {
    Clock::duration period;
    Clock::time_point due;
    std::function<void()> fn;
  };
  void Run();

  std::mutex mutex_;
  std::condition_variable cv_;
  std::vector<Job> jobs_;
  std::deque<std::packaged_task<void()>> tasks_;
  bool started_ = false, stopping_ = false;
  std::thread thread_;
};

}  // namespace wild_mvs
