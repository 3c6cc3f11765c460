// Copyright wild_mvs authors. The per-view MVS driver (ReconstructView) on
// real photographs: the Middlebury templeSparseRing shipped in data/ (16
// views, 640x480, calibrated cameras, no sparse points: tracks computed
// from the known poses first, as `wild_mvs reconstruct` does). Five
// neighbouring reference views at 320x240; a sample is correct (as in
// bench/bench_depth_stats.cpp) when its 3-D point lies in the README's tight
// bounding box enlarged by 5 mm AND another of the five depth maps agrees
// with it within 0.5 % of depth. The thresholds are about 15 % below the
// values measured when the test was written (printed; comments below).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <memory>
#include <vector>

#include "test_paths.h"
#include "wild_mvs/core/image.h"
#include "wild_mvs/core/metrics.h"
#include "wild_mvs/core/reconstruct_view.h"
#include "wild_mvs/core/sparse_tracker.h"
#include "wild_mvs/core/thread_pool.h"
#include "wild_mvs/io/dataset.h"
#include "wild_mvs/io/report_json.h"

namespace wild_mvs {
namespace {

// data/templeSparseRing/README.txt
constexpr double kBox[6] = {-0.073568, 0.021728, -0.012445,
                            0.028855,  0.181892, 0.062736};
constexpr double kMargin = 0.005;
constexpr double kConsistency = 0.005;

struct Counts {
  int samples = 0, in_box = 0, consistent = 0, correct = 0;
};

Counts Evaluate(const std::vector<DepthMap>& maps, size_t mi) {
  const DepthMap& dm = maps[mi];
  Counts c;
  for (int y = 0; y < dm.height(); ++y) {
    for (int x = 0; x < dm.width(); ++x) {
      const float d = dm.depth.at<float>(y, x);
      if (!(d > 0)) continue;
      ++c.samples;
      const Eigen::Vector3d X =
          dm.camera.Backproject(Eigen::Vector2d(x + 0.5, y + 0.5), d);
      bool inside = true;
      for (int k = 0; k < 3; ++k)
        inside = inside && X[k] >= kBox[k] - kMargin &&
                 X[k] <= kBox[k + 3] + kMargin;
      bool agree = false;
      for (size_t oj = 0; oj < maps.size() && !agree; ++oj)
        agree = oj != mi && AgreesWithDepthMap(X, maps[oj], kConsistency);
      if (inside) ++c.in_box;
      if (agree) ++c.consistent;
      if (inside && agree) ++c.correct;
    }
  }
  return c;
}

TEST(MvsRealTemple, FiveViewsCorrectSamples) {
  DatasetOptions dopt;
  dopt.path = testing::SourceDir() + "/data/templeSparseRing";
  dopt.format = DatasetFormat::kMiddlebury;
  Scene scene = LoadDataset(dopt);
  ASSERT_EQ(scene.views.size(), 16u);
  ASSERT_TRUE(scene.points.empty());
  ImageOptions iopt;
  ImageCache cache(MakeSceneLoader(scene, iopt), 256);
  ThreadPool pool(2);
  // Tracks from the known poses, as `wild_mvs reconstruct` computes them.
  TrackerStats stats;
  scene.points =
      ComputeSparseTracks(scene, cache, TrackerOptions(), &pool, &stats);
  std::printf("sparse: %zu points from %lld features\n", scene.points.size(),
              static_cast<long long>(stats.features));
  EXPECT_GT(scene.points.size(), 2500u);  // measured 3051
  MvsOptions options;
  options.max_image_size = 320;
  // Neighbouring views on the ring, so that their maps overlap.
  const std::vector<int> refs = {3, 4, 5, 6, 7};
  std::vector<DepthMap> maps;
  for (int ref : refs) {
    ViewReport rep;
    maps.push_back(ReconstructView(scene, ref, cache, options, &pool, &rep));
    EXPECT_EQ(maps.back().width(), 320);
    EXPECT_EQ(maps.back().height(), 240);
    EXPECT_GE(rep.neighbors.size(), 2u);
    std::printf("view %s: %d samples, %d of %d seeds, %.1f s; %s\n",
                scene.views[ref].Stem().c_str(), rep.samples,
                rep.seeds_accepted, rep.seeds_tried, rep.seconds,
                ViewReportJson(rep, scene).c_str());
  }
  Counts total;
  for (size_t i = 0; i < maps.size(); ++i) {
    const Counts c = Evaluate(maps, i);
    const double frac = c.samples ? double(c.correct) / c.samples : 0;
    std::printf(
        "view %s: samples %d in_box %d consistent %d correct %d (%.3f)\n",
        scene.views[refs[i]].Stem().c_str(), c.samples, c.in_box, c.consistent,
        c.correct, frac);
    // Per view: measured 7947..16410 correct samples, fractions 0.382..0.562
    // (the plain window: 9825..18887, 0.402..0.571).
    EXPECT_GT(c.correct, 7000) << scene.views[refs[i]].name;
    EXPECT_GT(frac, 0.34) << scene.views[refs[i]].name;
    total.samples += c.samples;
    total.in_box += c.in_box;
    total.consistent += c.consistent;
    total.correct += c.correct;
  }
  const double in_box = double(total.in_box) / std::max(1, total.samples);
  const double correct = double(total.correct) / std::max(1, total.samples);
  std::printf(
      "TOTAL samples %d in_box %d (%.3f) consistent %d correct %d (%.3f)\n",
      total.samples, total.in_box, in_box, total.consistent, total.correct,
      correct);
  // Measured: 126210 samples, 64188 correct; in the box 0.745, correct 0.509
  // (the plain window: 142347, 73138, 0.724, 0.514; at this
  // 320 px size the bilateral window finds 12 % fewer correct samples, at
  // 640 px 2.9 % fewer in less CPU time).
  EXPECT_GT(total.correct, 56000);
  EXPECT_GT(in_box, 0.61);
  EXPECT_GT(correct, 0.43);
}

}  // namespace
}  // namespace wild_mvs
