// Copyright wild_mvs authors.
#include "wild_mvs/stream/drop_counter.h"

#include <algorithm>
#include <cmath>

namespace wild_mvs {
namespace {

double SteadySeconds() {
  return std::chrono::duration<double>(
             std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

}  // namespace

DropCounter::DropCounter(double throttle_seconds, double window_seconds,
                         size_t max_reasons, ClockFn clock)
    : throttle_(throttle_seconds),
      window_(window_seconds > 0 ? window_seconds : 60.0),
      max_reasons_(max_reasons < 1 ? 1 : max_reasons),
      clock_(clock ? std::move(clock) : ClockFn(SteadySeconds)) {}

void DropCounter::set_throttle(double seconds) {
  std::lock_guard<std::mutex> lock(mutex_);
  throttle_ = seconds;
}

void DropCounter::set_window(double seconds) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (seconds > 0) window_ = seconds;
}

double DropCounter::window() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return window_;
}

int64_t DropCounter::BucketOf(double t) const {
  return static_cast<int64_t>(std::floor(t / (window_ / kBuckets)));
}

// buckets[b % kBuckets] holds bucket b for the last kBuckets buckets up to
// last_bucket.
void DropCounter::Advance(Entry* e, int64_t now) {
  if (now <= e->last_bucket) return;
  if (now - e->last_bucket >= kBuckets) {
    e->buckets.fill(0);
  } else {
    for (int64_t b = e->last_bucket + 1; b <= now; ++b) e->buckets[Slot(b)] = 0;
  }
  e->last_bucket = now;
}

uint64_t DropCounter::RecentOf(const Entry& e, int64_t now) const {
  // The window is buckets (now - kBuckets, now]; the ring holds
  // (last_bucket - kBuckets, last_bucket].
  uint64_t n = 0;
  for (int64_t b = std::max(now - kBuckets + 1, e.last_bucket - kBuckets + 1);
       b <= e.last_bucket; ++b)
    n += e.buckets[Slot(b)];
  return n;
}

bool DropCounter::Count(const std::string& reason, uint64_t* count) {
  return CountMany(reason, 1, count);
}

bool DropCounter::CountMany(const std::string& reason, uint64_t n,
                            uint64_t* count) {
  std::lock_guard<std::mutex> lock(mutex_);
  const double now = clock_();
  const int64_t bucket = BucketOf(now);
  auto it = entries_.find(reason);
  if (it == entries_.end()) {
    // One slot is kept for kOtherReason.
    const std::string& key =
        entries_.size() + 1 < max_reasons_ ? reason : std::string(kOtherReason);
    it = entries_.find(key);
    if (it == entries_.end()) {
      Entry fresh;
      fresh.last_bucket = bucket;
      it = entries_.emplace(key, fresh).first;
    }
  }
  Entry& e = it->second;
  Advance(&e, bucket);
  e.count += n;
  e.buckets[Slot(bucket)] += n;
  if (count) *count = e.count;
  if (!e.logged || now - e.last_log >= throttle_) {
    e.logged = true;
    e.last_log = now;
    return true;
  }
  return false;
}

std::map<std::string, uint64_t> DropCounter::Counts() const {
  std::lock_guard<std::mutex> lock(mutex_);
  std::map<std::string, uint64_t> out;
  for (const auto& [k, e] : entries_) out[k] = e.count;
  return out;
}

std::map<std::string, uint64_t> DropCounter::Recent() const {
  std::lock_guard<std::mutex> lock(mutex_);
  const int64_t now = BucketOf(clock_());
  std::map<std::string, uint64_t> out;
  for (const auto& [k, e] : entries_) {
    const uint64_t n = RecentOf(e, now);
    if (n > 0) out[k] = n;
  }
  return out;
}

uint64_t DropCounter::Total() const {
  std::lock_guard<std::mutex> lock(mutex_);
  uint64_t n = 0;
  for (const auto& [k, e] : entries_) n += e.count;
  return n;
}

uint64_t DropCounter::RecentTotal() const {
  std::lock_guard<std::mutex> lock(mutex_);
  const int64_t now = BucketOf(clock_());
  uint64_t n = 0;
  for (const auto& [k, e] : entries_) n += RecentOf(e, now);
  return n;
}

}  // namespace wild_mvs
