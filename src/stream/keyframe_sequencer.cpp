// Copyright wild_mvs authors.
#include "wild_mvs/stream/keyframe_sequencer.h"

#include <algorithm>
#include <iterator>

namespace wild_mvs {

bool KeyframeSequencer::OnKeyframe(uint64_t session, uint32_t id) {
  if (!have_session_ || session != session_ns_) {
    // The selector's first or next session: from the oldest keyframe of it
    // the index listed, else from its start.
    uint32_t first = 0;
    for (const auto& [key, t] : announced_)
      if (key.first == session) {
        first = key.second;
        break;
      }
    have_session_ = true;
    session_ns_ = session;
    next_id_ = std::min(first, id);
  }
  return id >= next_id_;  // else fetched already
}

uint32_t KeyframeSequencer::OnIndex(uint64_t session, uint32_t first_id,
                                    size_t count, double now) {
  if (count == 0) return next_id_;
  const uint32_t last = first_id + static_cast<uint32_t>(count) - 1;
  const bool current = have_session_ && session == session_ns_;
  if (current && last < next_id_) return next_id_;  // nothing new
  // Keyframes of another session than the current one are remembered only
  // from the newest session announced (a bag loop or a selector reset).
  for (auto it = announced_.begin(); it != announced_.end();) {
    const bool stale = it->first.first != session &&
                       !(have_session_ && it->first.first == session_ns_);
    it = stale ? announced_.erase(it) : std::next(it);
  }
  const uint32_t from = current ? std::max(next_id_, first_id) : first_id;
  bool due = false;
  for (uint32_t id = from; id <= last; ++id) {
    const auto [it, fresh] =
        announced_.emplace(std::make_pair(session, id), now);
    if (!fresh && now - it->second >= repair_delay_) due = true;
  }
  if (!due) return next_id_;
  if (!current) {  // nothing of this session arrived in time
    have_session_ = true;
    session_ns_ = session;
    next_id_ = first_id;
  }
  return last + 1;
}

void KeyframeSequencer::Taken(uint32_t id) {
  next_id_ = id + 1;
  for (auto it = announced_.begin(); it != announced_.end();) {
    const bool done =
        it->first.first == session_ns_ && it->first.second < next_id_;
    it = done ? announced_.erase(it) : std::next(it);
  }
}

}  // namespace wild_mvs
