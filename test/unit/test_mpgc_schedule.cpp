// Copyright wild_mvs authors. The paper's MPGC schedule, rule by rule
// (docs/ALGORITHM.md section 4), on rendered planes with exact ground
// truth: a pixel that converges after iteration 6 stops there, the normal
// and colour scales are updated at every fifth iteration, the oscillation
// check happens once, and a view that leaves the image after settling is
// replaced. The schedule is the paper's (MpgcSchedule); tests substitute
// other values to observe one rule at a time.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "patch_context_util.h"
#include "synthetic_scene.h"
#include "wild_mvs/core/mpgc.h"
#include "wild_mvs/core/patch.h"

namespace wild_mvs {
namespace {

using Kind = MatchTrace::Kind;
using testing::Render;
using testing::SyntheticScene;

using testing::AsMatch;
using testing::MakeContext;

// A textured plane 20 degrees off fronto-parallel seen by 5 cameras on a
// short arc, constant light, no noise.
const SyntheticScene& Plane() {
  static const SyntheticScene* s = [] {
    testing::SyntheticSpec spec = testing::SlantedPlaneSpec(20, 5);
    spec.width = 200;
    spec.height = 150;
    spec.focal = 200;
    spec.num_sparse_points = 10;
    return new SyntheticScene(Render(spec));
  }();
  return *s;
}

Eigen::Vector3d GtNormal(const SyntheticScene& s, int v, int x, int y) {
  const cv::Vec3f n = s.normals[v].at<cv::Vec3f>(y, x);
  return Eigen::Vector3d(n[0], n[1], n[2]);
}

void PrintTrace(const MatchTrace& tr) {
  for (const auto& e : tr.events)
    std::printf("  it %2d kind %d view %d\n", e.iteration,
                static_cast<int>(e.kind), e.view);
}

// Started on the true plane, the patch does not move: its NCCs are stable
// from the first test on, so it converges after iteration 6 (the baseline
// is recorded after the 5 settling iterations) and stops there.
TEST(MpgcSchedule, PixelOnItsPlaneConvergesAtIterationSix) {
  const SyntheticScene& s = Plane();
  const int ref = 2, x = 100, y = 75;
  const PatchContext ctx = MakeContext(s, ref);
  MpgcOptions mo;
  PatchMatcher m(ctx, mo, LocalViewSelectionOptions());
  PatchResult r;
  MatchTrace tr;
  ASSERT_TRUE(m.Match(x, y, s.depth[ref].at<float>(y, x),
                      GtNormal(s, ref, x, y), &r, &tr));
  EXPECT_EQ(r.iterations, 6);
  EXPECT_TRUE(tr.Has(5, Kind::kBaseline));
  EXPECT_TRUE(tr.Has(6, Kind::kConverged));
  EXPECT_EQ(tr.events.back().kind, Kind::kConverged);
  EXPECT_EQ(tr.Count(Kind::kBaseline), r.num_active);
  EXPECT_NEAR(r.depth, s.depth[ref].at<float>(y, x),
              1e-3 * s.depth[ref].at<float>(y, x));
}

// With an unreachable eps (and no drops) the patch cannot converge before
// it reaches its floating-point fixpoint: the normal and colour scales are
// fitted at iterations 1 (the new active set) and 5, the depth alone at the
// others, and the match fails after max_iterations (7 here: the fixpoint
// of the float NCC sums comes at iteration 8 with clang's AVX2 kernels,
// later with GCC's).
TEST(MpgcSchedule, FullUpdateEveryFifthIterationAndFailureAfterMax) {
  const SyntheticScene& s = Plane();
  const int ref = 2, x = 90, y = 70;
  const PatchContext ctx = MakeContext(s, ref);
  MpgcOptions mo;
  mo.drop_ncc = -1;
  MpgcSchedule sc;
  sc.convergence_eps = 1e-300;
  sc.oscillation_iteration = 0;  // never
  sc.max_iterations = 7;
  PatchMatcher m(ctx, mo, LocalViewSelectionOptions(), sc);
  MatchTrace tr;
  // Started 5 % off: from 3 % the float NCC sums of the SIMD kernels
  // (mpgc_kernels.h) repeat exactly between two iterations, which is
  // convergence even for eps = 1e-300.
  EXPECT_FALSE(m.Match(x, y, s.depth[ref].at<float>(y, x) * 1.05,
                       Eigen::Vector3d(0, 0, -1), nullptr, &tr));
  int full = 0, depth_only = 0;
  for (const auto& e : tr.events) {
    if (e.kind == Kind::kFullUpdate) {
      ++full;
      // Update of pass `it` = iteration it + 1.
      const int iteration = e.iteration + 1;
      EXPECT_TRUE(iteration == 1 || iteration == 5) << iteration;
    }
    if (e.kind == Kind::kDepthUpdate) ++depth_only;
  }
  EXPECT_EQ(full, 2);
  EXPECT_EQ(depth_only, 5);
  EXPECT_TRUE(tr.Has(7, Kind::kFailed));
  EXPECT_EQ(tr.events.back().kind, Kind::kFailed);
  if (::testing::Test::HasFailure()) PrintTrace(tr);
}

// The oscillation rule runs once, after iteration `oscillation_iteration`
// (7 here, while the NCCs still move): the views whose NCC still moves by
// more than eps leave then, local view selection refills A from the unused
// views, and no view is dropped for oscillation at any other iteration.
TEST(MpgcSchedule, OscillationCheckRunsOnce) {
  const SyntheticScene& s = Plane();
  const int ref = 2, x = 100, y = 80;
  const PatchContext ctx = MakeContext(s, ref);  // 4 neighbours
  MpgcOptions mo;
  mo.drop_ncc = -1;
  mo.min_active_views = 1;
  MpgcSchedule sc;
  sc.convergence_eps = 1e-300;
  sc.oscillation_iteration = 7;
  sc.max_iterations = 10;
  LocalViewSelectionOptions lo;
  lo.num_active = 2;
  lo.min_ncc = -1;
  PatchMatcher m(ctx, mo, lo, sc);
  MatchTrace tr;
  EXPECT_FALSE(m.Match(x, y, s.depth[ref].at<float>(y, x) * 1.03,
                       Eigen::Vector3d(0, 0, -1), nullptr, &tr));
  int osc = 0, entered7 = 0;
  for (const auto& e : tr.events) {
    if (e.kind == Kind::kDropOscillation) {
      ++osc;
      EXPECT_EQ(e.iteration, 7);
    }
    if (e.iteration == 7 && e.kind == Kind::kEntered) ++entered7;
  }
  EXPECT_GE(osc, 1);
  EXPECT_EQ(entered7, osc);                   // refilled from the unused views
  EXPECT_TRUE(tr.Has(7, Kind::kFullUpdate));  // the new set: full update
  // The paper's default: once, after iteration 14.
  EXPECT_EQ(MpgcSchedule().oscillation_iteration, 14);
  if (::testing::Test::HasFailure()) PrintTrace(tr);
}

// A view whose window leaves its image after settling is replaced by local
// view selection in the same iteration (when an untried view is left).
// Pixels of R near its border, started 6 % off, move along the epipolar
// lines out of the neighbours' images as the depth converges; after every
// such event local view selection must try the untried views.
TEST(MpgcSchedule, ViewLeavingTheImageAfterSettlingIsReplaced) {
  const SyntheticScene& s = Plane();
  const int ref = 0;  // an end of the arc: neighbours all on one side
  const PatchContext ctx = MakeContext(s, ref);
  MpgcOptions mo;
  mo.min_active_views = 1;
  mo.drop_ncc = -1;
  MpgcSchedule sc;
  sc.settle_iterations = 1;
  LocalViewSelectionOptions lo;
  lo.num_active = 2;
  lo.min_ncc = -1;
  PatchMatcher m(ctx, mo, lo, sc);
  int cases = 0, refilled = 0;
  for (int y = 10; y < 140; y += 4) {
    for (int x = 3; x < 197; x += 1) {
      const float gt = s.depth[ref].at<float>(y, x);
      if (!(gt > 0)) continue;
      for (double f : {0.94, 1.06}) {
        MatchTrace tr;
        m.Match(x, y, gt * f, GtNormal(s, ref, x, y), nullptr, &tr);
        for (size_t i = 0; i < tr.events.size(); ++i) {
          const auto& e = tr.events[i];
          if (e.kind != Kind::kLeftImage || e.iteration < 1) continue;
          int tried = 0;  // views local view selection has tried so far
          for (size_t j = 0; j < i; ++j)
            tried += tr.events[j].kind == Kind::kEntered ||
                     tr.events[j].kind == Kind::kRefused;
          if (tried >= 4) continue;  // nothing left to refill from
          ++cases;
          bool tried_more = false;
          for (size_t j = i + 1; j < tr.events.size(); ++j)
            if (tr.events[j].iteration == e.iteration &&
                (tr.events[j].kind == Kind::kEntered ||
                 tr.events[j].kind == Kind::kRefused))
              tried_more = true;
          refilled += tried_more;
          if (!tried_more) {
            std::printf("pixel %d,%d start %.2f:\n", x, y, f);
            PrintTrace(tr);
          }
        }
      }
    }
  }
  std::printf("views that left the image after settling: %d, refilled %d\n",
              cases, refilled);
  EXPECT_GT(cases, 0);
  EXPECT_EQ(refilled, cases);
}

TEST(MpgcSchedule, OptionsChecked) {
  EXPECT_NO_THROW(MpgcOptions().Check());
  MpgcOptions o;
  o.window = 4;  // odd only
  EXPECT_THROW(o.Check(), std::exception);
  o = MpgcOptions();
  o.drop_ncc = 1.5;
  EXPECT_THROW(o.Check(), std::exception);
  o = MpgcOptions();
  o.min_active_views = 0;
  EXPECT_THROW(o.Check(), std::exception);
}

}  // namespace
}  // namespace wild_mvs
