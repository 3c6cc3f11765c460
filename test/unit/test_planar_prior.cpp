// Copyright wild_mvs authors. The planar prior (planar_prior.h) on rendered
// scenes with exact depth: a weakly textured wall under camera noise, where
// no single window can be matched but the triangles of a few known samples
// can, and two textured planes at different depths, where triangles that
// span the depth edge name planes no surface lies on. And the triangle
// test's statistic on given scores: pixels without a score are no evidence.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "patch_context_util.h"
#include "synthetic_scene.h"
#include "wild_mvs/core/planar_prior.h"
#include "wild_mvs/core/thread_pool.h"

namespace wild_mvs {
namespace {

using testing::MakeContext;
using testing::Render;
using testing::SyntheticObject;
using testing::SyntheticScene;
using testing::SyntheticSpec;

constexpr int kRef = 0;

// Cameras beside each other, all looking along +y, the reference first.
SyntheticSpec Cameras() {
  SyntheticSpec spec;
  spec.width = 240;
  spec.height = 180;
  spec.focal = 240;
  spec.num_sparse_points = 0;
  spec.camera_centers = {{0, -2, 0},
                         {0.3, -2, 0.05},
                         {-0.3, -2, -0.05},
                         {0.6, -2, -0.1},
                         {-0.6, -2, 0.1}};
  for (const Eigen::Vector3d& c : spec.camera_centers)
    spec.look_ats.push_back(c + Eigen::Vector3d(0, 2, 0));
  return spec;
}

SyntheticObject Plane(double y, double x_center, double half_width,
                      unsigned seed) {
  SyntheticObject p;
  p.center = Eigen::Vector3d(x_center, y, 0);
  p.axis_u = Eigen::Vector3d(1, 0, 0);
  p.axis_v = Eigen::Vector3d(0, 0, 1);
  p.size = Eigen::Vector3d(half_width, 3, 1);
  p.texture_seed = seed;
  p.texture_scale = 0.06;
  return p;
}

// A wall at depth 2 with 10 % of the usual albedo variation, slanted
// 30 degrees about the vertical, under noise of 0.01 (typical camera).
const SyntheticScene& WeakWall() {
  static const SyntheticScene scene = [] {
    SyntheticSpec spec = Cameras();
    SyntheticObject wall = Plane(0, 0, 4, 7);
    const double a = 30 * M_PI / 180;
    wall.axis_u = Eigen::Vector3d(std::cos(a), std::sin(a), 0);
    wall.texture_contrast = 0.1;
    spec.objects = {wall};
    spec.noise_sigma = 0.01;
    return Render(spec);
  }();
  return scene;
}

// A near plane at depth 2 on the left half, a far one at depth 3 behind.
const SyntheticScene& TwoPlanes() {
  static const SyntheticScene scene = [] {
    SyntheticSpec spec = Cameras();
    spec.objects = {Plane(0, -2, 2, 3), Plane(1, 0, 6, 5)};
    return Render(spec);
  }();
  return scene;
}

// R's map holding the exact depth at every `step`-th pixel of a grid (the
// confident samples growth found), nothing elsewhere; with their exact
// normals, or with none (as sparse points have).
DepthMap SparseMap(const SyntheticScene& s, int step,
                   bool with_normals = true) {
  DepthMap dm;
  dm.view = kRef;
  dm.camera = s.scene.views[kRef].camera;
  const cv::Mat& gt = s.depth[kRef];
  dm.depth = cv::Mat::zeros(gt.size(), CV_32F);
  dm.normal = cv::Mat::zeros(gt.size(), CV_32FC3);
  dm.confidence = cv::Mat::zeros(gt.size(), CV_32F);
  for (int y = step / 2; y < gt.rows; y += step)
    for (int x = step / 2; x < gt.cols; x += step) {
      if (!(gt.at<float>(y, x) > 0)) continue;
      dm.depth.at<float>(y, x) = gt.at<float>(y, x);
      if (with_normals)
        dm.normal.at<cv::Vec3f>(y, x) = s.normals[kRef].at<cv::Vec3f>(y, x);
      dm.confidence.at<float>(y, x) = 0.9f;
    }
  return dm;
}

struct Score {
  int filled = 0, within_1pct = 0, surface = 0;
};

Score ScoreAgainst(const SyntheticScene& s, const DepthMap& before,
                   const DepthMap& after) {
  Score sc;
  const cv::Mat& gt = s.depth[kRef];
  for (int y = 0; y < gt.rows; ++y)
    for (int x = 0; x < gt.cols; ++x) {
      const float g = gt.at<float>(y, x);
      if (g > 0) ++sc.surface;
      if (before.depth.at<float>(y, x) > 0) continue;
      const float d = after.depth.at<float>(y, x);
      if (!(d > 0)) continue;
      ++sc.filled;
      if (g > 0 && std::abs(d - g) <= 0.01f * g) ++sc.within_1pct;
    }
  return sc;
}

DepthMap Fill(const SyntheticScene& s, const DepthMap& in, const cv::Mat& mask,
              PlanarPriorStats* stats) {
  PatchContext ctx = MakeContext(s, kRef);
  ctx.ref_noise = NoiseProfile::Estimate(ctx.ref_image);
  for (PatchView& v : ctx.views) v.noise = NoiseProfile::Estimate(v.image);
  DepthMap out = in;
  out.depth = in.depth.clone();
  out.normal = in.normal.clone();
  out.confidence = in.confidence.clone();
  ThreadPool pool(2);
  FillFromPlanarPrior(ctx, MpgcOptions(), LocalViewSelectionOptions(), {}, mask,
                      &pool, &out, stats);
  return out;
}

TEST(PlanarPrior, FillsAWeaklyTexturedWallWhereNoWindowMatches) {
  const SyntheticScene& s = WeakWall();
  const DepthMap in = SparseMap(s, 24);
  PlanarPriorStats stats;
  const DepthMap out = Fill(s, in, cv::Mat(), &stats);
  const Score sc = ScoreAgainst(s, in, out);
  EXPECT_GT(stats.triangles_kept, 0);
  EXPECT_EQ(stats.samples_added, sc.filled);
  // A third of the wall at least, at the depths of the wall's plane.
  EXPECT_GT(sc.filled, 0.33 * sc.surface) << sc.filled << " of " << sc.surface;
  EXPECT_GT(sc.within_1pct, 0.99 * sc.filled);
  // The known samples stay as they were.
  for (int y = 0; y < in.height(); ++y) {
    for (int x = 0; x < in.width(); ++x) {
      if (in.depth.at<float>(y, x) > 0) {
        ASSERT_EQ(out.depth.at<float>(y, x), in.depth.at<float>(y, x));
      }
    }
  }
}

TEST(PlanarPrior, KeepsNoTriangleAcrossADepthEdge) {
  const SyntheticScene& s = TwoPlanes();
  // Triangles inside either plane are kept; the ones spanning the edge
  // (their plane cuts through the gap between the two) are not: their
  // corners' normals disagree with them.
  const DepthMap in = SparseMap(s, 16);
  const Score sc = ScoreAgainst(s, in, Fill(s, in, cv::Mat(), nullptr));
  EXPECT_GT(sc.filled, 0.6 * sc.surface);
  EXPECT_GT(sc.within_1pct, 0.999 * sc.filled)
      << sc.filled - sc.within_1pct << " wrong of " << sc.filled;
  // Corners without normals: the photo-consistency test alone rejects
  // most of them.
  const DepthMap bare = SparseMap(s, 16, false);
  PlanarPriorStats stats;
  const Score sb = ScoreAgainst(s, bare, Fill(s, bare, cv::Mat(), &stats));
  EXPECT_LT(stats.triangles_kept, stats.triangles);
  EXPECT_GT(sb.filled, 0.6 * sb.surface);
  EXPECT_GT(sb.within_1pct, 0.99 * sb.filled)
      << sb.filled - sb.within_1pct << " wrong of " << sb.filled;
}

TEST(PlanarPrior, PixelsWithoutAScoreAreNoEvidence) {
  // Eight pixels where the plane beats its shifted copies by 0.1, then
  // many the matcher could not score (PlaneScore's -1: a window without
  // texture, or seen by fewer than two views): the verdict and the score
  // are those of the eight. Counted as zero differences, the unscored
  // pixels would shrink the mean below three standard errors and pull the
  // score towards -1.
  PlaneEvidence e;
  for (int i = 0; i < 8; ++i)
    e.Add(0.8, 0.65 + 0.02 * (i % 2), 0.75 - 0.02 * (i % 2));
  ASSERT_TRUE(e.Supports());
  for (int i = 0; i < 200; ++i) {
    e.Add(-1, -1, -1);
    e.Add(0.8, -1, 0.7);  // a shifted copy without a score
    e.Add(0.8, 0.7, -1);
    e.Add(-1, 0.7, 0.7);
  }
  EXPECT_EQ(e.samples(), 8);
  EXPECT_TRUE(e.Supports());
  EXPECT_NEAR(e.MeanScore(), 0.8, 1e-12);
}

TEST(PlanarPrior, EvidenceNeedsEnoughPixelsAndAConsistentWin) {
  PlaneEvidence few;
  for (int i = 0; i < 7; ++i) few.Add(0.8, 0.7, 0.7);
  EXPECT_FALSE(few.Supports());  // 7 pixels: too few to tell
  few.Add(0.8, 0.7, 0.7);
  EXPECT_TRUE(few.Supports());
  // The plane wins on half the pixels and loses as much on the others.
  PlaneEvidence even;
  for (int i = 0; i < 48; ++i) even.Add(0.7 + (i % 2 ? 0.1 : -0.1), 0.7, 0.7);
  EXPECT_FALSE(even.Supports());
  // Wins by 0.05 on average, but spread +-0.5: within the noise.
  PlaneEvidence noisy;
  for (int i = 0; i < 48; ++i)
    noisy.Add(0.55 + (i % 2 ? 0.5 : -0.5) * 0.9, 0.5, 0.5);
  EXPECT_FALSE(noisy.Supports());
  EXPECT_EQ(PlaneEvidence().MeanScore(), -1);
}

TEST(PlanarPrior, LeavesMaskedPixelsEmpty) {
  const SyntheticScene& s = WeakWall();
  const DepthMap in = SparseMap(s, 24);
  cv::Mat mask(in.height(), in.width(), CV_8U, cv::Scalar(255));
  mask.colRange(0, in.width() / 2).setTo(0);
  const DepthMap out = Fill(s, in, mask, nullptr);
  int filled_right = 0;
  for (int y = 0; y < in.height(); ++y)
    for (int x = 0; x < in.width(); ++x) {
      const bool was = in.depth.at<float>(y, x) > 0;
      const bool is = out.depth.at<float>(y, x) > 0;
      if (x < in.width() / 2) {
        ASSERT_EQ(was, is) << x << "," << y;
      } else if (is && !was) {
        ++filled_right;
      }
    }
  EXPECT_GT(filled_right, 0);
}

}  // namespace
}  // namespace wild_mvs
