// Copyright wild_mvs authors. A keyframe selector's newest keyframes, which
// it announces in its index and serves to workers that missed them
// (ROS-free; T is what is served, e.g. the keyframe message).
//
// The history holds consecutive ids of one session: a keyframe of another
// session or one that does not follow the newest (a reset, a gap) starts
// it again. At most `capacity` keyframes are kept, the oldest leave first.
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <deque>
#include <utility>

namespace wild_mvs {

template <typename T>
class KeyframeHistory {
 public:
  struct Entry {
    uint64_t session = 0;
    uint32_t id = 0;
    T value;
  };

  explicit KeyframeHistory(size_t capacity)
      : capacity_(std::max<size_t>(capacity, 1)) {}

  void Add(uint64_t session, uint32_t id, T value) {
    if (!entries_.empty() &&
        (entries_.back().session != session || entries_.back().id + 1 != id))
      entries_.clear();
    entries_.push_back(Entry{session, id, std::move(value)});
    while (entries_.size() > capacity_) entries_.pop_front();
  }

  // The keyframe `id` of `session`, or nullptr when it is not held.
  const T* Find(uint64_t session, uint32_t id) const {
    for (const Entry& e : entries_)
      if (e.session == session && e.id == id) return &e.value;
    return nullptr;
  }

  // Oldest first: consecutive ids of one session.
  const std::deque<Entry>& entries() const { return entries_; }
  size_t capacity() const { return capacity_; }

 private:
  size_t capacity_;
  std::deque<Entry> entries_;
};

}  // namespace wild_mvs
