// Copyright wild_mvs authors. End-to-end tests of the per-view MVS driver
// (ReconstructView) on rendered scenes with exact ground-truth depth:
// completeness and accuracy under strong lighting changes and a transient
// occluder, thread-count determinism, the no-sparse-points fallback and the
// paper's ablation switches.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <memory>
#include <opencv2/core.hpp>

#include "synthetic_scene.h"
#include "wild_mvs/core/image.h"
#include "wild_mvs/core/reconstruct_view.h"
#include "wild_mvs/core/thread_pool.h"

namespace wild_mvs {
namespace {

using testing::Render;
using testing::SyntheticScene;

struct DepthScore {
  int gt_valid = 0;         // GT pixels with depth (excluding ignored objects)
  int estimated = 0;        // of those, pixels with an estimate
  int within = 0;           // ... within `rel` relative depth error
  double completeness = 0;  // within / gt_valid
  double inlier_ratio = 0;  // within / estimated (accuracy)
  double median_rel = 0;    // median relative error over estimated pixels
};

// Compares a depth map (any working resolution) with the ground truth of its
// view at the depth map's pixel centres (nearest GT pixel).
// Pixels whose GT surface is object `ignore_object` (e.g. the one-view
// occluder) are left out.
DepthScore Score(const SyntheticScene& s, const DepthMap& dm, double rel,
                 int ignore_object = -2) {
  const cv::Mat& gt = s.depth[dm.view];
  DepthScore r;
  std::vector<double> errs;
  const double sx = static_cast<double>(gt.cols) / dm.width();
  const double sy = static_cast<double>(gt.rows) / dm.height();
  for (int y = 0; y < dm.height(); ++y) {
    for (int x = 0; x < dm.width(); ++x) {
      const int gx = std::min(gt.cols - 1, static_cast<int>((x + 0.5) * sx));
      const int gy = std::min(gt.rows - 1, static_cast<int>((y + 0.5) * sy));
      const float g = gt.at<float>(gy, gx);
      if (!(g > 0)) continue;
      if (s.object_id[dm.view].at<int>(gy, gx) == ignore_object) continue;
      ++r.gt_valid;
      const float d = dm.depth.at<float>(y, x);
      if (!(d > 0)) continue;
      ++r.estimated;
      const double e = std::abs(d - g) / g;
      errs.push_back(e);
      if (e < rel) ++r.within;
    }
  }
  if (r.gt_valid) r.completeness = static_cast<double>(r.within) / r.gt_valid;
  if (r.estimated) {
    r.inlier_ratio = static_cast<double>(r.within) / r.estimated;
    std::nth_element(errs.begin(), errs.begin() + errs.size() / 2, errs.end());
    r.median_rel = errs[errs.size() / 2];
  }
  return r;
}

void Print(const char* what, const DepthScore& r) {
  std::printf(
      "%-34s gt %6d est %6d within1%% %6d completeness %.3f inliers %.3f "
      "median rel %.5f\n",
      what, r.gt_valid, r.estimated, r.within, r.completeness, r.inlier_ratio,
      r.median_rel);
}

bool BitIdentical(const cv::Mat& a, const cv::Mat& b) {
  if (a.size() != b.size() || a.type() != b.type()) return false;
  const size_t bytes = a.total() * a.elemSize();
  return std::memcmp(a.data, b.data, bytes) == 0;
}

class MvsEndToEnd : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    // Strong per-view exposure / white balance / gamma changes and a box in
    // view 0 only; cameras 15 degrees apart on an arc.
    testing::SyntheticSpec spec = testing::ClutteredSceneSpec(true, true, 105);
    spec.width = 240;
    spec.height = 180;
    spec.focal = 225;
    spec.num_sparse_points = 200;
    lit_ = new SyntheticScene(Render(spec));
  }
  // The default reconstruction of view 3 on 2 threads, shared by the tests.
  static const DepthMap& Default3(ViewReport* report) {
    static ViewReport rep;
    if (!default3_) {
      default3_ = new DepthMap(Run(*lit_, 3, MvsOptions(), 2, &rep));
    }
    *report = rep;
    return *default3_;
  }
  static void TearDownTestSuite() {
    delete lit_;
    lit_ = nullptr;
    delete default3_;
    default3_ = nullptr;
  }
  static DepthMap Run(const SyntheticScene& s, int ref,
                      const MvsOptions& options, int threads,
                      ViewReport* report) {
    ImageCache cache(s.Loader(), 64);
    std::unique_ptr<ThreadPool> pool;
    if (threads > 0) pool = std::make_unique<ThreadPool>(threads);
    return ReconstructView(s.scene, ref, cache, options, pool.get(), report);
  }
  static SyntheticScene* lit_;
  static DepthMap* default3_;
};
SyntheticScene* MvsEndToEnd::lit_ = nullptr;
DepthMap* MvsEndToEnd::default3_ = nullptr;

