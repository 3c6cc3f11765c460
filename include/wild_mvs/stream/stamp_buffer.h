// Copyright wild_mvs authors. Recent stamped inputs that a frame is paired
// with (ROS-free): the depth node's camera_infos (by exact stamp, or the
// latest; the poses of a pose topic are in pose_track.h). Stamps are
// integer nanoseconds. The Wait* calls wait up to a timeout of wall time
// (steady clock, never the stream's clock, which may stand still) for a
// matching item to arrive; Stop() wakes them for good.
#pragma once

#include <chrono>
#include <condition_variable>
#include <cstddef>
#include <cstdint>
#include <map>
#include <mutex>
#include <utility>

namespace wild_mvs {

namespace stamp_buffer_detail {
inline std::chrono::steady_clock::time_point Deadline(double timeout) {
  return std::chrono::steady_clock::now() +
         std::chrono::duration_cast<std::chrono::steady_clock::duration>(
             std::chrono::duration<double>(timeout));
}
}  // namespace stamp_buffer_detail

// Items by exact stamp plus the latest one; beyond `capacity` the oldest
// stamps are forgotten. An item with a stamp already held replaces it.
template <class T>
class ExactStampBuffer {
 public:
  explicit ExactStampBuffer(size_t capacity) : capacity_(capacity) {}

  void Add(uint64_t stamp_ns, T item) {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      latest_ = item;
      have_latest_ = true;
      items_[stamp_ns] = std::move(item);
      while (items_.size() > capacity_) items_.erase(items_.begin());
    }
    cv_.notify_all();
  }

  enum class Found {
    kYes,
    kNone,   // nothing received yet
    kOther,  // items held, none with this stamp
  };
  // The item with this exact stamp, waiting up to `timeout` s for it.
  Found WaitExact(uint64_t stamp_ns, double timeout, T* out) {
    std::unique_lock<std::mutex> lock(mutex_);
    cv_.wait_until(lock, stamp_buffer_detail::Deadline(timeout),
                   [&] { return stop_ || items_.count(stamp_ns) > 0; });
    auto it = items_.find(stamp_ns);
    if (it != items_.end()) {
      *out = it->second;
      return Found::kYes;
    }
    return items_.empty() ? Found::kNone : Found::kOther;
  }
  // The latest item, waiting up to `timeout` s for a first one.
  bool WaitLatest(double timeout, T* out) {
    std::unique_lock<std::mutex> lock(mutex_);
    cv_.wait_until(lock, stamp_buffer_detail::Deadline(timeout),
                   [&] { return stop_ || have_latest_; });
    if (!have_latest_) return false;
    *out = latest_;
    return true;
  }
  void Stop() {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      stop_ = true;
    }
    cv_.notify_all();
  }
  size_t size() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return items_.size();
  }

 private:
  const size_t capacity_;
  mutable std::mutex mutex_;
  std::condition_variable cv_;
  std::map<uint64_t, T> items_;
  T latest_{};
  bool have_latest_ = false;
  bool stop_ = false;
};

}  // namespace wild_mvs
