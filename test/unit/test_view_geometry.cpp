// Copyright wild_mvs authors. Geometry of view pairs on constructed cameras
// whose frustum overlaps and axis crossings are known exactly.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "mvs_test_scenes.h"
#include "wild_mvs/core/view_geometry.h"

namespace wild_mvs {
namespace {

using testing::LookAtCamera;

// 80 x 60, focal 100, principal point at the centre, at `center` looking
// along world +z (identity rotation): the 8 x 6 sample grid of
// FrustumGridOverlap lies at pixel columns 5, 15, ..., 75.
Camera AxisCamera(const Eigen::Vector3d& center) {
  Camera c;
  c.fx = c.fy = 100;
  c.cx = 40;
  c.cy = 30;
  c.width = 80;
  c.height = 60;
  c.t = -center;
  return c;
}

TEST(FrustumGridOverlap, ViewSeesAllOfItsOwnFrustum) {
  const Camera c = AxisCamera({0, 0, 0});
  EXPECT_EQ(FrustumGridOverlap(c, c, {0.5, 1, 7}), 1.0);
}

TEST(FrustumGridOverlap, NoDepthsGiveZero) {
  const Camera c = AxisCamera({0, 0, 0});
  EXPECT_EQ(FrustumGridOverlap(c, c, {}), 0.0);
}

TEST(FrustumGridOverlap, SidewaysShiftCutsColumnsExactly) {
  // other 0.4 to the right: a point at depth z appears 100 * 0.4 / z pixels
  // further left in other's image. At z = 1 the shift is 40 px, so the 4
  // sample columns right of the centre stay inside; at z = 2 it is 20 px and
  // the 6 columns from 25 on stay.
  const Camera cam = AxisCamera({0, 0, 0});
  const Camera other = AxisCamera({0.4, 0, 0});
  EXPECT_EQ(FrustumGridOverlap(cam, other, {1.0}), 4.0 / 8);
  EXPECT_EQ(FrustumGridOverlap(cam, other, {2.0}), 6.0 / 8);
  EXPECT_EQ(FrustumGridOverlap(cam, other, {1.0, 2.0}), 10.0 / 16);
  // Seen from other, cam lies to the left: the mirror image, same counts.
  EXPECT_EQ(FrustumGridOverlap(other, cam, {1.0, 2.0}), 10.0 / 16);
}

TEST(FrustumGridOverlap, PointsBehindTheOtherViewDoNotCount) {
  // other stands 6 ahead on the same axis: samples at depth 1 and 2 are
  // behind it; those at depth 10 are 4 in front of it, 2.5x further from
  // the image centre than in cam: of the columns only 25 .. 55 (-> 2.5 ..
  // 77.5), of the rows only 25 and 35 (-> 17.5, 42.5) stay inside.
  const Camera cam = AxisCamera({0, 0, 0});
  const Camera other = AxisCamera({0, 0, 6});
  EXPECT_EQ(FrustumGridOverlap(cam, other, {1.0, 2.0}), 0.0);
  EXPECT_EQ(FrustumGridOverlap(cam, other, {10.0}), 8.0 / 48);
}

TEST(FrustumGridOverlap, OppositeViewSeesNothing) {
  Camera back = AxisCamera({0, 0, 0});
  back.R = Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitY()).toRotationMatrix();
  EXPECT_EQ(FrustumGridOverlap(AxisCamera({0, 0, 0}), back, {1.0, 3.0}), 0.0);
}

// Horizontal cameras (world z up) for the axis tests: a at (0, -3, 0)
// looking at the origin, i.e. its axis is the world y axis.
Camera A() { return LookAtCamera({0, -3, 0}, {0, 0, 0}, 100, 80, 60); }

TEST(AxesClosestApproachDepth, CrossingAxesMeetAtTheirIntersection) {
  // b's axis crosses a's at the origin, 3 from a's centre, at right angles.
  double depth = -1;
  ASSERT_TRUE(AxesClosestApproachDepth(
      A(), LookAtCamera({3, 0, 0}, {0, 0, 0}, 100, 80, 60), 0.01, &depth));
  EXPECT_NEAR(depth, 3.0, 1e-12);
  // At 45 degrees through (0, 1, 0): 4 from a's centre.
  ASSERT_TRUE(AxesClosestApproachDepth(
      A(), LookAtCamera({2, -1, 0}, {0, 1, 0}, 100, 80, 60), 0.01, &depth));
  EXPECT_NEAR(depth, 4.0, 1e-12);
}

TEST(AxesClosestApproachDepth, SkewAxesGiveTheClosestPoint) {
  // b's axis is the line (x, 0, 0.5): 0.5 above a's axis where it passes
  // x = 0, y = 0, i.e. 3 along a's axis.
  double depth = -1;
  ASSERT_TRUE(AxesClosestApproachDepth(
      A(), LookAtCamera({3, 0, 0.5}, {0, 0, 0.5}, 100, 80, 60), 0.01, &depth));
  EXPECT_NEAR(depth, 3.0, 1e-12);
}

TEST(AxesClosestApproachDepth, ParallelAxesAreRejected) {
  double depth = -1;
  EXPECT_FALSE(AxesClosestApproachDepth(
      A(), LookAtCamera({1, -3, 0}, {1, 0, 0}, 100, 80, 60), 1e-6, &depth));
  EXPECT_EQ(depth, -1);  // untouched
}

TEST(AxesClosestApproachDepth, MinSin2IsTheThreshold) {
  // Axes 30 degrees apart (sin^2 = 0.25) crossing 3 from a's centre.
  const double a30 = M_PI / 6;
  const Camera b = LookAtCamera({3 * std::sin(a30), -3 * std::cos(a30) + 3, 0},
                                {0, 3, 0}, 100, 80, 60);
  double depth = -1;
  EXPECT_FALSE(AxesClosestApproachDepth(A(), b, 0.26, &depth));
  EXPECT_EQ(depth, -1);
  ASSERT_TRUE(AxesClosestApproachDepth(A(), b, 0.24, &depth));
  EXPECT_NEAR(depth, 6.0, 1e-12);
}

TEST(AxesClosestApproachDepth, CrossingBehindEitherCentreIsRejected) {
  double depth = -1;
  // b's axis crosses a's at (0, -6, 0), 3 behind a's centre.
  EXPECT_FALSE(AxesClosestApproachDepth(
      A(), LookAtCamera({3, -6, 0}, {0, -6, 0}, 100, 80, 60), 0.01, &depth));
  // b looks away from a's axis: the crossing at the origin is behind b.
  EXPECT_FALSE(AxesClosestApproachDepth(
      A(), LookAtCamera({3, 0, 0}, {6, 0, 0}, 100, 80, 60), 0.01, &depth));
  EXPECT_EQ(depth, -1);
}

}  // namespace
}  // namespace wild_mvs