// Completeness and accuracy against GT depth for an inner reference view
// and for view 0, which alone sees the occluder (its GT includes the box).
TEST_F(MvsEndToEnd, VaryingLightingAndOccluder) {
  const SyntheticScene& s = *lit_;
  for (int ref : {3, 0}) {
    ViewReport rep;
    const DepthMap dm =
        ref == 3 ? Default3(&rep) : Run(s, ref, MvsOptions(), 2, &rep);
    ASSERT_FALSE(dm.empty());
    EXPECT_EQ(dm.view, ref);
    EXPECT_TRUE(rep.fallbacks.empty());
    EXPECT_GE(rep.neighbors.size(), 3u);
    EXPECT_GT(rep.seeds_accepted, 0);
    const DepthScore r = Score(s, dm, 0.01);
    char name[64];
    std::snprintf(name, sizeof name, "view %d (default)", ref);
    Print(name, r);
    // The occluder (the last object) exists in view 0 only.
    const int occ = static_cast<int>(s.spec.objects.size()) - 1;
    const DepthScore ro = Score(s, dm, 0.01, occ);
    std::snprintf(name, sizeof name, "view %d without occluder pixels", ref);
    Print(name, ro);
    // Measured (240x180): view 3 completeness 0.868, inliers 0.969, median
    // 0.0005; view 0 0.627 / 0.872, without the occluder's pixels 0.721 /
    // 0.931.
    if (ref == 3) {
      EXPECT_GT(r.completeness, 0.78);
      EXPECT_GT(r.inlier_ratio, 0.93);
      EXPECT_LT(r.median_rel, 0.002);
    } else {
      EXPECT_GT(r.completeness, 0.52);
      EXPECT_GT(ro.completeness, 0.62);
      EXPECT_GT(ro.inlier_ratio, 0.88);
      EXPECT_LT(ro.median_rel, 0.003);
    }
  }
}

// The result does not depend on the number of threads.
TEST_F(MvsEndToEnd, DeterministicAcrossThreadCounts) {
  const SyntheticScene& s = *lit_;
  ViewReport r1, r2;
  const DepthMap a = Run(s, 3, MvsOptions(), 1, &r1);
  const DepthMap& b = Default3(&r2);
  ASSERT_GT(a.CountValid(), 0);
  EXPECT_TRUE(BitIdentical(a.depth, b.depth));
  EXPECT_TRUE(BitIdentical(a.normal, b.normal));
  EXPECT_TRUE(BitIdentical(a.confidence, b.confidence));
  EXPECT_EQ(r1.pixel_visits, r2.pixel_visits);
}

// Without any sparse point the driver seeds from a depth sweep, says so, and
// still recovers depth.
TEST_F(MvsEndToEnd, NoSparsePointsFallsBack) {
  SyntheticScene s = *lit_;
  s.scene.points.clear();
  ViewReport rep;
  const DepthMap dm = Run(s, 3, MvsOptions(), 2, &rep);
  ASSERT_FALSE(rep.fallbacks.empty());
  bool mentions = false;
  for (const auto& f : rep.fallbacks) {
    std::printf("%s\n", f.c_str());
    if (f.find("fallback") != std::string::npos) mentions = true;
  }
  EXPECT_TRUE(mentions);
  const DepthScore r = Score(s, dm, 0.01);
  Print("view 3 (no sparse points)", r);
  // Measured: completeness 0.860, inliers 0.966.
  EXPECT_GT(r.completeness, 0.75);
  EXPECT_GT(r.inlier_ratio, 0.93);
}

