// Copyright wild_mvs authors. Pairing frames with stamped inputs: exact
// stamp / latest (camera_info), waits in wall time, Stop.
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

}  // namespace
}  // namespace wild_mvs
