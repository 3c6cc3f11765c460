// Copyright wild_mvs authors.
#include "wild_mvs/stream/drop_counter.h"

namespace wild_mvs {

bool DropCounter::Count(const std::string& reason, uint64_t* count) {
  std::lock_guard<std::mutex> lock(mutex_);
  Entry& e = entries_[reason];
  ++e.count;
  if (count) *count = e.count;
  const auto now = std::chrono::steady_clock::now();
  if (!e.logged ||
      std::chrono::duration<double>(now - e.last_log).count() >= throttle_) {
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

uint64_t DropCounter::Total() const {
  std::lock_guard<std::mutex> lock(mutex_);
  uint64_t n = 0;
  for (const auto& [k, e] : entries_) n += e.count;
  return n;
}

}  // namespace wild_mvs
