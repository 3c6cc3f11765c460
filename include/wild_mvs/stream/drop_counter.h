// Copyright wild_mvs authors. Counts dropped input by reason, over the whole
// run and over a recent window, and throttles the error messages about it
// (ROS-free; the nodes log what it lets through and put both counts in
// their diagnostics, so that a WARN clears once drops stop).
//
// Reasons are meant to be fixed sentences ("<topic>: invalid image"); the
// details of one drop belong in the log message. Still, at most
// `max_reasons` distinct reasons are kept: later new ones are counted under
// kOtherReason, so that diagnostics keys stay bounded whatever the input.
#pragma once

#include <array>
#include <chrono>
#include <cstdint>
#include <functional>
#include <map>
#include <mutex>
#include <string>

namespace wild_mvs {

class DropCounter {
 public:
  // Seconds on a monotonic clock (tests inject their own).
  using ClockFn = std::function<double()>;
  static constexpr const char* kOtherReason = "other problems";
  static constexpr int kBuckets = 12;  // window resolution: window / 12

  explicit DropCounter(double throttle_seconds = 5.0,
                       double window_seconds = 60.0, size_t max_reasons = 32,
                       ClockFn clock = nullptr);
  void set_throttle(double seconds);
  void set_window(double seconds);
  // Counts one drop for `reason`. Returns true when a message about this
  // reason should be logged now (the first time, then at most once per
  // throttle period per reason); *count is the total for the reason.
  bool Count(const std::string& reason, uint64_t* count = nullptr);
  // Counts n drops at once (e.g. roscpp's own queue drops since the last
  // look); the same return value.
  bool CountMany(const std::string& reason, uint64_t n,
                 uint64_t* count = nullptr);
  // Since the start, and within the last window (per reason; reasons with
  // no recent drop are left out of Recent()).
  std::map<std::string, uint64_t> Counts() const;
  std::map<std::string, uint64_t> Recent() const;
  uint64_t Total() const;
  uint64_t RecentTotal() const;
  double window() const;

 private:
  struct Entry {
    uint64_t count = 0;
    std::array<uint64_t, kBuckets> buckets{};  // drops per recent bucket
    int64_t last_bucket = 0;                   // bucket index of buckets[0..]
    double last_log = 0;
    bool logged = false;
  };
  int64_t BucketOf(double t) const;
  static size_t Slot(int64_t bucket) {
    return static_cast<size_t>(((bucket % kBuckets) + kBuckets) % kBuckets);
  }
  // Zeroes the buckets that fell out of the window by bucket `now`.
  static void Advance(Entry* e, int64_t now);
  uint64_t RecentOf(const Entry& e, int64_t now) const;

  double throttle_, window_;
  size_t max_reasons_;
  ClockFn clock_;
  mutable std::mutex mutex_;
  mutable std::map<std::string, Entry> entries_;
};

}  // namespace wild_mvs
