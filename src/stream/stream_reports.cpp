// Copyright wild_mvs authors.
#include "wild_mvs/stream/stream_reports.h"

#include <cstdio>

namespace wild_mvs {

EvictionWatch::EvictionWatch(double throttle_seconds, double window_seconds,
                             DropCounter::ClockFn clock)
    : counter_(throttle_seconds, window_seconds, 32, std::move(clock)) {}

bool EvictionWatch::Update(uint64_t total) {
  uint64_t seen = seen_.load();
  while (seen < total && !seen_.compare_exchange_weak(seen, total)) {
  }
  if (seen >= total) return false;  // nothing new, or another caller took it
  return counter_.CountMany("evicted", total - seen);
}

std::string EvictionWarning(uint64_t total, const KeyframeStoreOptions& store,
                            double throttle_seconds) {
  char buf[512];
  std::snprintf(
      buf, sizeof(buf),
      "keyframe store full: %lu keyframes so far evicted before their depth "
      "map (depth maps are made slower than keyframes arrive; max_keyframes "
      "= %d, max_keyframe_mb = %.0f: raise them, lower the frame rate or "
      "keyframe_min_baseline; throttled to one message per %.0f s)",
      static_cast<unsigned long>(total), store.max_keyframes, store.max_mb,
      throttle_seconds);
  return buf;
}

std::string StreamSummary(uint64_t frames_received, uint64_t frames_dropped,
                          const StreamStats& s) {
  char buf[512];
  std::snprintf(buf, sizeof(buf),
                "%lu frames received, %lu keyframes, %lu depth maps (%lu "
                "cancelled at shutdown), %lu frames dropped, %lu keyframes "
                "evicted before a depth map, %lu stream resets",
                static_cast<unsigned long>(frames_received),
                static_cast<unsigned long>(s.keyframes_total),
                static_cast<unsigned long>(s.reconstructed),
                static_cast<unsigned long>(s.cancelled),
                static_cast<unsigned long>(frames_dropped),
                static_cast<unsigned long>(s.evicted_waiting),
                static_cast<unsigned long>(s.resets));
  return buf;
}

}  // namespace wild_mvs
