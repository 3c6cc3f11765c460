// Copyright wild_mvs authors. The second growing pass after the
// geometric-consistency filter (core/view_refinement.h, docs/ALGORITHM.md
// section 5.4) on a rendered scene with exact ground truth:
//  - its seeds: held samples on the border of holes, and the neighbours'
//    samples reprojected into the holes with the true depth and normal;
//  - the whole pipeline on real first-pass maps (MVS, filter, second pass,
//    filter): more ground-truth pixels within 1 %, accuracy not lower;
//  - where it can fail: seeded from neighbour maps that are 4 % wrong, the
//    seeds are wrong but MPGC and the filter do not let them in (copying
//    the reprojected depths would have been 100 % wrong).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <map>
#include <memory>
#include <opencv2/core.hpp>

#include "synthetic_scene.h"
#include "wild_mvs/core/geometric_consistency.h"
#include "wild_mvs/core/image.h"
#include "wild_mvs/core/reconstruct_view.h"
#include "wild_mvs/core/thread_pool.h"
#include "wild_mvs/core/view_refinement.h"

namespace wild_mvs {
namespace {

using testing::Render;
using testing::SyntheticScene;

struct Score {
  int gt = 0, estimated = 0, within = 0;
  double completeness() const { return gt ? double(within) / gt : 0; }
  double accuracy() const { return estimated ? double(within) / estimated : 0; }
};

// Against the ground truth of the map's view (same resolution here), 1 %.
Score ScoreMap(const SyntheticScene& s, const DepthMap& m,
               const cv::Mat& only = cv::Mat()) {
  Score r;
  const cv::Mat& gt = s.depth[m.view];
  for (int y = 0; y < m.height(); ++y)
    for (int x = 0; x < m.width(); ++x) {
      if (!only.empty() && !only.at<uint8_t>(y, x)) continue;
      const float g = gt.at<float>(y, x), d = m.depth.at<float>(y, x);
      if (g > 0) ++r.gt;
      if (!(d > 0)) continue;
      ++r.estimated;
      if (g > 0 && std::abs(d - g) < 0.01 * g) ++r.within;
    }
  return r;
}

void Print(const char* what, const Score& r) {
  std::printf("%-40s gt %6d est %6d within1%% %6d complete %.3f acc %.3f\n",
              what, r.gt, r.estimated, r.within, r.completeness(),
              r.accuracy());
}

DepthMap GtMap(const SyntheticScene& s, int v, float factor = 1.0f) {
  DepthMap m;
  m.view = v;
  m.camera = s.scene.views[v].camera;
  m.depth = s.depth[v] * factor;
  m.normal = s.normals[v].clone();
  m.confidence = cv::Mat(m.depth.size(), CV_32F, cv::Scalar(0.9f));
  m.confidence.setTo(0, s.depth[v] <= 0);
  return m;
}

class ViewRefinement : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    // Changing light and a box in view 0 only, 8 views 15 degrees apart.
    testing::SyntheticSpec spec = testing::ClutteredSceneSpec(true, true, 105);
    spec.width = 240;
    spec.height = 180;
    spec.focal = 225;
    spec.num_sparse_points = 200;
    scene_ = new SyntheticScene(Render(spec));
  }
  static void TearDownTestSuite() {
    delete scene_;
    scene_ = nullptr;
  }
  static SyntheticScene* scene_;
};
SyntheticScene* ViewRefinement::scene_ = nullptr;

