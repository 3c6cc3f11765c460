// Copyright wild_mvs authors. Global view selection (paper 5.1) on random
// collections: the selection equals a straightforward implementation of the
// paper's greedy rule (the one the library used before its per-feature
// parallax weights were cached), bit for bit, for every reference view; and
// on constructed cameras, the preference for parallax and resolution.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "mvs_test_scenes.h"
#include "random_collection.h"
#include "wild_mvs/core/global_view_selection.h"
#include "wild_mvs/core/stats.h"

namespace wild_mvs {
namespace {

constexpr double kDeg = M_PI / 180.0;

double RefParallaxWeight(const Eigen::Vector3d& d1, const Eigen::Vector3d& d2,
                         double max_rad) {
  const double a = std::acos(std::clamp(d1.dot(d2), -1.0, 1.0));
  return std::min((a / max_rad) * (a / max_rad), 1.0);
}

double RefResolutionWeight(double r) {
  if (r >= 2) return 2.0 / r;
  if (r >= 1) return 1.0;
  return r;
}

// g_R(V) = sum over shared features of w_N(f) * w_s(f), chosen greedily;
// w_N multiplies the parallax weights of every pair in N + {V} seeing f.
// Searches each feature's track for each view (slow, obviously right).
GlobalViewSelection ReferenceSelection(
    const Scene& scene, int ref, const std::vector<std::vector<int>>& ppv,
    const GlobalViewSelectionOptions& options) {
  const double amax = options.max_parallax_deg * kDeg;
  const Camera& cr = scene.views[ref].camera;
  const int nv = static_cast<int>(scene.views.size());
  struct Feature {
    Eigen::Vector3d X;
    std::vector<std::pair<int, Eigen::Vector3d>> seen;
    double within = 1;
    double s_ref = 0;
  };
  std::vector<Feature> feats;
  std::vector<std::vector<int>> cand_feats(nv);
  for (int p : ppv[ref]) {
    const SparsePoint& sp = scene.points[p];
    if (cr.Depth(sp.xyz) <= 0) continue;
    Feature f;
    f.X = sp.xyz;
    f.s_ref = FeatureScale(cr, sp.xyz);
    for (const Observation& o : sp.track) {
      bool dup = false;
      for (const auto& s : f.seen) dup |= s.first == o.view;
      const Camera& c = scene.views[o.view].camera;
      if (dup || c.Depth(sp.xyz) <= 0) continue;
      f.seen.emplace_back(o.view, (sp.xyz - c.Center()).normalized());
    }
    for (const auto& s : f.seen)
      if (s.first != ref) cand_feats[s.first].push_back(feats.size());
    feats.push_back(f);
  }
  auto direction = [](const Feature& f, int view) -> const Eigen::Vector3d* {
    for (const auto& s : f.seen)
      if (s.first == view) return &s.second;
    return nullptr;
  };
  std::vector<int> candidates;
  for (int v = 0; v < nv; ++v) {
    if (v == ref || cand_feats[v].empty()) continue;
    std::vector<double> angles;
    for (int fi : cand_feats[v]) {
      const Eigen::Vector3d* dr = direction(feats[fi], ref);
      const Eigen::Vector3d* dv = direction(feats[fi], v);
      if (dr && dv)
        angles.push_back(std::acos(std::clamp(dr->dot(*dv), -1.0, 1.0)));
    }
    if (Median(angles) >= options.min_baseline_deg * kDeg)
      candidates.push_back(v);
  }
  GlobalViewSelection out;
  std::vector<int> in_n{ref};
  std::vector<bool> taken(nv, false);
  while (static_cast<int>(out.neighbors.size()) < options.num_neighbors) {
    double best = 0;
    int best_v = -1;
    for (int v : candidates) {
      if (taken[v]) continue;
      double score = 0;
      for (int fi : cand_feats[v]) {
        const Feature& f = feats[fi];
        const Eigen::Vector3d* dv = direction(f, v);
        double w = f.within;
        for (int vi : in_n)
          if (const Eigen::Vector3d* di = direction(f, vi))
            w *= RefParallaxWeight(*di, *dv, amax);
        score += w * RefResolutionWeight(
                         f.s_ref / FeatureScale(scene.views[v].camera, f.X));
      }
      if (score > best) {
        best = score;
        best_v = v;
      }
    }
    if (best_v < 0) break;
    for (int fi : cand_feats[best_v]) {
      Feature& f = feats[fi];
      const Eigen::Vector3d* dv = direction(f, best_v);
      for (int vi : in_n)
        if (const Eigen::Vector3d* di = direction(f, vi))
          f.within *= RefParallaxWeight(*di, *dv, amax);
    }
    taken[best_v] = true;
    in_n.push_back(best_v);
    out.neighbors.push_back(best_v);
    out.scores.push_back(best);
  }
  return out;
}

void ExpectSameSelections(const Scene& scene,
                          const GlobalViewSelectionOptions& options) {
  const auto ppv = scene.PointsPerView();
  int compared = 0, full = 0;
  for (int ref = 0; ref < static_cast<int>(scene.views.size()); ++ref) {
    const GlobalViewSelection want =
        ReferenceSelection(scene, ref, ppv, options);
    if (want.neighbors.empty()) continue;  // the fallback: another test
    const GlobalViewSelection got = SelectGlobalViews(scene, ref, ppv, options);
    ASSERT_EQ(got.neighbors, want.neighbors) << "reference view " << ref;
    ASSERT_EQ(got.scores.size(), want.scores.size());
    for (size_t i = 0; i < got.scores.size(); ++i)
      EXPECT_EQ(got.scores[i], want.scores[i])  // bit for bit
          << "reference view " << ref << ", neighbour " << i;
    EXPECT_TRUE(got.fallbacks.empty());
    ++compared;
    full += static_cast<int>(got.neighbors.size()) == options.num_neighbors;
  }
  // The comparison is not vacuous: most views select a full neighbourhood.
  EXPECT_GT(compared, static_cast<int>(scene.views.size()) * 9 / 10);
  EXPECT_GT(full, compared / 2);
}

TEST(GlobalViewSelection, EqualsTheReferenceOnRandomCollections) {
  for (unsigned seed : {1u, 2u, 3u}) {
    SCOPED_TRACE(seed);
    ExpectSameSelections(testing::RandomCollection(60, 400, 10, seed),
                         GlobalViewSelectionOptions());
  }
}

TEST(GlobalViewSelection, EqualsTheReferenceWithOtherOptions) {
  GlobalViewSelectionOptions o;
  o.num_neighbors = 4;
  o.max_parallax_deg = 25;
  o.min_baseline_deg = 0;  // no twin exclusion
  ExpectSameSelections(testing::RandomCollection(40, 300, 20, 7), o);
  o.num_neighbors = 16;
  o.min_baseline_deg = 5;  // most candidates excluded
  ExpectSameSelections(testing::RandomCollection(80, 300, 6, 8), o);
}

TEST(GlobalViewSelection, DuplicateObservationsAndViewsBehindCount) {
  // Tracks listing a view twice, and views behind a point: both skipped the
  // same way.
  Scene scene = testing::RandomCollection(30, 300, 8, 11);
  for (size_t p = 0; p < scene.points.size(); p += 3)
    scene.points[p].track.push_back(scene.points[p].track.front());
  View behind = scene.views[0];
  behind.name = "behind.jpg";
  behind.camera.R = -behind.camera.R;  // a reflection: looks away
  behind.camera.R.row(0) = -behind.camera.R.row(0);
  behind.camera.t = -behind.camera.R * scene.views[0].camera.Center();
  scene.views.push_back(behind);
  for (size_t p = 1; p < scene.points.size(); p += 4) {
    Observation o = scene.points[p].track.back();
    o.view = static_cast<int>(scene.views.size()) - 1;
    scene.points[p].track.push_back(o);
  }
  ExpectSameSelections(scene, GlobalViewSelectionOptions());
}

// Constructed cameras on a circle around the origin: the selection prefers
// parallax (not the twin next to R) and matching resolution.
TEST(MvsGlobalViewSelection, PrefersParallaxAndMatchingResolution) {
  Scene scene;
  auto add = [&](const char* name, const Camera& cam) {
    View v;
    v.name = name;
    v.camera = cam;
    scene.views.push_back(v);
  };
  const Eigen::Vector3d o(0, 0, 0);
  add("ref",
      testing::LookAtCamera(testing::OnCircle(0, 4), o, 400, 320, 240));  // 0
  add("twin",
      testing::LookAtCamera(testing::OnCircle(0.2, 4), o, 400, 320, 240));  // 1
  add("good_left",
      testing::LookAtCamera(testing::OnCircle(-15, 4), o, 400, 320, 240));  // 2
  add("far_lowres",
      testing::LookAtCamera(testing::OnCircle(13, 4), o, 100, 80, 60));  // 3
  add("good_right",
      testing::LookAtCamera(testing::OnCircle(16, 4), o, 400, 320, 240));  // 4
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-0.6, 0.6);
  for (int i = 0; i < 200; ++i) {
    SparsePoint p;
    p.xyz = Eigen::Vector3d(u(rng), 0.5 * u(rng), u(rng));
    for (int v = 0; v < 5; ++v) {
      Eigen::Vector2d px;
      ASSERT_TRUE(scene.views[v].camera.Project(p.xyz, &px));
      Observation ob;
      ob.view = v;
      ob.xy = px;
      ob.scale = 2;
      p.track.push_back(ob);
    }
    scene.points.push_back(p);
  }
  const auto ppv = scene.PointsPerView();
  const GlobalViewSelection sel =
      SelectGlobalViews(scene, 0, ppv, GlobalViewSelectionOptions());
  ASSERT_GE(sel.neighbors.size(), 2u);
  EXPECT_TRUE(sel.fallbacks.empty());
  for (size_t i = 0; i < sel.neighbors.size(); ++i)
    std::printf("neighbour %zu: %s score %.2f\n", i,
                scene.views[sel.neighbors[i]].name.c_str(), sel.scores[i]);
  // The good cameras rank first (in either order), the twin never enters.
  const std::vector<int> first(sel.neighbors.begin(),
                               sel.neighbors.begin() + 2);
  EXPECT_TRUE(std::count(first.begin(), first.end(), 2) == 1 &&
              std::count(first.begin(), first.end(), 4) == 1);
  EXPECT_EQ(std::count(sel.neighbors.begin(), sel.neighbors.end(), 1), 0);
  // If the low-resolution camera enters, it scores below the good ones.
  for (size_t i = 2; i < sel.neighbors.size(); ++i)
    EXPECT_LT(sel.scores[i], 0.5 * sel.scores[1]);
  EXPECT_GT(sel.scores[0], 0);
}

}  // namespace
}  // namespace wild_mvs

