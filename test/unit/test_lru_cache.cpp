// Copyright wild_mvs authors. LruCache (core/lru_cache.h): least recently
// used first out, costs summed, pinned entries and `keep` respected.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "wild_mvs/core/lru_cache.h"

namespace wild_mvs {
namespace {

// The keys present, probed without changing the order (Contains).
std::vector<int> Present(const LruCache<int, std::string>& c,
                         std::vector<int> keys) {
  std::vector<int> out;
  for (int k : keys)
    if (c.Contains(k)) out.push_back(k);
  return out;
}

TEST(LruCache, LeastRecentlyUsedLeavesFirst) {
  LruCache<int, std::string> c;
  EXPECT_TRUE(c.Insert(1, "a", 10));
  EXPECT_TRUE(c.Insert(2, "b", 20));
  EXPECT_TRUE(c.Insert(3, "c", 30));
  EXPECT_EQ(c.size(), 3u);
  EXPECT_EQ(c.cost(), 60u);
  ASSERT_NE(c.Find(1), nullptr);  // 1 is now the most recently used
  EXPECT_EQ(*c.Find(1), "a");
  EXPECT_EQ(c.Find(4), nullptr);
  c.Evict(45);  // 2 (cost 20) goes: 40 left
  EXPECT_EQ(Present(c, {1, 2, 3}), (std::vector<int>{1, 3}));
  EXPECT_EQ(c.cost(), 40u);
  c.Evict(40);  // within budget: nothing goes
  EXPECT_EQ(c.size(), 2u);
  c.Evict(5);  // 3, then 1
  EXPECT_EQ(c.size(), 0u);
  EXPECT_EQ(c.cost(), 0u);
}

TEST(LruCache, InsertKeepsThePresentValue) {
  LruCache<int, std::string> c;
  EXPECT_TRUE(c.Insert(1, "a", 1));
  EXPECT_FALSE(c.Insert(1, "other", 5));
  EXPECT_EQ(*c.Find(1), "a");
  EXPECT_EQ(c.cost(), 1u);
  EXPECT_EQ(c.size(), 1u);
}

TEST(LruCache, KeepAndPinnedEntriesStay) {
  LruCache<int, std::string> c;
  for (int k = 1; k <= 4; ++k) c.Insert(k, std::to_string(k), 1);
  c.Evict(0, /*keep=*/1);  // only the newest stays
  EXPECT_EQ(Present(c, {1, 2, 3, 4}), (std::vector<int>{4}));
  c.Clear();
  EXPECT_EQ(c.cost(), 0u);
  for (int k = 1; k <= 4; ++k) c.Insert(k, std::to_string(k), 1);
  // 1 and 3 pinned: the others go, and the pinned stay even over budget.
  c.Evict(0, 0, [](const std::string& v) { return v == "1" || v == "3"; });
  EXPECT_EQ(Present(c, {1, 2, 3, 4}), (std::vector<int>{1, 3}));
  EXPECT_EQ(c.cost(), 2u);
  // Unpinned, the older of the two goes first.
  c.Evict(1);
  EXPECT_EQ(Present(c, {1, 2, 3, 4}), (std::vector<int>{3}));
}

TEST(LruCache, EraseAdjustsTheCost) {
  LruCache<int, std::string> c;
  c.Insert(1, "a", 7);
  c.Insert(2, "b", 5);
  c.Erase(1);
  c.Erase(9);  // absent: nothing
  EXPECT_EQ(c.cost(), 5u);
  EXPECT_EQ(Present(c, {1, 2}), (std::vector<int>{2}));
  EXPECT_TRUE(c.Insert(1, "again", 3));
  EXPECT_EQ(c.cost(), 8u);
}

}  // namespace
}  // namespace wild_mvs
