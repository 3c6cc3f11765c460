// Copyright wild_mvs authors. ThreadPool: tasks, ParallelFor, priorities.
#include <gtest/gtest.h>

#include <atomic>
#include <stdexcept>
#include <vector>

#include "wild_mvs/core/thread_pool.h"

#ifdef __linux__
#include <sys/resource.h>
#include <sys/syscall.h>
#include <unistd.h>
#endif

namespace wild_mvs {
namespace {

TEST(ThreadPool, ParallelForVisitsEveryIndexOnceAndRethrows) {
  ThreadPool pool(2);
  std::vector<std::atomic<int>> seen(1000);
  pool.ParallelFor(1000, [&seen](int i) { ++seen[i]; });
  for (const auto& s : seen) EXPECT_EQ(s.load(), 1);
  EXPECT_THROW(pool.ParallelFor(10,
                                [](int i) {
                                  if (i == 7) throw std::runtime_error("x");
                                }),
               std::runtime_error);
  EXPECT_EQ(pool.Submit([] { return 41 + 1; }).get(), 42);
}

#ifdef __linux__
// The nice value of the calling thread.
int ThreadNice() {
  errno = 0;
  return getpriority(PRIO_PROCESS, static_cast<id_t>(syscall(SYS_gettid)));
}

TEST(ThreadPool, BackgroundWorkersRunAtTheLowestPriority) {
  const int ours = ThreadNice();
  ThreadPool background(2, ThreadPool::Priority::kBackground);
  ThreadPool normal(1);
  for (int i = 0; i < 4; ++i)
    EXPECT_EQ(background.Submit(ThreadNice).get(), 19);
  EXPECT_EQ(normal.Submit(ThreadNice).get(), ours);
  EXPECT_EQ(ThreadNice(), ours);  // the caller's thread is left alone
}
#endif

}  // namespace
}  // namespace wild_mvs
