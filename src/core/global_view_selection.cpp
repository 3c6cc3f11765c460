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
    // The nearest views' own point depths (R's camera sees none of the
    // points: no feature of its own, and none of the others' in its view).
    std::vector<std::pair<double, int>> near;
    for (size_t v = 0; v < scene.views.size(); ++v) {
      if (static_cast<int>(v) == ref || v >= points_per_view.size() ||
          points_per_view[v].empty())
        continue;
      near.emplace_back(
          (scene.views[v].camera.Center() - cr.Center()).squaredNorm(),
          static_cast<int>(v));
    }
    std::sort(near.begin(), near.end());
    for (size_t k = 0;
         k < near.size() && static_cast<int>(k) < kNearestViewsForDepth; ++k) {
      const Camera& cv = scene.views[near[k].second].camera;
      for (int p : points_per_view[near[k].second]) {
        const double z = cv.Depth(scene.points[p].xyz);
        if (z > 0 && std::isfinite(z)) depths.push_back(z);
      }
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

  // R's features, flattened: feature f's observing views (deduplicated, in
  // track order) and their unit lines of sight are obs_view / obs_dir
  // [f.begin, f.begin + f.count). Everything below touches only R's
  // features and the views that see them, so the cost of a call does not
  // grow with the collection (for a given track length).
  struct Feature {
    Eigen::Vector3d X;
    int begin = 0, count = 0;
    double within = 1;  // product of w_a over pairs inside N
    double s_ref = 0;
    // Members of N that see the feature, in the order they entered N, as
    // slots; pw[k * count + s] = ParallaxWeight(dir of member k, dir of s).
    std::vector<int> members;
    std::vector<double> pw;
  };
  std::vector<Feature> feats;
  std::vector<int> obs_view;
  std::vector<Eigen::Vector3d> obs_dir;
  const std::vector<int> empty;
  const std::vector<int>& mine = ref < static_cast<int>(points_per_view.size())
                                     ? points_per_view[ref]
                                     : empty;
  feats.reserve(mine.size());
  for (int p : mine) {
    const SparsePoint& sp = scene.points[p];
    if (cr.Depth(sp.xyz) <= 0) continue;
    Feature f;
    f.X = sp.xyz;
    f.s_ref = FeatureScale(cr, sp.xyz);
    f.begin = static_cast<int>(obs_view.size());
    for (const Observation& o : sp.track) {
      if (o.view < 0 || o.view >= nv) continue;
      bool dup = false;
      for (int k = f.begin; k < static_cast<int>(obs_view.size()); ++k)
        dup |= obs_view[k] == o.view;
      if (dup) continue;
      const Camera& c = scene.views[o.view].camera;
      if (c.Depth(sp.xyz) <= 0) continue;
      obs_view.push_back(o.view);
      obs_dir.push_back((sp.xyz - c.Center()).normalized());
    }
    f.count = static_cast<int>(obs_view.size()) - f.begin;
    feats.push_back(std::move(f));
  }
  // Enters the view of slot s into f's members: its parallax weights with
  // every view of f (computed once, used by every later score).
  auto add_member = [&](Feature* f, int s) {
    const Eigen::Vector3d& dm = obs_dir[f->begin + s];
    f->members.push_back(s);
    for (int k = 0; k < f->count; ++k)
      f->pw.push_back(ParallaxWeight(dm, obs_dir[f->begin + k], amax));
  };

  // The other views seeing R's features, ascending, each with its features
  // (ascending) as (feature, slot, resolution weight w_s).
  struct Entry {
    int view, feature, slot;
    double ws;
  };
  std::vector<Entry> entries;
  entries.reserve(obs_view.size());
  std::vector<int> ref_slot(feats.size(), -1);
  for (size_t fi = 0; fi < feats.size(); ++fi) {
    Feature& f = feats[fi];
    for (int s = 0; s < f.count; ++s) {
      const int v = obs_view[f.begin + s];
      if (v == ref) {
        ref_slot[fi] = s;
        continue;
      }
      const double r = f.s_ref / FeatureScale(scene.views[v].camera, f.X);
      entries.push_back({v, static_cast<int>(fi), s, ResolutionWeight(r)});
    }
  }
  std::sort(entries.begin(), entries.end(), [](const Entry& a, const Entry& b) {
    return a.view != b.view ? a.view < b.view : a.feature < b.feature;
  });
  // Candidates: share features and have parallax with R.
  struct Candidate {
    int view;
    size_t begin, end;  // into entries
    bool taken = false;
  };
  std::vector<Candidate> candidates;
  std::vector<double> angles;
  for (size_t e0 = 0; e0 < entries.size();) {
    size_t e1 = e0;
    while (e1 < entries.size() && entries[e1].view == entries[e0].view) ++e1;
    angles.clear();
    for (size_t e = e0; e < e1; ++e) {
      const Feature& f = feats[entries[e].feature];
      const int rs = ref_slot[entries[e].feature];
      if (rs < 0) continue;
      const Eigen::Vector3d& dr = obs_dir[f.begin + rs];
      const Eigen::Vector3d& dv = obs_dir[f.begin + entries[e].slot];
      angles.push_back(std::acos(std::clamp(dr.dot(dv), -1.0, 1.0)));
    }
    if (!(Median(angles) < options.min_baseline_deg * kDeg))
      candidates.push_back({entries[e0].view, e0, e1});
    e0 = e1;
  }
  for (size_t fi = 0; fi < feats.size(); ++fi)
    if (ref_slot[fi] >= 0) add_member(&feats[fi], ref_slot[fi]);

  GlobalViewSelection out;
  while (static_cast<int>(out.neighbors.size()) < options.num_neighbors) {
    double best = 0;
    Candidate* chosen = nullptr;
    for (Candidate& c : candidates) {
      if (c.taken) continue;
      double score = 0;
      for (size_t e = c.begin; e < c.end; ++e) {
        const Feature& f = feats[entries[e].feature];
        double w = f.within;
        for (size_t k = 0; k < f.members.size(); ++k)
          w *= f.pw[k * f.count + entries[e].slot];
        score += w * entries[e].ws;
      }
      if (score > best) {
        best = score;
        chosen = &c;
      }
    }
    if (!chosen) break;
    // Update the within-N products of the features the new view sees.
    for (size_t e = chosen->begin; e < chosen->end; ++e) {
      Feature& f = feats[entries[e].feature];
      for (size_t k = 0; k < f.members.size(); ++k)
        f.within *= f.pw[k * f.count + entries[e].slot];
      add_member(&f, entries[e].slot);
    }
    chosen->taken = true;
    out.neighbors.push_back(chosen->view);
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
