// Copyright wild_mvs authors. Rescaling (paper 5.1, end): the scale ratio
// of two views from their shared features (exact on a known geometry) and
// the working resolutions it gives.
#include <gtest/gtest.h>

#include "wild_mvs/core/rescaling.h"

namespace wild_mvs {
namespace {

// Three cameras looking along +z (identity rotation), focal 500, 640x480,
// centred at z = 0 (the reference), z = -2 (farther from the scene: coarser)
// and z = 1 (nearer: finer). Points at z = 4 in front of all three.
Scene ThreeDepths() {
  Scene s;
  for (double z : {0.0, -2.0, 1.0}) {
    View v;
    v.name = std::to_string(s.views.size()) + ".png";
    v.camera.fx = v.camera.fy = 500;
    v.camera.cx = 320;
    v.camera.cy = 240;
    v.camera.width = 640;
    v.camera.height = 480;
    v.camera.t = -Eigen::Vector3d(0.1 * s.views.size(), 0, z);  // t = -R C
    s.views.push_back(v);
  }
  for (double x : {-0.5, 0.0, 0.5}) {
    SparsePoint p;
    p.xyz = Eigen::Vector3d(x, 0.2, 4);
    for (int v = 0; v < 3; ++v) p.track.push_back({v, {0, 0}, 1.0});
    s.points.push_back(p);
  }
  return s;
}

// scale_R(V) = s_R / s_V, s = depth / focal: the depth ratio here.
TEST(Rescaling, ScaleRatioIsTheFootprintRatio) {
  const Scene s = ThreeDepths();
  const auto ppv = s.PointsPerView();
  EXPECT_NEAR(ScaleRatio(s, 0, 1, ppv, nullptr), 4.0 / 6.0, 1e-12);
  EXPECT_NEAR(ScaleRatio(s, 0, 2, ppv, nullptr), 4.0 / 3.0, 1e-12);
  EXPECT_NEAR(ScaleRatio(s, 1, 0, ppv, nullptr), 6.0 / 4.0, 1e-12);
  // Without shared features: the fallback point, else 1.
  Scene bare = s;
  bare.points.clear();
  const auto none = bare.PointsPerView();
  const Eigen::Vector3d X(0, 0, 8);
  EXPECT_NEAR(ScaleRatio(bare, 0, 1, none, &X), 8.0 / 10.0, 1e-12);
  EXPECT_EQ(ScaleRatio(bare, 0, 1, none, nullptr), 1.0);
}

TEST(Rescaling, PlanDownsamplesTheReferenceAndFinerNeighbours) {
  const Scene s = ThreeDepths();
  // The coarsest neighbour at 0.3 < kRescaleMinScale: R is shrunk by
  // 0.3 / 0.6 = 0.5; the other neighbour's scale becomes 1.0 / 0.5 = 2 >
  // kRescaleMaxScale, so it is shrunk to R's scale (factor 1 / 2), while
  // the coarse one (0.3 / 0.5 = 0.6) keeps its size.
  const RescalingPlan p = PlanRescaling(s, 0, {1, 2}, {0.3, 1.0}, true, 0);
  EXPECT_NEAR(p.ref_factor, 0.5, 1e-12);
  EXPECT_EQ(p.ref_camera.width, 320);
  EXPECT_EQ(p.ref_camera.height, 240);
  EXPECT_NEAR(p.ref_camera.fx, 250, 1e-9);
  ASSERT_EQ(p.neighbor_cameras.size(), 2u);
  EXPECT_EQ(p.neighbor_cameras[0].width, 640);
  EXPECT_EQ(p.neighbor_cameras[1].width, 320);
  EXPECT_EQ(p.scales, (std::vector<double>{0.3, 1.0}));

  // At comparable scales nothing changes.
  const RescalingPlan same = PlanRescaling(s, 0, {1, 2}, {0.8, 1.1}, true, 0);
  EXPECT_EQ(same.ref_factor, 1.0);
  EXPECT_EQ(same.ref_camera.width, 640);
  EXPECT_EQ(same.neighbor_cameras[0].width, 640);
  EXPECT_EQ(same.neighbor_cameras[1].width, 640);

  // The ablation: original sizes whatever the scales.
  const RescalingPlan off = PlanRescaling(s, 0, {1, 2}, {0.3, 1.0}, false, 0);
  EXPECT_EQ(off.ref_factor, 1.0);
  EXPECT_EQ(off.neighbor_cameras[0].width, 640);
  EXPECT_EQ(off.neighbor_cameras[1].width, 640);
}

TEST(Rescaling, MaxImageSizeLimitsEveryWorkingImage) {
  const Scene s = ThreeDepths();
  const RescalingPlan p = PlanRescaling(s, 0, {1, 2}, {0.8, 1.1}, true, 320);
  EXPECT_NEAR(p.ref_factor, 0.5, 1e-12);
  EXPECT_EQ(p.ref_camera.width, 320);
  // The neighbours' scales relative to the shrunk R are 1.6 and 2.2 (above
  // kRescaleMaxScale): shrunk to R's scale, 640 / 1.6 and 640 / 2.2 wide.
  EXPECT_EQ(p.neighbor_cameras[0].width, 400);
  EXPECT_NEAR(p.neighbor_cameras[1].width, 640 / 2.2, 1);
  // Without rescaling the limit alone applies.
  const RescalingPlan off = PlanRescaling(s, 0, {1, 2}, {0.8, 1.1}, false, 320);
  EXPECT_EQ(off.ref_camera.width, 320);
  EXPECT_EQ(off.neighbor_cameras[0].width, 320);
  EXPECT_EQ(off.neighbor_cameras[1].width, 320);
}

}  // namespace
}  // namespace wild_mvs
