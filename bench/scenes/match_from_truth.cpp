// Copyright wild_mvs authors. Whether MPGC can match a family scene's
// pixels at all (not a test): for every 4th pixel and row of every view of
// a rendered family scene (families.h), MPGC (default options, the
// window's size and step as given) started at the exact depth and normal,
// every other view a neighbour and each image's noise estimated as
// ReconstructView does. The pixels whose surface point at least
// mpgc.min_active_views other views see (their ground-truth depth agrees
// within 1 %) are put in one class each, pooled over the views:
//   right        converged within 1 % of the true depth;
//   wrong        converged elsewhere;
//   few_entered  failed: fewer than min_active_views views reached
//                local.min_ncc at the true plane (the window's texture is
//                too weak against the images' noise and light changes);
//   other        failed otherwise (a view dropped below drop_ncc, the
//                window left an image, oscillation, no convergence).
// The renderer's linear images are used as they are (before the 8-bit
// encoding of make_scene). docs/METHODS.md, "Where coverage is lost".
//
//   match_from_truth relief|weak [--seed S] [--window N] [--step K]
//                    [--width W]
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "families.h"
#include "patch_context_util.h"
#include "wild_mvs/core/error.h"
#include "wild_mvs/core/image_noise.h"
#include "wild_mvs/core/mpgc.h"

namespace wild_mvs {
namespace {

struct Tally {
  long pixels = 0, right = 0, wrong = 0, few_entered = 0, other = 0;
};

// Other views whose ground truth sees the surface point of (x, y) in ref.
int SeenBy(const testing::SyntheticScene& s, int ref, int x, int y) {
  const Camera& rc = s.scene.views[ref].camera;
  const Eigen::Vector3d X = rc.Backproject(Eigen::Vector2d(x + 0.5, y + 0.5),
                                           s.depth[ref].at<float>(y, x));
  int seen = 0;
  for (size_t v = 0; v < s.scene.views.size(); ++v) {
    if (static_cast<int>(v) == ref) continue;
    const Camera& c = s.scene.views[v].camera;
    Eigen::Vector2d q;
    if (!c.Project(X, &q)) continue;
    const int qx = static_cast<int>(std::floor(q.x()));
    const int qy = static_cast<int>(std::floor(q.y()));
    if (qx < 0 || qy < 0 || qx >= s.depth[v].cols || qy >= s.depth[v].rows)
      continue;
    const float zv = s.depth[v].at<float>(qy, qx);
    seen += zv > 0 && std::abs(zv - c.Depth(X)) < 0.01 * zv;
  }
  return seen;
}

Tally MatchView(const testing::SyntheticScene& s, int ref,
                const MpgcOptions& mo) {
  PatchContext ctx = testing::MakeContext(s, ref);
  ctx.window = mo.window;
  ctx.ref_noise = NoiseProfile::Estimate(ctx.ref_image);
  for (PatchView& v : ctx.views) v.noise = NoiseProfile::Estimate(v.image);
  PatchMatcher matcher(ctx, mo, LocalViewSelectionOptions());
  Tally t;
  const cv::Mat& depth = s.depth[ref];
  for (int y = 6; y < depth.rows - 6; y += 4)
    for (int x = 6; x < depth.cols - 6; x += 4) {
      const float z = depth.at<float>(y, x);
      if (!(z > 0) || SeenBy(s, ref, x, y) < mo.min_active_views) continue;
      ++t.pixels;
      const cv::Vec3f n = s.normals[ref].at<cv::Vec3f>(y, x);
      MatchTrace trace;
      PatchResult r;
      if (matcher.Match(x, y, z, Eigen::Vector3d(n[0], n[1], n[2]), &r,
                        &trace)) {
        ++(std::abs(r.depth - z) <= 0.01 * z ? t.right : t.wrong);
      } else if (trace.Count(MatchTrace::Kind::kEntered) <
                 mo.min_active_views) {
        ++t.few_entered;
      } else {
        ++t.other;
      }
    }
  return t;
}

int Run(int argc, char** argv) {
  Require(argc >= 2,
          "usage: match_from_truth relief|weak [--seed S] "
          "[--window N] [--step K] [--width W]");
  const std::string kind = argv[1];
  Require(kind == "relief" || kind == "weak",
          "match_from_truth: unknown family '", kind, "' (relief or weak)");
  families::FamilyOptions fo;
  MpgcOptions mo;
  mo.window_step = 1;
  for (int i = 2; i + 1 < argc; i += 2) {
    const std::string a = argv[i];
    const int v = std::atoi(argv[i + 1]);
    if (a == "--seed")
      fo.seed = static_cast<unsigned>(v);
    else if (a == "--window")
      mo.window = v;
    else if (a == "--step")
      mo.window_step = v;
    else if (a == "--width")
      fo.width = v, fo.height = v * 3 / 4;
    else
      Require(false, "match_from_truth: unknown argument '", a, "'");
  }
  mo.Check();
  const testing::SyntheticScene s =
      testing::Render(kind == "relief" ? families::ReliefScene(fo)
                                       : families::WeakTextureScene(fo));
  Tally all;
  for (size_t v = 0; v < s.scene.views.size(); ++v) {
    const Tally t = MatchView(s, static_cast<int>(v), mo);
    all.pixels += t.pixels;
    all.right += t.right;
    all.wrong += t.wrong;
    all.few_entered += t.few_entered;
    all.other += t.other;
  }
  const double n = std::max(1L, all.pixels);
  std::printf(
      "%s seed %u %dx%d, window %d step %d: %ld pixels seen by >= %d other "
      "views; right %.3f wrong %.3f few_entered %.3f other %.3f\n",
      kind.c_str(), fo.seed, fo.width, fo.height, mo.window, mo.window_step,
      all.pixels, mo.min_active_views, all.right / n, all.wrong / n,
      all.few_entered / n, all.other / n);
  return 0;
}

}  // namespace
}  // namespace wild_mvs

int main(int argc, char** argv) {
  try {
    return wild_mvs::Run(argc, argv);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "%s\n", e.what());
    return 1;
  }
}
