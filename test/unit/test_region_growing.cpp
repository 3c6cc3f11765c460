// Copyright wild_mvs authors. Region growing (paper 6.1) from one seed on
// a rendered slanted plane with exact ground truth.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

#include "mvs_test_scenes.h"
#include "patch_context_util.h"
#include "synthetic_scene.h"
#include "wild_mvs/core/region_growing.h"
#include "wild_mvs/core/thread_pool.h"

namespace wild_mvs {
namespace {

using testing::LitPlaneSpec;
using testing::MakeContext;
using testing::Render;
using testing::SyntheticScene;
using testing::SyntheticSpec;

struct GrowOutcome {
  cv::Mat depth, normal, conf;
  GrowStats stats;
  int visible = 0, filled = 0, good = 0;
  double median = 1, p95 = 1;
};

// Grows the rendered slanted plane of LitPlaneSpec (160 x 120, view 2) from
// one seed 1 % off the ground truth, scored against the exact depth.
GrowOutcome GrowPlaneFromOneSeed(const RegionGrowingOptions& options,
                                 int threads) {
  SyntheticSpec spec = LitPlaneSpec();
  spec.width = 160;
  spec.height = 120;
  spec.focal = 160;
  const SyntheticScene s = Render(spec);
  const int ref = 2;
  const PatchContext ctx = MakeContext(s, ref);
  const cv::Mat& gt = s.depth[ref];
  const int w = gt.cols, h = gt.rows;
  GrowOutcome o;
  o.depth = cv::Mat::zeros(h, w, CV_32F);
  o.normal = cv::Mat::zeros(h, w, CV_32FC3);
  o.conf = cv::Mat::zeros(h, w, CV_32F);
  const int sx = w / 2, sy = h / 2;
  std::vector<Seed> seeds{Seed{sx, sy, gt.at<float>(sy, sx) * 1.01}};
  ThreadPool pool(threads);
  GrowRegions(ctx, MpgcOptions(), LocalViewSelectionOptions(), options, seeds,
              cv::Mat(), &pool, &o.depth, &o.normal, &o.conf, &o.stats);
  EXPECT_EQ(o.stats.seeds_tried, 1);
  EXPECT_EQ(o.stats.seeds_accepted, 1);
  // Visible plane pixels far enough from the border for a 5x5 window.
  std::vector<double> errs;
  for (int y = 2; y < h - 2; ++y) {
    for (int x = 2; x < w - 2; ++x) {
      const float g = gt.at<float>(y, x);
      const float d = o.depth.at<float>(y, x);
      if (!(g > 0)) {
        EXPECT_EQ(d, 0) << "depth on the background at " << x << "," << y;
        continue;
      }
      ++o.visible;
      if (!(d > 0)) continue;
      ++o.filled;
      const double e = std::abs(d - g) / g;
      errs.push_back(e);
      if (e < 0.005) ++o.good;
      EXPECT_GT(o.conf.at<float>(y, x), 0);
    }
  }
  EXPECT_GT(o.visible, w * h / 2);
  std::sort(errs.begin(), errs.end());
  if (!errs.empty()) {
    o.median = errs[errs.size() / 2];
    o.p95 = errs[errs.size() * 95 / 100];
  }
  std::printf(
      "region growing: coverage %.3f, within 0.5%% %.3f, median rel err "
      "%.5f, p95 %.5f, %lld visits, %d phases\n",
      static_cast<double>(o.filled) / o.visible,
      static_cast<double>(o.good) / o.visible, o.median, o.p95,
      o.stats.pixel_visits, o.stats.phases);
  return o;
}

TEST(MvsRegionGrowing, FillsTexturedPlaneFromOneSeed) {
  const GrowOutcome o = GrowPlaneFromOneSeed(RegionGrowingOptions(), 2);
  EXPECT_GT(static_cast<double>(o.filled) / o.visible, 0.8);
  EXPECT_GT(static_cast<double>(o.good) / o.visible, 0.75);
  EXPECT_LT(o.median, 0.002);
}

}  // namespace
}  // namespace wild_mvs
