// Copyright wild_mvs authors. Region growing under light that changes
// between views, on a rendered scene with exact ground truth: a textured
// ground with relief (bumps), two spheres, six views at distances 0.8 to
// 1.7x of each other and a near-duplicate of the second one, each lit by a
// sun from another direction or overcast, with its own exposure, white
// balance, gamma and image noise.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <opencv2/core.hpp>
#include <random>

#include "patch_context_util.h"
#include "synthetic_scene.h"
#include "wild_mvs/core/mpgc.h"
#include "wild_mvs/core/region_growing.h"

namespace wild_mvs {
namespace {

using testing::Render;
using testing::SyntheticObject;
using testing::SyntheticScene;
using testing::SyntheticSpec;
using testing::ViewLighting;

constexpr int kViews = 7;

SyntheticSpec Spec(bool changing_light) {
  using T = SyntheticObject::Type;
  SyntheticSpec s;
  s.width = 320;
  s.height = 240;
  s.focal = 300;
  s.num_sparse_points = 0;
  s.noise_sigma = 0.004;
  SyntheticObject ground;
  ground.type = T::kPlane;
  ground.center = Eigen::Vector3d(0, 0, 0);
  ground.size = Eigen::Vector3d(2.2, 2.2, 1);
  ground.texture_seed = 11;
  s.objects.push_back(ground);
  SyntheticObject ball;
  ball.type = T::kSphere;
  ball.center = Eigen::Vector3d(0.1, 0.0, 0.55);
  ball.size = Eigen::Vector3d(0.55, 0.55, 0.55);
  ball.texture_seed = 41;
  s.objects.push_back(ball);
  SyntheticObject drum;
  drum.type = T::kSphere;
  drum.center = Eigen::Vector3d(-0.8, 0.6, 0.3);
  drum.size = Eigen::Vector3d(0.3, 0.3, 0.3);
  drum.texture_seed = 43;
  s.objects.push_back(drum);
  // Relief: bumps on the ground (weak albedo texture on them, so that
  // their look is mostly their shading).
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> U(-1, 1);
  for (int k = 0; k < 90; ++k) {
    SyntheticObject bump;
    bump.type = T::kSphere;
    const double r = 0.06 + 0.04 * (U(rng) + 1);
    bump.center =
        Eigen::Vector3d(0.2 + 0.9 * U(rng), -0.5 + 0.7 * U(rng), -0.4 * r);
    bump.size = Eigen::Vector3d(r, r, r);
    bump.texture_seed = 100 + k;
    bump.texture_scale = 1.0;
    s.objects.push_back(bump);
  }
  // Six cameras 12 degrees apart at 0.8 to 1.7 times the ring's distance
  // from the scene (other image scales) and a near-duplicate of the second.
  s.camera_centers = testing::MakeRingCameras(6, 2.6, 1.5, 72);
  static const double kDist[6] = {1.0, 1.5, 0.8, 1.0, 1.7, 0.9};
  for (int k = 0; k < 6; ++k)
    s.camera_centers[k] =
        Eigen::Vector3d(0, 0, 0.35) +
        kDist[k] * (s.camera_centers[k] - Eigen::Vector3d(0, 0, 0.35));
  s.camera_centers.push_back(s.camera_centers[1] +
                             Eigen::Vector3d(0.03, -0.02, 0.01));
  s.look_at = Eigen::Vector3d(0, 0, 0.35);
  if (changing_light) {
    static const double kAz[kViews] = {0, 150, 60, 250, 110, 300, 160};
    static const double kEl[kViews] = {35, 55, 25, 45, 65, 30, 50};
    static const double kExposure[kViews] = {1.0, 0.6, 1.8, 0.8,
                                             1.3, 0.7, 0.65};
    static const double kGamma[kViews] = {1.0, 2.2, 1.5, 1.0, 1.8, 1.3, 2.2};
    static const double kWb[kViews][3] = {
        {1.0, 1.0, 1.0},   {1.2, 1.0, 0.8},  {0.8, 1.0, 1.2}, {1.1, 0.9, 1.0},
        {0.9, 1.05, 1.15}, {1.2, 1.05, 0.8}, {1.2, 1.0, 0.8}};
    // A sun from another direction in views 0, 1, 3 and 5; 2, 4 and 6 are
    // overcast (the renderer's soft default shading, the same in each).
    for (int k = 0; k < kViews; ++k) {
      ViewLighting l;
      const double az = kAz[k] * M_PI / 180, el = kEl[k] * M_PI / 180;
      if (k % 2 == 0 && k > 0)
        l.sun.setZero();
      else
        l.sun = Eigen::Vector3d(std::cos(az) * std::cos(el),
                                std::sin(az) * std::cos(el), std::sin(el));
      l.exposure = kExposure[k];
      l.gamma = kGamma[k];
      l.white_balance = Eigen::Vector3d(kWb[k][0], kWb[k][1], kWb[k][2]);
      s.lighting.push_back(l);
    }
  }
  return s;
}

const SyntheticScene& Scene(bool changing_light) {
  static const SyntheticScene* constant =
      new SyntheticScene(Render(Spec(false)));
  static const SyntheticScene* changing =
      new SyntheticScene(Render(Spec(true)));
  return changing_light ? *changing : *constant;
}

struct Growth {
  int truth = 0, within = 0, estimates = 0, off5 = 0;
  void Print(const char* what) const {
    std::printf("%-40s completeness %.3f (%d of %d), off>5%% %.4f\n", what,
                within / std::max(1.0, 1.0 * truth), within, truth,
                off5 / std::max(1.0, 1.0 * estimates));
  }
};

// Region growing in views 0 and 3 from seeds at the true depth every 16 px.
Growth Grow(const SyntheticScene& s, bool explain_test) {
  Growth g;
  for (int ref : {0, 3}) {
    PatchContext ctx = testing::MakeContext(s, ref);
    ctx.ablation.explain_test = explain_test;
    std::vector<Seed> seeds;
    for (int y = 8; y < s.depth[ref].rows; y += 16)
      for (int x = 8; x < s.depth[ref].cols; x += 16) {
        const float z = s.depth[ref].at<float>(y, x);
        if (!(z > 0)) continue;
        Seed sd;
        sd.x = x;
        sd.y = y;
        sd.depth = z;
        seeds.push_back(sd);
      }
    const int W = s.depth[ref].cols, H = s.depth[ref].rows;
    cv::Mat depth = cv::Mat::zeros(H, W, CV_32F),
            normal = cv::Mat::zeros(H, W, CV_32FC3),
            conf = cv::Mat::zeros(H, W, CV_32F);
    GrowStats st;
    GrowRegions(ctx, MpgcOptions(), LocalViewSelectionOptions(),
                RegionGrowingOptions(), seeds, cv::Mat(), nullptr, &depth,
                &normal, &conf, &st);
    for (int y = 0; y < H; ++y)
      for (int x = 0; x < W; ++x) {
        const float z = s.depth[ref].at<float>(y, x);
        const float d = depth.at<float>(y, x);
        g.truth += z > 0;
        if (!(d > 0)) continue;
        ++g.estimates;
        if (z > 0 && std::abs(d - z) < 0.01 * z) ++g.within;
        if (!(z > 0) || std::abs(d - z) > 0.05 * z) ++g.off5;
      }
  }
  return g;
}

// The explain test (ablation.explain_test, mpgc.explain_margin: unexplained
// matches keep their depth but do not expand) trades completeness for
// gross errors. Under light, noise and scale that change between views the
// gap between the views' mutual NCC and R's widens for right matches too,
// so the trade is steeper there (docs/METHODS.md, "Tried and rejected").
// This test bounds both sides of the trade: gross errors must fall, and the
// completeness it costs must stay small with constant light and bounded
// with changing light.
TEST(ChangingLight, ExplainTestTradesCompletenessForGrossErrors) {
  for (bool changing : {false, true}) {
    const SyntheticScene& s = Scene(changing);
    const Growth on = Grow(s, true), none = Grow(s, false);
    std::printf("%s light\n", changing ? "changing" : "constant");
    on.Print("defaults");
    none.Print("explain test off");
    ASSERT_GT(none.truth, 100000);
    EXPECT_GT(none.within, 0.7 * none.truth);
    // Fewer gross errors among the estimates than without the test.
    EXPECT_LT(on.off5 * static_cast<double>(none.estimates),
              0.8 * none.off5 * static_cast<double>(on.estimates));
    // The completeness it costs, in points of the ground truth: below 3.5
    // with constant light, below 6 with changing light.
    const double cost = (none.within - on.within) / (1.0 * none.truth);
    EXPECT_LT(cost, changing ? 0.06 : 0.035);
  }
}

}  // namespace
}  // namespace wild_mvs