// Seeds from exact maps: a hole cut into view 3's map is bordered by held
// seeds and filled with neighbour seeds at the true depth and normal.
TEST_F(ViewRefinement, SeedsFromExactMaps) {
  const SyntheticScene& s = *scene_;
  DepthMap own = GtMap(s, 3);
  cv::Mat hole = cv::Mat::zeros(own.depth.size(), CV_8U);
  hole(cv::Rect(80, 60, 60, 50)).setTo(1);
  own.depth.setTo(0, hole);
  own.normal.setTo(cv::Vec3f(0, 0, 0), hole);
  own.confidence.setTo(0, hole);
  std::vector<DepthMap> nbs;
  for (int v : {1, 2, 4, 5}) nbs.push_back(GtMap(s, v));
  std::vector<const DepthMap*> ptrs;
  for (const DepthMap& m : nbs) ptrs.push_back(&m);
  RefinementOptions o;
  o.neighbor_seed_stride = 4;
  RefinementSeedStats st;
  const std::vector<Seed> seeds = RefinementSeeds(own, ptrs, cv::Mat(), o, &st);
  EXPECT_EQ(static_cast<int>(seeds.size()), st.held + st.neighbor);
  EXPECT_GT(st.held, 200);  // the hole's border (and the sky's)
  int in_hole = 0, good = 0, facing = 0;
  for (const Seed& sd : seeds) {
    if (sd.held) {
      EXPECT_GT(own.depth.at<float>(sd.y, sd.x), 0.f);
      continue;
    }
    EXPECT_EQ(own.depth.at<float>(sd.y, sd.x), 0.f);  // only in holes
    if (!hole.at<uint8_t>(sd.y, sd.x)) continue;
    ++in_hole;
    const float g = s.depth[3].at<float>(sd.y, sd.x);
    good += g > 0 && std::abs(sd.depth - g) < 0.01 * g;
    const cv::Vec3f n = s.normals[3].at<cv::Vec3f>(sd.y, sd.x);
    facing += sd.normal.dot(Eigen::Vector3d(n[0], n[1], n[2])) > 0.95;
  }
  std::printf(
      "held %d, neighbour %d (%d in the hole, %d within 1 %%, %d "
      "with the true normal)\n",
      st.held, st.neighbor, in_hole, good, facing);
  // One per 4x4 block of the 60x50 hole, nearly all at the true depth.
  EXPECT_GE(in_hole, 15 * 12);
  EXPECT_GT(good, 0.95 * in_hole);
  EXPECT_GT(facing, 0.9 * in_hole);
  // Switched off: nothing.
  o.grow_from_consistent = false;
  o.neighbor_seed_stride = 0;
  EXPECT_TRUE(RefinementSeeds(own, ptrs, cv::Mat(), o, &st).empty());
}

