// Copyright wild_mvs authors.
#include "wild_mvs/stream/keyframe_ledger.h"

#include <chrono>
#include <cmath>
#include <iterator>

#include "wild_mvs/core/error.h"

namespace wild_mvs {

namespace {
constexpr size_t kTwiceKeysKept = 32;
}  // namespace

void KeyframeLedgerOptions::Check() const {
  Require(std::isfinite(missing_after) && missing_after > 0,
          "keyframe_missing_after = ", missing_after, " must be > 0 (s)");
  Require(max_keyframes >= 1, "keyframe_ledger_size = ", max_keyframes,
          " must be >= 1");
}

KeyframeLedger::KeyframeLedger(const KeyframeLedgerOptions& options,
                               ClockFn clock)
    : options_(options), clock_(std::move(clock)) {
  options_.Check();
  if (!clock_) {
    clock_ = [] {
      return std::chrono::duration<double>(
                 std::chrono::steady_clock::now().time_since_epoch())
          .count();
    };
  }
}

KeyframeLedger::Entry& KeyframeLedger::At(const Key& key) {
  auto [it, inserted] = entries_.try_emplace(key);
  if (inserted) {
    // Bounded: forget the oldest session and stamp (never the new entry).
    while (entries_.size() > static_cast<size_t>(options_.max_keyframes)) {
      auto oldest = entries_.begin();
      if (oldest == it) ++oldest;
      entries_.erase(oldest);
    }
  }
  return it->second;
}

void KeyframeLedger::Announce(uint64_t session_ns, uint64_t stamp_ns) {
  std::lock_guard<std::mutex> lock(mutex_);
  Entry& e = At({session_ns, stamp_ns});
  if (e.announced_at < 0) e.announced_at = clock_();
}

bool KeyframeLedger::Done(uint64_t session_ns, uint64_t stamp_ns,
                          int revision) {
  std::lock_guard<std::mutex> lock(mutex_);
  Entry& e = At({session_ns, stamp_ns});
  if (revision != 0) return true;  // a redo with better neighbours
  if (++e.first_views == 1) return true;
  ++twice_;
  if (twice_keys_.size() < kTwiceKeysKept)
    twice_keys_.push_back({session_ns, stamp_ns});
  return false;
}

void KeyframeLedger::Clear() {
  std::lock_guard<std::mutex> lock(mutex_);
  entries_.clear();
  twice_ = 0;
  twice_keys_.clear();
}

KeyframeLedger::Report KeyframeLedger::Summarize(size_t max_listed) const {
  std::lock_guard<std::mutex> lock(mutex_);
  Report r;
  const double now = clock_();
  for (const auto& [key, e] : entries_) {
    if (e.announced_at >= 0) ++r.announced;
    if (e.first_views > 0) {
      ++r.done;
    } else if (e.announced_at >= 0 &&
               now - e.announced_at > options_.missing_after) {
      ++r.missing;
      if (r.missing_keys.size() < max_listed) r.missing_keys.push_back(key);
    }
  }
  r.twice = twice_;
  for (size_t i = 0; i < twice_keys_.size() && i < max_listed; ++i)
    r.twice_keys.push_back(twice_keys_[i]);
  return r;
}

}  // namespace wild_mvs
