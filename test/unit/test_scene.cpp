// Copyright wild_mvs authors. The scene: sparse points per view.
#include <gtest/gtest.h>

#include <vector>

#include "wild_mvs/core/scene.h"

namespace wild_mvs {
namespace {

// A track with two observations in one view (a repeated feature) lists the
// point once for that view: global view selection counts shared points.
TEST(Scene, PointsPerViewListsAPointOncePerView) {
  Scene scene;
  scene.views.resize(3);
  SparsePoint p;
  p.xyz = Eigen::Vector3d(0, 0, 1);
  for (int v : {0, 1, 1, 2}) {
    Observation o;
    o.view = v;
    p.track.push_back(o);
  }
  scene.points.push_back(p);
  p.track.resize(2);  // views 0, 1
  scene.points.push_back(p);
  const auto ppv = scene.PointsPerView();
  ASSERT_EQ(ppv.size(), 3u);
  EXPECT_EQ(ppv[0], (std::vector<int>{0, 1}));
  EXPECT_EQ(ppv[1], (std::vector<int>{0, 1}));
  EXPECT_EQ(ppv[2], (std::vector<int>{0}));
}

}  // namespace
}  // namespace wild_mvs