namespace wild_mvs {
namespace {

// A camera moving along a wall 3 away, looking at it: the first view sees
// none of the sparse points (its part of the wall gave no feature), so
// neither its own points nor the others' in its frustum give its scene
// depth. The depths its nearest views see of their own points do (the
// optical axes are parallel and never cross).
TEST(MvsGlobalViewSelection,
     SceneDepthOfAViewWithoutPointsFromItsNearestViews) {
  Scene scene;
  for (int i = 0; i < 9; ++i) {
    View v;
    v.name = "view_" + std::to_string(i);
    const Eigen::Vector3d c(0.25 * i, 0, 0);
    v.camera =
        testing::LookAtCamera(c, c + Eigen::Vector3d(0, 3, 0), 400, 320, 240);
    scene.views.push_back(v);
  }
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> ux(1.5, 4.0), uz(-0.8, 0.8);
  for (int i = 0; i < 300; ++i) {
    SparsePoint p;
    p.xyz = Eigen::Vector3d(ux(rng), 3.0, uz(rng));
    for (int v = 0; v < 9; ++v) {
      Eigen::Vector2d px;
      if (!scene.views[v].camera.Project(p.xyz, &px) ||
          !scene.views[v].camera.InImage(px))
        continue;
      Observation ob;
      ob.view = v;
      ob.xy = px;
      p.track.push_back(ob);
    }
    if (p.track.size() >= 2) scene.points.push_back(p);
  }
  const auto ppv = scene.PointsPerView();
  ASSERT_TRUE(ppv[0].empty());
  for (const SparsePoint& p : scene.points) {
    Eigen::Vector2d px;
    ASSERT_FALSE(scene.views[0].camera.Project(p.xyz, &px) &&
                 scene.views[0].camera.InImage(px));
  }
  double lo = 0, hi = 0;
  const double z = EstimateSceneDepth(scene, 0, ppv, &lo, &hi);
  EXPECT_NEAR(z, 3.0, 0.03);
  EXPECT_GT(lo, 0);
  EXPECT_GE(hi, lo);
}

}  // namespace
}  // namespace wild_mvs