// The pipeline on first-pass MVS maps of every view: filter, second pass,
// filter again. More of view 3's (and view 0's) ground truth within 1 %,
// at no lower accuracy.
TEST_F(ViewRefinement, IncreasesCompletenessWithoutLosingAccuracy) {
  const SyntheticScene& s = *scene_;
  ThreadPool pool(2);
  ImageCache cache(s.Loader(), 64);
  // The plain window, as measured. (With the bilateral window, the
  // default, the first pass leaves the second nothing to add
  // here: view 3 0.872 -> 0.872, view 0 0.633 -> 0.633 complete; the
  // second pass is off by default.)
  MvsOptions options;
  options.mpgc.bilateral_sigma_color = 0;
  const int n = static_cast<int>(s.scene.views.size());
  std::vector<DepthMap> raw(n);
  for (int v = 0; v < n; ++v) {
    ViewReport rep;
    raw[v] = ReconstructView(s.scene, v, cache, options, &pool, &rep);
  }
  auto neighbours_of = [&](const std::vector<DepthMap>& maps, int v) {
    std::vector<const DepthMap*> p;
    for (int u : maps[v].neighbors) p.push_back(&maps[u]);
    return p;
  };
  std::vector<DepthMap> first(n);
  for (int v = 0; v < n; ++v) {
    first[v] = raw[v];
    first[v].depth = raw[v].depth.clone();
    first[v].normal = raw[v].normal.clone();
    first[v].confidence = raw[v].confidence.clone();
    FilterByConsistency(&first[v], neighbours_of(raw, v), options.consistency,
                        nullptr);
  }
  // The second pass of every view with `o`, then view v's filtered.
  auto second_pass = [&](const MvsOptions& o, int v, Score* score,
                         std::map<int, int>* wrong_new) {
    std::vector<DepthMap> second(n);
    for (int u = 0; u < n; ++u) {
      ViewReport rep;
      second[u] = RefineView(s.scene, u, cache, o, first[u],
                             neighbours_of(first, u), &pool, &rep);
      EXPECT_EQ(rep.start_samples, first[u].CountValid());
      EXPECT_GE(second[u].CountValid(), first[u].CountValid());
    }
    DepthMap f = second[v];
    f.depth = second[v].depth.clone();  // the filter works in place
    FilterByConsistency(&f, neighbours_of(second, v), o.consistency, nullptr,
                        first[v].depth, o.refine.min_consistent_new);
    *score = ScoreMap(s, f);
    for (int y = 0; y < f.height(); ++y)
      for (int x = 0; x < f.width(); ++x) {
        const float d = f.depth.at<float>(y, x), g = s.depth[v].at<float>(y, x);
        if (!(d > 0) || first[v].depth.at<float>(y, x) > 0) continue;
        if (g > 0 && std::abs(d - g) < 0.01 * g) continue;
        ++(*wrong_new)[s.object_id[v].at<int>(y, x)];
      }
    return second;
  };
  const int occluder = static_cast<int>(s.spec.objects.size()) - 1;
  for (int v : {3, 0}) {
    Score b;
    std::map<int, int> wrong_new;
    const std::vector<DepthMap> second =
        second_pass(options, v, &b, &wrong_new);
    const Score a = ScoreMap(s, first[v]);
    char what[64];
    std::snprintf(what, sizeof what, "view %d first pass, filtered", v);
    Print(what, a);
    std::snprintf(what, sizeof what, "view %d second pass, filtered", v);
    Print(what, b);
    for (const auto& [obj, count] : wrong_new)
      std::printf("  %d new wrong samples on object %d\n", count, obj);
    // Measured: view 3 0.884 -> 0.886 complete at 0.972 -> 0.972; view 0
    // 0.643 -> 0.644 at 0.943 -> 0.942.
    EXPECT_GT(b.within, a.within) << v;
    EXPECT_GE(b.accuracy(), a.accuracy() - 0.003) << v;
    if (v == 3) {
      // Deterministic for any number of threads.
      ViewReport r1;
      const DepthMap one = RefineView(s.scene, 3, cache, options, first[3],
                                      neighbours_of(first, 3), nullptr, &r1);
      EXPECT_EQ(cv::norm(one.depth, second[3].depth, cv::NORM_INF), 0.0);
      continue;
    }
    // View 0 alone sees a box (the occluder): the neighbours' samples of
    // the ground behind it, reprojected into view 0 as seeds
    // (neighbor_seed_stride), are matched there by MPGC and confirmed by
    // every neighbour. This is why those seeds are off by default.
    MvsOptions with_seeds = options;
    with_seeds.refine.neighbor_seed_stride = 4;
    Score c;
    std::map<int, int> wrong_c;
    second_pass(with_seeds, v, &c, &wrong_c);
    Print("view 0 with neighbour seeds, filtered", c);
    std::printf("  %d new wrong samples on the occluder (without: %d)\n",
                wrong_c[occluder], wrong_new[occluder]);
    EXPECT_GT(wrong_c[occluder], 10 * std::max(1, wrong_new[occluder]));
    EXPECT_LT(c.accuracy(), a.accuracy() - 0.01);
  }
}

// From exact maps with a hole (the first pass and the filter taken as
// perfect): growth from the hole's border refills it with correct depths.
TEST_F(ViewRefinement, FillsAHoleFromItsBorder) {
  const SyntheticScene& s = *scene_;
  ThreadPool pool(2);
  ImageCache cache(s.Loader(), 64);
  const MvsOptions options;
  DepthMap own = GtMap(s, 3);
  cv::Mat hole = cv::Mat::zeros(own.depth.size(), CV_8U);
  hole(cv::Rect(70, 60, 80, 60)).setTo(1);
  own.depth.setTo(0, hole);
  own.normal.setTo(cv::Vec3f(0, 0, 0), hole);
  // Exact samples at the highest confidence: never revisited.
  own.confidence.setTo(1.0f, own.depth > 0);
  own.confidence.setTo(0, hole);
  std::vector<DepthMap> right;
  for (int v : {1, 2, 4, 5}) right.push_back(GtMap(s, v));
  std::vector<const DepthMap*> rp;
  for (const DepthMap& m : right) rp.push_back(&m);
  ViewReport rep;
  DepthMap out = RefineView(s.scene, 3, cache, options, own, rp, &pool, &rep);
  EXPECT_GT(rep.refine_seeds.held, 200);
  const Score before = ScoreMap(s, own, hole), grown = ScoreMap(s, out, hole);
  Print("hole before", before);
  Print("hole after the second pass", grown);
  EXPECT_EQ(before.estimated, 0);
  // Measured: 0.958 of the hole grown, 0.962 of it within 1 %; after the
  // filter against the (exact) neighbours' maps 0.952 at 0.987.
  EXPECT_GT(grown.completeness(), 0.8);
  EXPECT_GT(grown.accuracy(), 0.95);
  // Outside the hole the exact samples are kept as they were.
  cv::Mat diff = (out.depth != own.depth) & (hole == 0) & (own.depth > 0);
  EXPECT_EQ(cv::countNonZero(diff), 0);
  FilterByConsistency(&out, rp, options.consistency, nullptr, own.depth,
                      options.refine.min_consistent_new);
  const Score kept = ScoreMap(s, out, hole);
  Print("hole after the filter", kept);
  EXPECT_GT(kept.completeness(), 0.8);
  EXPECT_GT(kept.accuracy(), 0.97);
}

