// Copyright wild_mvs authors. A worker's keyframe sequencing (no ROS): every
// keyframe taken once and in order, gaps fetched at once, announced
// keyframes fetched after the repair delay, sessions.
#include <gtest/gtest.h>

#include <set>
#include <vector>

#include "wild_mvs/stream/keyframe_sequencer.h"

namespace wild_mvs {
namespace {

// A worker over a selector that holds keyframes `held` (ids of session
// kSession): records what it takes and what it fetched or lost.
constexpr uint64_t kSession = 1000000000ull;

struct Worker {
  KeyframeSequencer seq{1.0};
  std::set<uint32_t> held;  // what the selector can still serve
  std::vector<uint32_t> taken, fetched, lost;

  void Fetch(uint32_t end) {
    for (uint32_t id = seq.next_id(); id < end; ++id) {
      if (held.count(id)) {
        fetched.push_back(id);
        taken.push_back(id);
        seq.Taken(id);
      } else {
        lost.push_back(id);
        seq.Lost(id);
      }
    }
  }
  void Keyframe(uint32_t id, uint64_t session = kSession) {
    if (!seq.OnKeyframe(session, id)) return;
    Fetch(id);
    taken.push_back(id);
    seq.Taken(id);
  }
  void Index(uint32_t first, size_t count, double now,
             uint64_t session = kSession) {
    Fetch(seq.OnIndex(session, first, count, now));
  }
};

TEST(KeyframeSequencer, InOrderKeyframesAreTakenOnce) {
  Worker w;
  for (uint32_t id = 0; id < 5; ++id) w.Keyframe(id);
  w.Keyframe(3);  // a repeat
  EXPECT_EQ(w.taken, (std::vector<uint32_t>{0, 1, 2, 3, 4}));
  EXPECT_TRUE(w.fetched.empty());
  EXPECT_EQ(w.seq.next_id(), 5u);
  EXPECT_EQ(w.seq.session(), kSession);
}

TEST(KeyframeSequencer, AGapIsFetchedAtOnce) {
  Worker w;
  w.held = {2, 3};
  w.Keyframe(0);
  w.Keyframe(1);
  w.Keyframe(5);  // 2 and 3 fetched, 4 lost, then 5
  EXPECT_EQ(w.taken, (std::vector<uint32_t>{0, 1, 2, 3, 5}));
  EXPECT_EQ(w.fetched, (std::vector<uint32_t>{2, 3}));
  EXPECT_EQ(w.lost, (std::vector<uint32_t>{4}));
  w.Keyframe(4);  // arrives late: taken already as lost, skipped
  EXPECT_EQ(w.taken.size(), 5u);
}

TEST(KeyframeSequencer, AnnouncedKeyframesAreFetchedAfterTheRepairDelay) {
  Worker w;
  w.held = {0, 1, 2, 3};
  w.Keyframe(0);
  w.Keyframe(1);
  w.Index(0, 3, 10.0);  // announces 2 (first seen at 10 s)
  EXPECT_EQ(w.taken.size(), 2u);
  EXPECT_EQ(w.seq.announced(), 1u);
  w.Index(0, 4, 10.5);  // 2 and 3 not due yet (3 first seen now)
  EXPECT_EQ(w.taken.size(), 2u);
  w.Index(0, 4, 11.0);  // 2 is due: 2 and 3 fetched
  EXPECT_EQ(w.taken, (std::vector<uint32_t>{0, 1, 2, 3}));
  EXPECT_EQ(w.fetched, (std::vector<uint32_t>{2, 3}));
  EXPECT_EQ(w.seq.announced(), 0u);
  w.Keyframe(3);  // the late message: a repeat
  EXPECT_EQ(w.taken.size(), 4u);
  w.Index(0, 4, 20.0);  // nothing new
  EXPECT_EQ(w.taken.size(), 4u);
  EXPECT_TRUE(w.lost.empty());
}

TEST(KeyframeSequencer, ANewSessionStartsFromItsOldestAnnouncedKeyframe) {
  Worker w;
  w.Keyframe(0);
  w.Keyframe(1);
  const uint64_t next = kSession + 5;
  w.held = {3};              // of the new session
  w.Index(3, 2, 1.0, next);  // announces 3 and 4 of the next session
  w.Keyframe(4, next);       // 3 fetched first
  EXPECT_EQ(w.seq.session(), next);
  EXPECT_EQ(w.taken, (std::vector<uint32_t>{0, 1, 3, 4}));
  EXPECT_EQ(w.fetched, (std::vector<uint32_t>{3}));
  // A session none of whose keyframes arrived: fetched when due.
  Worker v;
  v.held = {7, 8};
  v.Index(7, 2, 1.0);
  EXPECT_TRUE(v.taken.empty());
  v.Index(7, 2, 2.5);
  EXPECT_EQ(v.taken, (std::vector<uint32_t>{7, 8}));
  EXPECT_EQ(v.seq.next_id(), 9u);
}

TEST(KeyframeSequencer, OnlyTheNewestOtherSessionIsRemembered) {
  Worker w;
  w.Keyframe(0);
  w.Index(0, 3, 1.0);                // 1, 2 of the current session
  w.Index(0, 2, 1.0, kSession + 1);  // a reset: 0, 1 of another
  w.Index(0, 2, 1.0, kSession + 2);  // and another: the previous one goes
  // 1, 2 of the current session and 0, 1 of the newest other one.
  EXPECT_EQ(w.seq.announced(), 4u);
  EXPECT_EQ(w.seq.OnIndex(kSession, 0, 0, 5.0), w.seq.next_id());  // empty
}

}  // namespace
}  // namespace wild_mvs