// With only a handful of sparse points (fewer than sweep.below_seeds match)
// the depth sweep also seeds the pixels still empty, and the driver says
// so; the sweep's seeds must not cost completeness or accuracy (on this
// connected scene growth from 3 seeds already reaches most of it).
TEST_F(MvsEndToEnd, FewSparsePointsAddSweepSeeds) {
  SyntheticScene s = *lit_;
  s.scene.points.resize(4);
  ViewReport rep;
  MvsOptions few;
  few.sweep.below_seeds = 1;  // only when no sparse feature matched
  const DepthScore r0 = Score(s, Run(s, 3, few, 2, &rep), 0.01);
  Print("view 3, 4 sparse points, no sweep", r0);
  const DepthScore r1 = Score(s, Run(s, 3, MvsOptions(), 2, &rep), 0.01);
  Print("view 3, 4 sparse points, sweep", r1);
  bool said = false;
  for (const auto& f : rep.fallbacks) {
    std::printf("%s\n", f.c_str());
    said = said || f.find("sweep.below_seeds") != std::string::npos;
  }
  EXPECT_TRUE(said);
  EXPECT_GE(r1.completeness, r0.completeness);
  EXPECT_GT(r1.completeness, 0.75);
  EXPECT_GT(r1.inlier_ratio, 0.93);
}

// The paper's ablations, on the paper's pipeline (--preset paper): each
// switch costs what the paper says it should under the strong lighting
// changes of this scene. Fixed colour scales lose nearly everything here;
// the constant-light control (same geometry, same options) shows that the
// loss comes from the lighting, not from a broken switch.
TEST_F(MvsEndToEnd, Ablations) {
  const SyntheticScene& s = *lit_;
  const int ref = 3;
  const MvsOptions paper = PaperMvsOptions();
  ViewReport rep;
  const DepthScore def = Score(s, Run(s, ref, paper, 2, &rep), 0.01);
  Print("paper preset", def);

  MvsOptions no_local = paper;
  no_local.ablation.local_view_selection = false;
  const DepthScore nl = Score(s, Run(s, ref, no_local, 2, &rep), 0.01);
  Print("no local view selection", nl);

  MvsOptions no_normal = paper;
  no_normal.ablation.optimize_normal = false;
  const DepthScore nn = Score(s, Run(s, ref, no_normal, 2, &rep), 0.01);
  Print("no normal optimisation", nn);

  MvsOptions fixed_scale = paper;
  fixed_scale.ablation.optimize_color_scale = false;
  const DepthScore fs = Score(s, Run(s, ref, fixed_scale, 2, &rep), 0.01);
  Print("colour scale fixed", fs);

  MvsOptions grey = paper;
  grey.ablation.color = false;
  const DepthScore gr = Score(s, Run(s, ref, grey, 2, &rep), 0.01);
  Print("grey", gr);

  // Constant lighting control.
  testing::SyntheticSpec spec = testing::ClutteredSceneSpec(false, true, 105);
  spec.width = 240;
  spec.height = 180;
  spec.focal = 225;
  spec.num_sparse_points = 200;
  const SyntheticScene flat = Render(spec);
  const DepthScore cdef = Score(flat, Run(flat, ref, paper, 2, &rep), 0.01);
  Print("constant light: paper preset", cdef);
  const DepthScore cfs =
      Score(flat, Run(flat, ref, fixed_scale, 2, &rep), 0.01);
  Print("constant light: colour scale fixed", cfs);

  // Measured (240x180, view 3, paper preset): 0.873 complete; no local
  // view selection 0.631; no normal optimisation 0.701 with median error
  // 0.0047 (0.0005); colour scale fixed 0.001; grey 0.861. Constant light:
  // see the printout (fixed scales lose almost nothing there).
  EXPECT_GT(def.completeness, 0.78);
  EXPECT_GT(nl.completeness, 0.45);
  EXPECT_LT(nl.completeness, def.completeness - 0.15);
  EXPECT_GT(nl.inlier_ratio, 0.9);
  EXPECT_GT(nn.completeness, 0.6);
  EXPECT_GT(nn.median_rel, 2 * def.median_rel);
  EXPECT_GT(gr.completeness, 0.78);
  EXPECT_LT(fs.completeness, def.completeness - 0.5);
  // The control: with constant light the scales are 1 and fixing them
  // costs at most a few percent.
  EXPECT_GT(cdef.completeness, 0.78);
  EXPECT_GT(cfs.completeness, cdef.completeness - 0.05);
}

}  // namespace
}  // namespace wild_mvs
