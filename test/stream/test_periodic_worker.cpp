// Copyright wild_mvs authors. The nodes' output worker: periodic jobs and
// posted tasks on its own thread, tasks before due jobs, a slow job never
// stacking, Stop() satisfying every future.
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <stdexcept>
#include <thread>

#include "wild_mvs/stream/periodic_worker.h"

namespace wild_mvs {
namespace {

using namespace std::chrono_literals;

TEST(PeriodicWorker, RunsJobsPeriodicallyOnItsOwnThread) {
  PeriodicWorker w;
  std::atomic<int> runs{0};
  std::thread::id job_thread;
  w.Every(0.01, [&] {
    job_thread = std::this_thread::get_id();
    ++runs;
  });
  w.Start();
  while (runs < 5) std::this_thread::sleep_for(1ms);
  w.Stop();
  EXPECT_NE(job_thread, std::this_thread::get_id());
  const int after = runs;
  std::this_thread::sleep_for(30ms);
  EXPECT_EQ(runs, after);  // nothing after Stop
}

TEST(PeriodicWorker, PostedTasksRunAfterTheCurrentJobAndReturnResults) {
  PeriodicWorker w;
  std::atomic<bool> in_job{false}, release{false};
  std::atomic<int> job_runs{0};
  // A slow job (a mesh): holds the worker until released.
  w.Every(0.001, [&] {
    in_job = true;
    while (!release) std::this_thread::sleep_for(1ms);
    in_job = false;
    ++job_runs;
  });
  w.Start();
  while (!in_job) std::this_thread::sleep_for(1ms);
  std::atomic<bool> task_ran{false};
  std::future<void> f = w.Post([&] {
    EXPECT_FALSE(in_job);  // never during the job
    task_ran = true;
  });
  EXPECT_EQ(f.wait_for(20ms), std::future_status::timeout);  // job running
  release = true;
  f.get();
  EXPECT_TRUE(task_ran);
  // A task's exception reaches its future; the worker goes on.
  std::future<void> g = w.Post([] { throw std::runtime_error("disk full"); });
  EXPECT_THROW(g.get(), std::runtime_error);
  std::future<void> h = w.Post([] {});
  h.get();
  w.Stop();
  EXPECT_GE(job_runs, 1);
}

TEST(PeriodicWorker, ASlowJobDelaysButNeverStacks) {
  PeriodicWorker w;
  std::atomic<int> runs{0};
  // Period 1 ms, each run 20 ms: about one run per 21 ms, not a backlog.
  w.Every(0.001, [&] {
    ++runs;
    std::this_thread::sleep_for(20ms);
  });
  w.Start();
  const auto t0 = std::chrono::steady_clock::now();
  while (runs < 3) std::this_thread::sleep_for(1ms);
  w.Stop();
  const double s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0)
          .count();
  EXPECT_LE(runs, static_cast<int>(s / 0.020) + 2);
}

TEST(PeriodicWorker, TasksPostedAfterStopRunOnTheCaller) {
  PeriodicWorker w;
  w.Start();
  w.Stop();
  std::thread::id ran_on;
  w.Post([&] { ran_on = std::this_thread::get_id(); }).get();
  EXPECT_EQ(ran_on, std::this_thread::get_id());
}

}  // namespace
}  // namespace wild_mvs
