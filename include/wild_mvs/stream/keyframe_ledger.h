// Copyright wild_mvs authors. Which keyframes a fusion node was told about
// (a keyframe selector's index) and which depth views it received for them
// (ROS-free).
//
// With several depth workers a keyframe may be reconstructed by none of
// them (a worker that never got it) or by two (workers that disagree on
// ownership). The ledger names both: a keyframe announced more than
// `missing_after` seconds ago without a first depth view is missing; a
// second first reconstruction (revision 0) of the same keyframe is done
// twice. Keyframes are identified by (session, stamp), both in ns, exactly
// as the messages carry them. Memory is bounded: beyond `max_keyframes` the
// oldest entries are forgotten. Thread-safe.
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <map>
#include <mutex>
#include <utility>
#include <vector>

namespace wild_mvs {

struct KeyframeLedgerOptions {
  // s (wall time) after its announcement before a keyframe without a depth
  // view counts as missing.
  double missing_after = 60.0;
  int max_keyframes = 10000;  // entries kept (the oldest are forgotten)
  void Check() const;
};

class KeyframeLedger {
 public:
  using ClockFn = std::function<double()>;  // seconds, monotonic
  explicit KeyframeLedger(const KeyframeLedgerOptions& options,
                          ClockFn clock = nullptr);

  using Key = std::pair<uint64_t, uint64_t>;  // (session ns, stamp ns)
  // A keyframe the selector made (repeats are ignored).
  void Announce(uint64_t session_ns, uint64_t stamp_ns);
  // A depth view of a keyframe: revision 0 is its first reconstruction.
  // Returns false when that keyframe had a first reconstruction already
  // (done twice).
  bool Done(uint64_t session_ns, uint64_t stamp_ns, int revision);
  void Clear();

  struct Report {
    uint64_t announced = 0;  // keyframes announced (held)
    uint64_t done = 0;       // of the keyframes held, with a depth view
    uint64_t missing = 0;    // announced, no depth view after missing_after
    uint64_t twice = 0;      // first reconstructions received twice (total)
    std::vector<Key> missing_keys, twice_keys;  // the first few of each
  };
  Report Summarize(size_t max_listed) const;

 private:
  struct Entry {
    double announced_at = -1;  // -1: never announced
    int first_views = 0;       // revision-0 views received
  };
  Entry& At(const Key& key);

  KeyframeLedgerOptions options_;
  ClockFn clock_;
  mutable std::mutex mutex_;
  std::map<Key, Entry> entries_;  // ordered by session, then stamp
  uint64_t twice_ = 0;
  std::vector<Key> twice_keys_;  // bounded
};

}  // namespace wild_mvs
