// Copyright wild_mvs authors. Sparse tracks on real data with known cameras:
// Middlebury templeSparseRing (16 views, 640x480). Skipped when ../shared is
// absent.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <string>
#include <vector>

#include "test_paths.h"
#include "wild_mvs/core/image.h"
#include "wild_mvs/core/scene.h"
#include "wild_mvs/core/sparse_tracker.h"
#include "wild_mvs/core/thread_pool.h"
#include "wild_mvs/core/triangulation.h"
#include "wild_mvs/io/image_files.h"
#include "wild_mvs/io/middlebury.h"

namespace wild_mvs {
namespace {

TEST(SparseTrackerReal, TempleSparseRing) {
  WILD_MVS_REQUIRE_SHARED(dir, "datasets/middlebury_templeSparseRing");
  // The cameras only (the par format has no points).
  Scene scene = ReadMiddleburyPar(dir + "/templeSR_par.txt");
  ASSERT_EQ(scene.views.size(), 16u);
  ImageOptions io;
  ImageCache cache(MakeSceneLoader(scene, io), 256);
  TrackerOptions opt;
  ThreadPool pool(2);
  TrackerStats stats;
  const std::vector<SparsePoint> pts =
      ComputeSparseTracks(scene, cache, opt, &pool, &stats);
  std::vector<double> errors;
  std::vector<int> hist(8, 0);
  int inside = 0;
  // README.txt bounding box, with a 10 % margin.
  const Eigen::Vector3d lo(-0.073568, 0.021728, -0.012445),
      hi(0.028855, 0.181892, 0.062736);
  const Eigen::Vector3d margin = 0.1 * (hi - lo);
  for (const SparsePoint& p : pts) {
    ASSERT_GE(p.track.size(), 2u);
    hist[std::min<size_t>(p.track.size(), 7)]++;
    for (const Observation& o : p.track) {
      const Camera& c = scene.views[o.view].camera;
      ASSERT_GT(c.Depth(p.xyz), 0);
      const double e = ReprojectionError(c, p.xyz, o.xy);
      ASSERT_LE(e, opt.max_reprojection_error + 1e-9);
      EXPECT_GT(o.scale, 0);
      errors.push_back(e);
    }
    if ((p.xyz.array() >= (lo - margin).array()).all() &&
        (p.xyz.array() <= (hi + margin).array()).all()) {
      ++inside;
    }
  }
  std::sort(errors.begin(), errors.end());
  const double median = errors.empty() ? 1e9 : errors[errors.size() / 2];
  std::cout << "templeSparseRing: " << pts.size() << " points, "
            << errors.size() << " observations, " << stats.features
            << " features, " << stats.pairs_matched << " pairs, "
            << stats.matches << " matches, " << stats.conflicting_tracks
            << " conflicting tracks; median reprojection error " << median
            << " px; inside bbox " << inside << "; track lengths 2..7+:";
  for (int k = 2; k < 8; ++k) std::cout << " " << hist[k];
  std::cout << std::endl;
  EXPECT_GE(pts.size(), 2000u);
  EXPECT_LT(median, 0.5);
  EXPECT_GE(inside, 0.9 * pts.size());
  // SIFT orientation twins (same position and size, two descriptors) form
  // one track, not two identical points.
  std::vector<std::array<double, 3>> xyz;
  for (const SparsePoint& p : pts)
    xyz.push_back({p.xyz.x(), p.xyz.y(), p.xyz.z()});
  std::sort(xyz.begin(), xyz.end());
  EXPECT_EQ(std::adjacent_find(xyz.begin(), xyz.end()), xyz.end());
}

}  // namespace
}  // namespace wild_mvs