// Where it can fail: the neighbours' maps are 4 % too deep, so every seed
// reprojected into the hole is wrong. MPGC converges to the surface or
// fails; the new samples that survive the filter against the (true) maps
// are right. Copying the seeds' depths would have filled the hole with
// wrong depths only.
TEST_F(ViewRefinement, WrongNeighbourDepthsDoNotGetIn) {
  const SyntheticScene& s = *scene_;
  ThreadPool pool(2);
  ImageCache cache(s.Loader(), 64);
  const MvsOptions options;
  DepthMap own = GtMap(s, 3);
  // The working camera of view 3 is the full one here (240x180).
  cv::Mat hole = cv::Mat::zeros(own.depth.size(), CV_8U);
  hole(cv::Rect(70, 60, 80, 60)).setTo(1);
  own.depth.setTo(0, hole);
  own.normal.setTo(cv::Vec3f(0, 0, 0), hole);
  own.confidence.setTo(0, hole);
  std::vector<DepthMap> wrong, right;
  for (int v : {1, 2, 4, 5}) {
    wrong.push_back(GtMap(s, v, 1.04f));
    right.push_back(GtMap(s, v));
  }
  std::vector<const DepthMap*> wp, rp;
  for (const DepthMap& m : wrong) wp.push_back(&m);
  for (const DepthMap& m : right) rp.push_back(&m);
  // The seeds in the hole are wrong.
  RefinementOptions seeds_only;
  seeds_only.grow_from_consistent = false;
  seeds_only.neighbor_seed_stride = 4;
  RefinementSeedStats st;
  int seeds_in_hole = 0, seeds_right = 0;
  for (const Seed& sd : RefinementSeeds(own, wp, cv::Mat(), seeds_only, &st)) {
    if (!hole.at<uint8_t>(sd.y, sd.x)) continue;
    ++seeds_in_hole;
    const float g = s.depth[3].at<float>(sd.y, sd.x);
    seeds_right += g > 0 && std::abs(sd.depth - g) < 0.01 * g;
  }
  EXPECT_GT(seeds_in_hole, 100);
  EXPECT_LT(seeds_right, 0.05 * seeds_in_hole);
  // Only the neighbours' seeds (no growth from the border), then filtered
  // against the true maps.
  MvsOptions o = options;
  o.refine = seeds_only;
  ViewReport rep;
  DepthMap out = RefineView(s.scene, 3, cache, o, own, wp, &pool, &rep);
  const Score grown = ScoreMap(s, out, hole);
  FilterByConsistency(&out, rp, o.consistency, nullptr);
  const Score kept = ScoreMap(s, out, hole);
  Print("hole, grown from 4 % wrong seeds", grown);
  Print("hole, after the filter", kept);
  // What the filter keeps of the hole is right (or nothing got in).
  EXPECT_TRUE(kept.estimated == 0 || kept.accuracy() > 0.97) << kept.accuracy();
  EXPECT_LE(kept.estimated, grown.estimated);
}

}  // namespace
}  // namespace wild_mvs
