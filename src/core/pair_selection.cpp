// Copyright wild_mvs authors. Pair selection of the sparse tracker:
// the earlier views a new view is matched against, by frustum overlap.
#include <algorithm>
#include <cmath>

#include "sparse_tracker_impl.h"
#include "wild_mvs/core/stats.h"
#include "wild_mvs/core/triangulation.h"
#include "wild_mvs/core/view_geometry.h"

namespace wild_mvs {

using sparse_internal::kDeg;
using sparse_internal::kMaxPairAngleDeg;
using sparse_internal::kMinOverlap;

// Typical depth of the scene seen by `cam` (0 = unknown).
double SparseTracker::Impl::EstimateDepth(const Camera& cam) const {
  if (opt.scene_depth) return *opt.scene_depth;
  std::vector<double> depths;
  for (const auto& kv : points) {
    if (!kv.second.valid) continue;
    Eigen::Vector2d px;
    const Eigen::Vector3d& X = kv.second.point.xyz;
    if (cam.Project(X, &px) && cam.InImage(px)) depths.push_back(cam.Depth(X));
  }
  if (depths.size() >= 20) return Median(depths);
  // Convergence of the optical axes.
  depths.clear();
  const double min_sin2 = std::pow(std::sin(1.0 * kDeg), 2);  // ~parallel
  for (const ViewData& v : views) {
    if (v.removed) continue;
    double s;
    if (AxesClosestApproachDepth(cam, v.camera, min_sin2, &s)) {
      depths.push_back(s);
    }
  }
  return depths.empty() ? 0 : Median(depths);
}

std::vector<int> SparseTracker::Impl::SelectNeighbors(const Camera& cam) const {
  const double depth = EstimateDepth(cam);
  const Eigen::Vector3d c = cam.Center();
  const double min_angle = opt.min_triangulation_angle_deg * kDeg;
  std::vector<std::pair<double, int>> scored;  // (-score, slot)
  for (size_t s = 0; s < views.size(); ++s) {
    const ViewData& v = views[s];
    if (v.removed) continue;
    const double axis_angle = std::acos(std::min(
        1.0,
        std::max(-1.0, cam.ViewDirection().dot(v.camera.ViewDirection()))));
    if (axis_angle > kMaxPairAngleDeg * kDeg) continue;
    const double b = (v.camera.Center() - c).norm();
    if (!(b > 0)) continue;
    double score = 0;
    if (depth > 0) {
      const double overlap =
          FrustumGridOverlap(cam, v.camera,
                             {0.5 * depth, std::sqrt(0.5) * depth, depth,
                              std::sqrt(2.0) * depth, 2 * depth});
      if (overlap < kMinOverlap) continue;
      const Eigen::Vector3d X = cam.Backproject(
          Eigen::Vector2d(0.5 * cam.width, 0.5 * cam.height), depth);
      const double angle = TriangulationAngle(c, v.camera.Center(), X);
      // Too small an angle at the typical depth: only far-off structure
      // would pass the angle filter.
      if (angle < 0.5 * min_angle) continue;
      score = overlap * std::min(1.0, angle / (10 * kDeg));
    } else {
      // Unknown depth: sweep the depths at which the pair's triangulation
      // angle lies between ~60 degrees and the minimum angle.
      const double far = b / std::tan(std::max(min_angle, 0.5 * kDeg));
      std::vector<double> depths;
      for (double d = b; d <= far * 1.0001; d *= 2) depths.push_back(d);
      score = FrustumGridOverlap(cam, v.camera, depths);
      if (score < kMinOverlap) continue;
    }
    scored.emplace_back(-score, static_cast<int>(s));
  }
  std::sort(scored.begin(), scored.end());
  std::vector<int> slots;
  for (size_t k = 0;
       k < scored.size() && static_cast<int>(k) < opt.max_neighbors; ++k) {
    slots.push_back(scored[k].second);
  }
  return slots;
}

}  // namespace wild_mvs
