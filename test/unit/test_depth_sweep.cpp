// Copyright wild_mvs authors. The fronto-parallel depth sweep on a rendered
// scene of two planes facing the reference camera, at exact depths 2 (left
// half of the image) and 3 (right half).
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "patch_context_util.h"
#include "synthetic_scene.h"
#include "wild_mvs/core/depth_sweep.h"
#include "wild_mvs/core/error.h"
#include "wild_mvs/core/thread_pool.h"

namespace wild_mvs {
namespace {

using testing::MakeContext;
using testing::Render;
using testing::SyntheticObject;
using testing::SyntheticScene;
using testing::SyntheticSpec;

constexpr int kRef = 0;
// Depth range of the sweeps below: its depths are uniform in 1/z, so both
// plane depths are sweep samples (1/2 and 1/3 lie on the grid of 1/4 .. 1).
constexpr double kMinDepth = 1.0, kMaxDepth = 4.0;

// The reference camera at (0, -2, 0) looks along +y: the plane y = 0 lies at
// depth 2, the plane y = 1 at depth 3. The near plane covers world x in
// [-1, 0] (the left half of the reference image), the far one all of it.
// Four more cameras stand beside the reference one, up to 0.6 away.
const SyntheticScene& TwoPlanes() {
  static const SyntheticScene scene = [] {
    SyntheticSpec spec;
    spec.width = 160;
    spec.height = 120;
    spec.focal = 160;
    spec.num_sparse_points = 0;
    SyntheticObject near_plane;
    near_plane.center = Eigen::Vector3d(-0.5, 0, 0);
    near_plane.axis_u = Eigen::Vector3d(1, 0, 0);
    near_plane.axis_v = Eigen::Vector3d(0, 0, 1);
    near_plane.size = Eigen::Vector3d(0.5, 2, 1);
    near_plane.texture_seed = 3;
    SyntheticObject far_plane = near_plane;
    far_plane.center = Eigen::Vector3d(0, 1, 0);
    far_plane.size = Eigen::Vector3d(4, 3, 1);
    far_plane.texture_seed = 5;
    spec.objects = {near_plane, far_plane};
    spec.camera_centers = {{0, -2, 0},
                           {0.3, -2, 0},
                           {-0.3, -2, 0},
                           {0.6, -2, 0.1},
                           {-0.6, -2, -0.1}};
    spec.look_ats.assign(spec.camera_centers.size(), Eigen::Vector3d::Zero());
    // Every camera looks along +y, as the reference one does.
    for (size_t v = 0; v < spec.camera_centers.size(); ++v)
      spec.look_ats[v] = spec.camera_centers[v] + Eigen::Vector3d(0, 2, 0);
    return Render(spec);
  }();
  return scene;
}

std::vector<Seed> Sweep(const PatchContext& ctx, const cv::Mat& mask,
                        ThreadPool* pool, double min_depth = kMinDepth,
                        double max_depth = kMaxDepth) {
  return SweepSeeds(ctx, MpgcOptions(), LocalViewSelectionOptions(),
                    DepthSweepOptions(), min_depth, max_depth, mask, pool);
}

// Whether the ground-truth depth is the same over the (2r+1)^2 window at
// (x, y): a fronto-parallel window there lies on one plane.
bool UniformDepth(const cv::Mat& gt, int x, int y, int r) {
  const float d = gt.at<float>(y, x);
  for (int dy = -r; dy <= r; ++dy) {
    for (int dx = -r; dx <= r; ++dx) {
      const int xx = x + dx, yy = y + dy;
      if (xx < 0 || yy < 0 || xx >= gt.cols || yy >= gt.rows) return false;
      if (std::abs(gt.at<float>(yy, xx) - d) > 1e-5f * d) return false;
    }
  }
  return d > 0;
}

TEST(DepthSweep, SceneHasExactPlaneDepths) {
  const cv::Mat& gt = TwoPlanes().depth[kRef];
  EXPECT_FLOAT_EQ(gt.at<float>(60, 20), 2.0f);
  EXPECT_FLOAT_EQ(gt.at<float>(60, 140), 3.0f);
  EXPECT_FLOAT_EQ(gt.at<float>(5, 5), 2.0f);
  EXPECT_FLOAT_EQ(gt.at<float>(115, 155), 3.0f);
}

TEST(DepthSweep, RecoversBothPlaneDepthsExactly) {
  const SyntheticScene& s = TwoPlanes();
  const PatchContext ctx = MakeContext(s, kRef);
  const cv::Mat& gt = s.depth[kRef];
  const std::vector<Seed> seeds = Sweep(ctx, cv::Mat(), nullptr);
  int on_near = 0, on_far = 0;
  for (const Seed& seed : seeds) {
    ASSERT_GE(seed.x, 0);
    ASSERT_GE(seed.y, 0);
    ASSERT_LT(seed.x, gt.cols);
    ASSERT_LT(seed.y, gt.rows);
    // Away from the depth edge the sweep's best depth is the sample equal to
    // the plane's: the neighbouring samples are 2.4 % (near) and 1.6 % (far)
    // off.
    if (!UniformDepth(gt, seed.x, seed.y, 4)) continue;
    const double g = gt.at<float>(seed.y, seed.x);
    EXPECT_NEAR(seed.depth, g, 1e-6 * g) << "at " << seed.x << "," << seed.y;
    (g < 2.5 ? on_near : on_far)++;
  }
  // 20 x 15 grid points, half of them on each plane; a few lie at the depth
  // edge or too close to the border for the window.
  EXPECT_GE(on_near, 100);
  EXPECT_GE(on_far, 100);
}

TEST(DepthSweep, SeedsOnlyInsideTheMask) {
  const SyntheticScene& s = TwoPlanes();
  const PatchContext ctx = MakeContext(s, kRef);
  const int w = s.depth[kRef].cols, h = s.depth[kRef].rows;
  cv::Mat mask = cv::Mat::zeros(h, w, CV_8U);
  mask(cv::Rect(w / 2, 0, w - w / 2, h)).setTo(255);
  const std::vector<Seed> seeds = Sweep(ctx, mask, nullptr);
  ASSERT_FALSE(seeds.empty());
  for (const Seed& seed : seeds) EXPECT_GE(seed.x, w / 2);
  // Without the mask the left half is seeded too.
  int left = 0;
  for (const Seed& seed : Sweep(ctx, cv::Mat(), nullptr))
    left += seed.x < w / 2;
  EXPECT_GT(left, 0);
}

TEST(DepthSweep, ParallelSweepEqualsSerialSweep) {
  const SyntheticScene& s = TwoPlanes();
  const PatchContext ctx = MakeContext(s, kRef);
  const std::vector<Seed> serial = Sweep(ctx, cv::Mat(), nullptr);
  ThreadPool pool(2);
  double cpu = 0;
  const std::vector<Seed> parallel = SweepSeeds(
      ctx, MpgcOptions(), LocalViewSelectionOptions(), DepthSweepOptions(),
      kMinDepth, kMaxDepth, cv::Mat(), &pool, &cpu);
  ASSERT_EQ(serial.size(), parallel.size());
  for (size_t i = 0; i < serial.size(); ++i) {
    EXPECT_EQ(serial[i].x, parallel[i].x);
    EXPECT_EQ(serial[i].y, parallel[i].y);
    EXPECT_EQ(serial[i].depth, parallel[i].depth);
  }
  EXPECT_GE(cpu, 0);
}

TEST(DepthSweep, RangeWithoutTheSurfaceGivesFewSeeds) {
  // Depths 4 .. 8 all lie behind both planes: only chance matches of the
  // texture pass the score threshold, far fewer than where the range holds
  // the planes (there nearly every one of the 300 grid points).
  const SyntheticScene& s = TwoPlanes();
  const PatchContext ctx = MakeContext(s, kRef);
  const size_t right = Sweep(ctx, cv::Mat(), nullptr).size();
  const size_t wrong = Sweep(ctx, cv::Mat(), nullptr, 4.0, 8.0).size();
  EXPECT_GE(right, 250u);
  EXPECT_LT(wrong, right / 4);
}

TEST(DepthSweep, EmptyRangeOrNoViewsGiveNoSeeds) {
  const SyntheticScene& s = TwoPlanes();
  const PatchContext ctx = MakeContext(s, kRef);
  EXPECT_TRUE(Sweep(ctx, cv::Mat(), nullptr, 0.0, 4.0).empty());
  EXPECT_TRUE(Sweep(ctx, cv::Mat(), nullptr, 2.0, 2.0).empty());
  EXPECT_TRUE(Sweep(ctx, cv::Mat(), nullptr, 3.0, 2.0).empty());
  EXPECT_TRUE(Sweep(ctx, cv::Mat(), nullptr, 1.0, NAN).empty());
  PatchContext alone;
  alone.ref_camera = ctx.ref_camera;
  alone.ref_image = ctx.ref_image;
  EXPECT_TRUE(Sweep(alone, cv::Mat(), nullptr).empty());
}

TEST(DepthSweep, CheckRejectsBelowSeedsUnderOne) {
  DepthSweepOptions o;
  EXPECT_NO_THROW(o.Check());
  o.below_seeds = 1;
  EXPECT_NO_THROW(o.Check());
  o.below_seeds = 0;
  EXPECT_THROW(o.Check(), Error);
}

}  // namespace
}  // namespace wild_mvs
