// Copyright wild_mvs authors. Drop counts: totals, a recent window that
// empties when drops stop (so a node's WARN clears), bounded reasons, and
// the throttle of the log messages; on an injected clock.
#include <gtest/gtest.h>

#include <string>

#include "wild_mvs/stream/drop_counter.h"

namespace wild_mvs {
namespace {

struct FakeClock {
  double now = 1000.0;
  DropCounter::ClockFn Fn() {
    return [this] { return now; };
  }
};

TEST(DropCounter, RecentWindowEmptiesWhenDropsStop) {
  FakeClock clock;
  DropCounter d(5.0, 60.0, 32, clock.Fn());
  for (int i = 0; i < 10; ++i) {
    d.Count("/camera/image_raw: invalid image");
    clock.now += 1.0;
  }
  EXPECT_EQ(d.Total(), 10u);
  EXPECT_EQ(d.RecentTotal(), 10u);
  // 30 s later: all within the 60 s window still.
  clock.now += 30;
  EXPECT_EQ(d.RecentTotal(), 10u);
  // Once the window has passed the last drop, nothing recent remains; the
  // totals stay.
  clock.now += 40;
  EXPECT_LT(d.RecentTotal(), 10u);  // the oldest have left the window
  clock.now += 30;
  EXPECT_EQ(d.RecentTotal(), 0u);
  EXPECT_TRUE(d.Recent().empty());
  EXPECT_EQ(d.Total(), 10u);
  EXPECT_EQ(d.Counts().at("/camera/image_raw: invalid image"), 10u);
  // New drops count again, and only they are recent.
  d.Count("/camera/image_raw: invalid image");
  d.Count("tf: no transform");
  EXPECT_EQ(d.RecentTotal(), 2u);
  EXPECT_EQ(d.Recent().at("tf: no transform"), 1u);
  EXPECT_EQ(d.Total(), 12u);
}

TEST(DropCounter, RecentCountIsExactOverTheWindowToItsResolution) {
  FakeClock clock;
  clock.now = 0;
  DropCounter d(5.0, 12.0, 32, clock.Fn());  // 1 s buckets
  // One drop per second for 100 s: the window holds the last 12 (+- the
  // current bucket's share).
  for (int i = 0; i < 100; ++i) {
    d.Count("a");
    clock.now += 1.0;
  }
  clock.now -= 0.5;  // within the last drop's bucket
  const uint64_t recent = d.RecentTotal();
  EXPECT_GE(recent, 11u);
  EXPECT_LE(recent, 12u);
  EXPECT_EQ(d.Total(), 100u);
}

TEST(DropCounter, ReasonsAreBounded) {
  FakeClock clock;
  DropCounter d(5.0, 60.0, 4, clock.Fn());
  for (int i = 0; i < 100; ++i)
    d.Count("pose: frame_id 'frame_" + std::to_string(i) + "' is wrong");
  const auto counts = d.Counts();
  EXPECT_EQ(counts.size(), 4u);  // 3 reasons + "other problems"
  EXPECT_EQ(counts.at(DropCounter::kOtherReason), 97u);
  EXPECT_EQ(d.Total(), 100u);
  // A reason already held keeps its own key.
  d.Count("pose: frame_id 'frame_0' is wrong");
  EXPECT_EQ(d.Counts().at("pose: frame_id 'frame_0' is wrong"), 2u);
}

TEST(DropCounter, CountsManyAtOnce) {
  FakeClock clock;
  DropCounter d(5.0, 60.0, 32, clock.Fn());
  uint64_t n = 0;
  EXPECT_TRUE(d.CountMany("/camera/image_raw: roscpp queue full", 7, &n));
  EXPECT_EQ(n, 7u);
  d.Count("/camera/image_raw: roscpp queue full", &n);
  EXPECT_EQ(n, 8u);
  EXPECT_EQ(d.RecentTotal(), 8u);
}

TEST(DropCounter, ThrottlesMessagesPerReason) {
  FakeClock clock;
  DropCounter d(5.0, 60.0, 32, clock.Fn());
  uint64_t n = 0;
  EXPECT_TRUE(d.Count("a", &n));  // the first is always logged
  EXPECT_EQ(n, 1u);
  EXPECT_FALSE(d.Count("a"));
  EXPECT_TRUE(d.Count("b"));  // per reason
  clock.now += 5.0;
  EXPECT_TRUE(d.Count("a", &n));
  EXPECT_EQ(n, 3u);
  EXPECT_FALSE(d.Count("a"));
}

}  // namespace
}  // namespace wild_mvs
