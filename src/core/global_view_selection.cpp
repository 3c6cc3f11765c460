// Copyright wild_mvs authors.
#include "wild_mvs/core/global_view_selection.h"

#include <algorithm>
#include <cmath>

#include "wild_mvs/core/error.h"
#include "wild_mvs/core/stats.h"
#include "wild_mvs/core/view_geometry.h"

namespace wild_mvs {
namespace {

constexpr double kDeg = M_PI / 180.0;

double ParallaxWeight(const Eigen::Vector3d& d1, const Eigen::Vector3d& d2,
                      double max_rad) {
  const double c = std::clamp(d1.dot(d2), -1.0, 1.0);
  const double a = std::acos(c);
  const double w = (a / max_rad) * (a / max_rad);
  return std::min(w, 1.0);
}

double ResolutionWeight(double r) {
  if (r >= 2) return 2.0 / r;
  if (r >= 1) return 1.0;
  return r;
}

double Percentile(std::vector<double> v, double q) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  const size_t i = std::min(v.size() - 1, static_cast<size_t>(q * v.size()));
  return v[i];
}

}  // namespace

void GlobalViewSelectionOptions::Check() const {
  Require(num_neighbors >= 1 && num_neighbors <= 32,
          "mvs.global.num_neighbors = ", num_neighbors, " must be in [1, 32]");
  Require(max_parallax_deg > 0 && max_parallax_deg <= 90,
          "mvs.global.max_parallax_deg = ", max_parallax_deg,
          " must be in (0, 90]");
  Require(min_baseline_deg >= 0 && min_baseline_deg < 45,
          "mvs.global.min_baseline_deg = ", min_baseline_deg,
          " must be in [0, 45)");
  Require(fallback_max_baseline_deg > min_baseline_deg &&
              fallback_max_baseline_deg <= 180,
          "mvs.global.fallback_max_baseline_deg = ", fallback_max_baseline_deg,
          " must be in (min_baseline_deg, 180]");
}

void RegisterOptions(OptionRegistry* registry, const std::string& prefix,
                     GlobalViewSelectionOptions* o) {
  auto key = [&prefix](const char* name) {
    return OptionRegistry::Join(prefix, name);
  };
  registry
      ->Add(key("num_neighbors"), &o->num_neighbors,
            "global view selection: neighbourhood size |N| (paper: 10)")
      .Min(1)
      .Max(32);
  registry
      ->Add(key("max_parallax_deg"), &o->max_parallax_deg,
            "parallax weight a_max in degrees (paper: 10)")
      .Above(0)
      .Max(90);
  registry
      ->Add(key("min_baseline_deg"), &o->min_baseline_deg,
            "views with a smaller median triangulation angle never enter N "
            "(twins)")
      .Min(0)
      .Below(45);
  registry
      ->Add(key("fallback_max_baseline_deg"), &o->fallback_max_baseline_deg,
            "fallback without shared features: largest triangulation angle")
      .Max(180)
      .Note("> min_baseline_deg");
}

double FeatureScale(const Camera& cam, const Eigen::Vector3d& X) {
  return cam.PixelFootprint(cam.Depth(X));
}

double EstimateSceneDepth(const Scene& scene, int ref,
                          const std::vector<std::vector<int>>& points_per_view,
                          double* min_depth, double* max_depth) {
  const Camera& cr = scene.views[ref].camera;
  std::vector<double> depths;
  if (ref < static_cast<int>(points_per_view.size()))
    for (int p : points_per_view[ref]) {
      const double z = cr.Depth(scene.points[p].xyz);
      if (z > 0 && std::isfinite(z)) depths.push_back(z);
    }
  if (depths.empty()) {
    for (const SparsePoint& p : scene.points) {
      Eigen::Vector2d px;
      if (cr.Project(p.xyz, &px) && cr.InImage(px))
        depths.push_back(cr.Depth(p.xyz));
    }
  }
  if (depths.empty()) {
    // Closest approach of the optical axes of R and each other view.
    for (size_t v = 0; v < scene.views.size(); ++v) {
      if (static_cast<int>(v) == ref) continue;
      double s;
      if (AxesClosestApproachDepth(cr, scene.views[v].camera, 1e-6, &s)) {
        depths.push_back(s);
      }
    }
  }
  if (depths.empty()) {
    if (min_depth) *min_depth = 0;
    if (max_depth) *max_depth = 0;
    return 0;
  }
  if (min_depth) *min_depth = Percentile(depths, 0.02);
  if (max_depth) *max_depth = Percentile(depths, 0.98);
  return Median(depths);
}

