// Copyright wild_mvs authors. Counts dropped input by reason and throttles
// the error messages about it (ROS-free; the nodes log what it lets through).
#pragma once

#include <chrono>
#include <cstdint>
#include <map>
#include <mutex>
#include <string>

namespace wild_mvs {

class DropCounter {
 public:
  explicit DropCounter(double throttle_seconds = 5.0)
      : throttle_(throttle_seconds) {}
  // Counts one drop for `reason` ("image: bad encoding"). Returns true when
  // a message about this reason should be logged now (the first time, then
  // at most once per throttle period per reason); *count is the total for
  // the reason.
  void set_throttle(double seconds) { throttle_ = seconds; }
  bool Count(const std::string& reason, uint64_t* count = nullptr);
  std::map<std::string, uint64_t> Counts() const;
  uint64_t Total() const;

 private:
  struct Entry {
    uint64_t count = 0;
    std::chrono::steady_clock::time_point last_log{};
    bool logged = false;
  };
  double throttle_;
  mutable std::mutex mutex_;
  std::map<std::string, Entry> entries_;
};

}  // namespace wild_mvs
