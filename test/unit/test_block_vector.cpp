// Copyright wild_mvs authors. BlockVector: an append-only array in blocks.
#include <gtest/gtest.h>

#include "wild_mvs/core/block_vector.h"

namespace wild_mvs {
namespace {

TEST(BlockVector, AppendsAcrossBlocksWithStableAddresses) {
  BlockVector<int, 3> v;  // 8 elements per block
  EXPECT_TRUE(v.empty());
  EXPECT_EQ(v.bytes(), 0u);
  v.push_back(0);
  const int* first = &v[0];
  for (int i = 1; i < 21; ++i) v.push_back(i);
  ASSERT_EQ(v.size(), 21u);
  for (int i = 0; i < 21; ++i) EXPECT_EQ(v[i], i);
  EXPECT_EQ(&v[0], first);  // growing moved nothing
  v[20] = -1;
  EXPECT_EQ(v[20], -1);
  // Three blocks of 8 ints and the block table: no doubling of the size.
  EXPECT_GE(v.bytes(), 3 * 8 * sizeof(int));
  EXPECT_LT(v.bytes(), 3 * 8 * sizeof(int) + 8 * sizeof(void*));
  v.clear();
  EXPECT_TRUE(v.empty());
  EXPECT_EQ(v.bytes(), 0u);
  v.push_back(7);
  EXPECT_EQ(v[0], 7);
}

}  // namespace
}  // namespace wild_mvs