GlobalViewSelection SelectViewsByFrustumOverlap(
    const Scene& scene, int ref, double scene_depth,
    const GlobalViewSelectionOptions& options) {
  GlobalViewSelection out;
  if (!(scene_depth > 0)) return out;
  const Camera& cr = scene.views[ref].camera;
  const Eigen::Vector3d X0 = cr.Backproject(
      Eigen::Vector2d(cr.width * 0.5, cr.height * 0.5), scene_depth);
  const Eigen::Vector3d dR = (X0 - cr.Center()).normalized();
  std::vector<std::pair<double, int>> scored;
  for (size_t v = 0; v < scene.views.size(); ++v) {
    if (static_cast<int>(v) == ref) continue;
    const Camera& cv = scene.views[v].camera;
    if (cv.Depth(X0) <= 0) continue;
    const Eigen::Vector3d dV = (X0 - cv.Center()).normalized();
    const double angle = std::acos(std::clamp(dR.dot(dV), -1.0, 1.0)) / kDeg;
    if (angle < options.min_baseline_deg ||
        angle > options.fallback_max_baseline_deg)
      continue;
    const double overlap = FrustumGridOverlap(cr, cv, {scene_depth});
    const double r = FeatureScale(cr, X0) / FeatureScale(cv, X0);
    const double score =
        overlap * ParallaxWeight(dR, dV, options.max_parallax_deg * kDeg) *
        ResolutionWeight(r);
    if (score > 0) scored.emplace_back(-score, static_cast<int>(v));
  }
  std::sort(scored.begin(), scored.end());
  for (const auto& s : scored) {
    if (static_cast<int>(out.neighbors.size()) >= options.num_neighbors) break;
    out.neighbors.push_back(s.second);
    out.scores.push_back(-s.first);
  }
  return out;
}

GlobalViewSelection SelectGlobalViews(
    const Scene& scene, int ref,
    const std::vector<std::vector<int>>& points_per_view,
    const GlobalViewSelectionOptions& options) {
  Require(ref >= 0 && ref < static_cast<int>(scene.views.size()),
          "SelectGlobalViews: no view ", ref);
  const double amax = options.max_parallax_deg * kDeg;
  const Camera& cr = scene.views[ref].camera;
  const int nv = static_cast<int>(scene.views.size());

  // R's features: for each, the views seeing it and their unit lines of
  // sight.
  struct Feature {
    Eigen::Vector3d X;
    std::vector<std::pair<int, Eigen::Vector3d>> seen;  // view, direction
    double within = 1;  // product of w_a over pairs inside N
    double s_ref = 0;
  };
  std::vector<Feature> feats;
  std::vector<std::vector<int>> cand_feats(nv);
  const std::vector<int> empty;
  const std::vector<int>& mine = ref < static_cast<int>(points_per_view.size())
                                     ? points_per_view[ref]
                                     : empty;
  for (int p : mine) {
    const SparsePoint& sp = scene.points[p];
    if (cr.Depth(sp.xyz) <= 0) continue;
    Feature f;
    f.X = sp.xyz;
    f.s_ref = FeatureScale(cr, sp.xyz);
    for (const Observation& o : sp.track) {
      if (o.view < 0 || o.view >= nv) continue;
      bool dup = false;
      for (const auto& s : f.seen) dup |= s.first == o.view;
      if (dup) continue;
      const Camera& c = scene.views[o.view].camera;
      if (c.Depth(sp.xyz) <= 0) continue;
      f.seen.emplace_back(o.view, (sp.xyz - c.Center()).normalized());
    }
    const int fi = static_cast<int>(feats.size());
    for (const auto& s : f.seen)
      if (s.first != ref) cand_feats[s.first].push_back(fi);
    feats.push_back(std::move(f));
  }
  auto direction = [&](const Feature& f, int view) -> const Eigen::Vector3d* {
    for (const auto& s : f.seen)
      if (s.first == view) return &s.second;
    return nullptr;
  };

  // Candidates: share features and have parallax with R.
  std::vector<int> candidates;
  for (int v = 0; v < nv; ++v) {
    if (v == ref || cand_feats[v].empty()) continue;
    std::vector<double> angles;
    for (int fi : cand_feats[v]) {
      const Eigen::Vector3d* dr = direction(feats[fi], ref);
      const Eigen::Vector3d* dv = direction(feats[fi], v);
      if (!dr || !dv) continue;
      angles.push_back(std::acos(std::clamp(dr->dot(*dv), -1.0, 1.0)));
    }
    if (Median(angles) < options.min_baseline_deg * kDeg) continue;
    candidates.push_back(v);
  }

  GlobalViewSelection out;
  std::vector<int> in_n{ref};
  std::vector<uint8_t> taken(nv, 0);
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
        for (int vi : in_n) {
          const Eigen::Vector3d* di = direction(f, vi);
          if (di) w *= ParallaxWeight(*di, *dv, amax);
        }
        const double r = f.s_ref / FeatureScale(scene.views[v].camera, f.X);
        score += w * ResolutionWeight(r);
      }
      if (score > best) {
        best = score;
        best_v = v;
      }
    }
    if (best_v < 0) break;
    // Update the within-N products of the features the new view sees.
    for (int fi : cand_feats[best_v]) {
      Feature& f = feats[fi];
      const Eigen::Vector3d* dv = direction(f, best_v);
      for (int vi : in_n) {
        const Eigen::Vector3d* di = direction(f, vi);
        if (di) f.within *= ParallaxWeight(*di, *dv, amax);
      }
    }
    taken[best_v] = 1;
    in_n.push_back(best_v);
    out.neighbors.push_back(best_v);
    out.scores.push_back(best);
  }

  if (out.neighbors.empty()) {
    double dmin = 0, dmax = 0;
    const double depth =
        EstimateSceneDepth(scene, ref, points_per_view, &dmin, &dmax);
    GlobalViewSelection fb =
        SelectViewsByFrustumOverlap(scene, ref, depth, options);
    fb.fallbacks.push_back(
        Msg("fallback: view '", scene.views[ref].name,
            "' shares no usable sparse feature with another view; ",
            fb.neighbors.size(),
            " neighbours chosen by frustum overlap, baseline and resolution at "
            "scene depth ",
            depth));
    return fb;
  }
  return out;
}

}  // namespace wild_mvs
