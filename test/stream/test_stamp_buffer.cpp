// Copyright wild_mvs authors. Pairing frames with stamped inputs: exact
// stamp / latest (camera_info), nearest within a tolerance (poses), waits in
// wall time, Stop.
#include <gtest/gtest.h>

#include <chrono>
#include <string>
#include <thread>

#include "wild_mvs/stream/stamp_buffer.h"

namespace wild_mvs {
namespace {

using namespace std::chrono_literals;
using Clock = std::chrono::steady_clock;
using Exact = ExactStampBuffer<std::string>;
using Nearest = NearestStampBuffer<std::string>;

double Since(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

TEST(ExactStampBuffer, PairsByExactStampAndKeepsTheLatest) {
  Exact b(2);
  std::string v;
  EXPECT_EQ(b.WaitExact(100, 0, &v), Exact::Found::kNone);
  EXPECT_FALSE(b.WaitLatest(0, &v));
  b.Add(100, "a");
  b.Add(200, "b");
  EXPECT_EQ(b.WaitExact(200, 0, &v), Exact::Found::kYes);
  EXPECT_EQ(v, "b");
  EXPECT_EQ(b.WaitExact(150, 0, &v), Exact::Found::kOther);
  b.Add(200, "b2");  // same stamp: replaced
  EXPECT_EQ(b.WaitExact(200, 0, &v), Exact::Found::kYes);
  EXPECT_EQ(v, "b2");
  b.Add(50, "z");  // beyond capacity 2: the oldest stamp (50) goes
  EXPECT_EQ(b.size(), 2u);
  EXPECT_EQ(b.WaitExact(50, 0, &v), Exact::Found::kOther);
  EXPECT_EQ(b.WaitExact(100, 0, &v), Exact::Found::kYes);
  ASSERT_TRUE(b.WaitLatest(0, &v));
  EXPECT_EQ(v, "z");  // latest by arrival, not by stamp
}

TEST(ExactStampBuffer, WaitsForALateItemUntilTheTimeout) {
  Exact b(10);
  b.Add(1, "other");
  std::thread late([&] {
    std::this_thread::sleep_for(50ms);
    b.Add(7, "late");
  });
  std::string v;
  const auto t0 = Clock::now();
  EXPECT_EQ(b.WaitExact(7, 20.0, &v), Exact::Found::kYes);
  EXPECT_LT(Since(t0), 10.0);
  EXPECT_EQ(v, "late");
  late.join();
  const auto t1 = Clock::now();
  EXPECT_EQ(b.WaitExact(8, 0.1, &v), Exact::Found::kOther);
  EXPECT_GE(Since(t1), 0.09);
  // Stop wakes a waiter for good.
  std::thread stopper([&] {
    std::this_thread::sleep_for(50ms);
    b.Stop();
  });
  const auto t2 = Clock::now();
  EXPECT_EQ(b.WaitExact(9, 20.0, &v), Exact::Found::kOther);
  EXPECT_LT(Since(t2), 10.0);
  stopper.join();
}

TEST(NearestStampBuffer, NearestWithinTheTolerance) {
  Nearest b(3);
  std::string v;
  EXPECT_FALSE(b.WaitNearest(1000000000, 0.01, 0, &v));
  b.Add(1000000000, "t1.000");
  b.Add(1020000000, "t1.020");
  ASSERT_TRUE(b.WaitNearest(1012000000, 0.01, 0, &v));
  EXPECT_EQ(v, "t1.020");  // 8 ms away; t1.000 is 12 ms away
  ASSERT_TRUE(b.WaitNearest(1003000000, 0.01, 0, &v));
  EXPECT_EQ(v, "t1.000");
  EXPECT_FALSE(b.WaitNearest(1500000000, 0.01, 0, &v));
  b.Add(1020000000, "t1.020 again");  // same stamp, later arrival wins
  ASSERT_TRUE(b.WaitNearest(1020000000, 0.01, 0, &v));
  EXPECT_EQ(v, "t1.020 again");
  b.Add(2000000000, "t2");  // capacity 3: the first arrival goes
  EXPECT_EQ(b.size(), 3u);
  EXPECT_FALSE(b.WaitNearest(995000000, 0.006, 0, &v));
  EXPECT_DOUBLE_EQ(Nearest::Seconds(1500000000, 500000000), 1.0);
  EXPECT_NEAR(Nearest::Seconds(500000000, 1500000000), 1.0, 1e-12);
}

TEST(NearestStampBuffer, WaitsForAPoseAndStops) {
  Nearest b(10);
  std::thread late([&] {
    std::this_thread::sleep_for(50ms);
    b.Add(5000000000, "pose");
  });
  std::string v;
  const auto t0 = Clock::now();
  ASSERT_TRUE(b.WaitNearest(5001000000, 0.01, 20.0, &v));
  EXPECT_LT(Since(t0), 10.0);
  EXPECT_EQ(v, "pose");
  late.join();
  const auto t1 = Clock::now();
  EXPECT_FALSE(b.WaitNearest(9000000000, 0.01, 0.1, &v));
  EXPECT_GE(Since(t1), 0.09);
  std::thread stopper([&] {
    std::this_thread::sleep_for(50ms);
    b.Stop();
  });
  const auto t2 = Clock::now();
  EXPECT_FALSE(b.WaitNearest(9000000000, 0.01, 20.0, &v));
  EXPECT_LT(Since(t2), 10.0);
  stopper.join();
}

}  // namespace
}  // namespace wild_mvs
