// Copyright wild_mvs authors. What a depth node tells its user about its
// stream, ROS-free: the throttled warning about keyframes evicted from a
// full keyframe store before their depth map was made (reconstruction is
// slower than keyframes arrive), and the summary line at the end of a run.
#pragma once

#include <atomic>
#include <cstdint>
#include <string>

#include "wild_mvs/stream/drop_counter.h"
#include "wild_mvs/stream/keyframe_store.h"
#include "wild_mvs/stream/stream_reconstructor.h"

namespace wild_mvs {

// Follows StreamStats::evicted_waiting (a running total) and says when to
// warn: the first eviction, then at most once per throttle period.
// Thread-safe.
class EvictionWatch {
 public:
  // throttle_seconds: s between warnings (>= 0); window_seconds: s over
  // which RecentTotal() counts (> 0). `clock` as DropCounter's.
  EvictionWatch(double throttle_seconds, double window_seconds,
                DropCounter::ClockFn clock = nullptr);
  // Takes the current total; true when there are evictions not seen before
  // and a warning should be logged now.
  bool Update(uint64_t total);
  // Evictions seen within the last window_seconds.
  uint64_t RecentTotal() const { return counter_.RecentTotal(); }

 private:
  std::atomic<uint64_t> seen_{0};
  DropCounter counter_;
};

// The warning of EvictionWatch: `total` evictions so far, the store's
// bounds to raise, and the throttle (s) it is repeated at most once per.
std::string EvictionWarning(uint64_t total, const KeyframeStoreOptions& store,
                            double throttle_seconds);

// The end-of-run line: frames received, keyframes, depth maps (cancelled at
// shutdown), frames dropped, keyframes evicted, stream resets.
std::string StreamSummary(uint64_t frames_received, uint64_t frames_dropped,
                          const StreamStats& stats);

}  // namespace wild_mvs
