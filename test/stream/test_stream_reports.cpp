// Copyright wild_mvs authors. The depth node's stream reports: the eviction
// warning comes for new evictions only, throttled, on an injected clock;
// the texts carry the numbers.
#include <gtest/gtest.h>

#include <string>

#include "wild_mvs/stream/stream_reports.h"

namespace wild_mvs {
namespace {

struct FakeClock {
  double now = 1000.0;
  DropCounter::ClockFn Fn() {
    return [this] { return now; };
  }
};

TEST(EvictionWatch, WarnsOnNewEvictionsThrottled) {
  FakeClock clock;
  EvictionWatch w(5.0, 60.0, clock.Fn());
  EXPECT_FALSE(w.Update(0));  // none yet
  EXPECT_TRUE(w.Update(2));   // the first ones
  EXPECT_EQ(w.RecentTotal(), 2u);
  EXPECT_FALSE(w.Update(2));  // nothing new
  clock.now += 1;
  EXPECT_FALSE(w.Update(3));  // new, but within the throttle
  EXPECT_EQ(w.RecentTotal(), 3u);
  EXPECT_FALSE(w.Update(1));  // an older total changes nothing
  clock.now += 5;
  EXPECT_TRUE(w.Update(4));  // throttle passed
  EXPECT_EQ(w.RecentTotal(), 4u);
  // Recent evictions leave the window when evictions stop.
  clock.now += 200;
  EXPECT_EQ(w.RecentTotal(), 0u);
  EXPECT_FALSE(w.Update(4));
}

TEST(StreamReports, TextsCarryTheNumbers) {
  KeyframeStoreOptions store;
  store.max_keyframes = 17;
  store.max_mb = 300;
  const std::string warning = EvictionWarning(12, store, 5.0);
  EXPECT_NE(warning.find("12 keyframes so far evicted"), std::string::npos);
  EXPECT_NE(warning.find("max_keyframes = 17"), std::string::npos);
  EXPECT_NE(warning.find("max_keyframe_mb = 300"), std::string::npos);
  EXPECT_NE(warning.find("one message per 5 s"), std::string::npos);
  StreamStats s;
  s.keyframes_total = 9;
  s.reconstructed = 7;
  s.cancelled = 1;
  s.evicted_waiting = 2;
  s.resets = 3;
  EXPECT_EQ(StreamSummary(100, 4, s),
            "100 frames received, 9 keyframes, 7 depth maps (1 cancelled at "
            "shutdown), 4 frames dropped, 2 keyframes evicted before a depth "
            "map, 3 stream resets");
}

}  // namespace
}  // namespace wild_mvs
