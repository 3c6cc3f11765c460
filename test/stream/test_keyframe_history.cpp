// Copyright wild_mvs authors. A selector's keyframe history (no ROS):
// consecutive ids of one session, bounded, found by session and id.
#include <gtest/gtest.h>

#include <string>

#include "wild_mvs/stream/keyframe_history.h"

namespace wild_mvs {
namespace {

TEST(KeyframeHistory, KeepsTheNewestConsecutiveKeyframes) {
  KeyframeHistory<std::string> h(3);
  for (uint32_t id = 0; id < 5; ++id) h.Add(7, id, "k" + std::to_string(id));
  ASSERT_EQ(h.entries().size(), 3u);
  EXPECT_EQ(h.entries().front().id, 2u);
  EXPECT_EQ(h.entries().back().value, "k4");
  ASSERT_NE(h.Find(7, 3), nullptr);
  EXPECT_EQ(*h.Find(7, 3), "k3");
  EXPECT_EQ(h.Find(7, 1), nullptr);  // left the history
  EXPECT_EQ(h.Find(8, 3), nullptr);  // another session
  EXPECT_EQ(h.capacity(), 3u);
}

TEST(KeyframeHistory, AGapOrANewSessionStartsAgain) {
  KeyframeHistory<int> h(10);
  h.Add(7, 0, 0);
  h.Add(7, 1, 1);
  h.Add(7, 3, 3);  // a gap
  ASSERT_EQ(h.entries().size(), 1u);
  EXPECT_EQ(h.entries().front().id, 3u);
  h.Add(9, 4, 4);  // another session
  ASSERT_EQ(h.entries().size(), 1u);
  EXPECT_EQ(h.entries().front().session, 9u);
  EXPECT_EQ(h.Find(7, 3), nullptr);
  KeyframeHistory<int> one(0);  // at least one is kept
  one.Add(1, 0, 5);
  EXPECT_EQ(one.entries().size(), 1u);
}

}  // namespace
}  // namespace wild_mvs
