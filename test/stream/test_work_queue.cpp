// Copyright wild_mvs authors. The nodes' bounded input queue with its worker
// thread: arrival order, drop-oldest when full, stop.
#include <gtest/gtest.h>

#include <chrono>
#include <condition_variable>
#include <future>
#include <mutex>
#include <thread>
#include <vector>

#include "wild_mvs/stream/work_queue.h"

namespace wild_mvs {
namespace {

using namespace std::chrono_literals;

TEST(WorkQueue, ProcessesInArrivalOrder) {
  std::mutex mutex;
  std::condition_variable cv;
  std::vector<int> seen;
  WorkQueue<int> q(10, [&](int v) {
    std::lock_guard<std::mutex> lock(mutex);
    seen.push_back(v);
    cv.notify_all();
  });
  for (int i = 1; i <= 5; ++i) EXPECT_TRUE(q.Push(i));
  q.Start();
  {
    std::unique_lock<std::mutex> lock(mutex);
    ASSERT_TRUE(cv.wait_for(lock, 10s, [&] { return seen.size() == 5; }));
  }
  EXPECT_EQ(seen, (std::vector<int>{1, 2, 3, 4, 5}));
  EXPECT_EQ(q.received(), 5u);
  EXPECT_TRUE(q.Stop().empty());
}

TEST(WorkQueue, FullQueueDropsTheOldest) {
  std::vector<int> seen;
  WorkQueue<int> q(3, [&](int v) { seen.push_back(v); });  // not started
  EXPECT_TRUE(q.Push(1));
  EXPECT_TRUE(q.Push(2));
  EXPECT_TRUE(q.Push(3));
  EXPECT_FALSE(q.Push(4));  // 1 dropped
  EXPECT_FALSE(q.Push(5));  // 2 dropped
  EXPECT_EQ(q.size(), 3u);
  EXPECT_EQ(q.capacity(), 3u);
  EXPECT_EQ(q.received(), 5u);
  const std::deque<int> left = q.Stop();
  EXPECT_EQ(std::vector<int>(left.begin(), left.end()),
            (std::vector<int>{3, 4, 5}));
  EXPECT_TRUE(seen.empty());
  q.Start();  // after Stop: nothing runs
  EXPECT_TRUE(q.Push(6));
  std::this_thread::sleep_for(20ms);
  EXPECT_TRUE(seen.empty());
}

TEST(WorkQueue, StopFinishesTheCurrentItemAndReturnsTheRest) {
  std::promise<void> started;
  std::promise<void> release;
  std::shared_future<void> released = release.get_future().share();
  std::vector<int> seen;
  WorkQueue<int> q(10, [&](int v) {
    if (v == 1) {
      started.set_value();
      released.wait();
    }
    seen.push_back(v);
  });
  q.Start();
  q.Push(1);
  started.get_future().wait();  // the worker holds item 1
  q.Push(2);
  q.Push(3);
  std::thread releaser([&] {
    std::this_thread::sleep_for(200ms);
    release.set_value();
  });
  const std::deque<int> left = q.Stop();  // waits for item 1
  releaser.join();
  EXPECT_EQ(seen, (std::vector<int>{1}));
  EXPECT_EQ(std::vector<int>(left.begin(), left.end()),
            (std::vector<int>{2, 3}));
}

}  // namespace
}  // namespace wild_mvs
