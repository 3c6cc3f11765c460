// Copyright wild_mvs authors. A depth worker's side of the keyframe
// distribution (ROS-free; the ROS layer, ros/keyframe_link.h, carries the
// messages and calls the selector's service).
//
// A keyframe selector publishes every keyframe with consecutive ids per
// session (a session is the selector's start or reset, by its stamp in ns)
// and now and then an index of its newest keyframes (first id and count).
// A worker must take every keyframe exactly once and in order, and fetch
// the ones it missed from the selector: a gap in the ids at once, a
// keyframe the index announced that has not arrived `repair_delay` s after
// its first announcement. KeyframeSequencer decides what to take, skip and
// fetch; its caller fetches (and then reports Taken or Lost per id).
//
// Usage, for a keyframe message of (session, id):
//   if (!seq.OnKeyframe(session, id)) skip (a repeat);
//   else fetch ids [seq.next_id(), id) one by one, then take it (Taken(id)).
// For an index message: end = seq.OnIndex(session, first, count, now); fetch
// ids [seq.next_id(), end) of seq.session(). Fetching id: Taken(id) when
// the selector had it, Lost(id) when not. Not thread-safe.
#pragma once

#include <cstddef>
#include <cstdint>
#include <map>
#include <utility>

namespace wild_mvs {

class KeyframeSequencer {
 public:
  explicit KeyframeSequencer(double repair_delay)
      : repair_delay_(repair_delay) {}

  // A keyframe of `session` with `id` arrived. A new session starts from
  // the oldest keyframe of it an index listed (else from this one). False
  // when the keyframe was taken already (a repeat: skip it); else the ids
  // [next_id(), id) are to be fetched before it is taken.
  bool OnKeyframe(uint64_t session, uint32_t id);
  // An index of `session` listing ids [first_id, first_id + count), seen
  // at `now` (steady seconds). Returns the end of the ids to fetch now,
  // [next_id(), end) of session(): the ids listed that have not arrived
  // within repair_delay of their first announcement (and every id before
  // them). Returns next_id() when nothing is to be fetched. An index of a
  // session none of whose keyframes arrived in time makes it the current
  // session.
  uint32_t OnIndex(uint64_t session, uint32_t first_id, size_t count,
                   double now);
  // Keyframe `id` of session() was taken: the next one expected is id + 1,
  // and the announcements of ids before it are forgotten.
  void Taken(uint32_t id);
  // Keyframe `id` of session() is lost (the selector no longer has it):
  // the next one expected is id + 1.
  void Lost(uint32_t id) { next_id_ = id + 1; }

  uint64_t session() const { return session_ns_; }
  uint32_t next_id() const { return next_id_; }
  // Keyframes announced and neither arrived nor given up on (all sessions).
  size_t announced() const { return announced_.size(); }

 private:
  double repair_delay_;
  bool have_session_ = false;
  uint64_t session_ns_ = 0;
  uint32_t next_id_ = 0;  // the next keyframe id expected
  // First announcement (steady s) of keyframes listed by the index but not
  // arrived, by (session, id).
  std::map<std::pair<uint64_t, uint32_t>, double> announced_;
};

}  // namespace wild_mvs
