// Copyright wild_mvs authors.
#include "wild_mvs/core/rescaling.h"

#include <algorithm>
#include <cmath>

#include "wild_mvs/core/error.h"
#include "wild_mvs/core/global_view_selection.h"

namespace wild_mvs {

double ScaleRatio(const Scene& scene, int ref, int view,
                  const std::vector<std::vector<int>>& points_per_view,
                  const Eigen::Vector3d* fallback_point) {
  const Camera& cr = scene.views[ref].camera;
  const Camera& cv = scene.views[view].camera;
  double sum = 0;
  int n = 0;
  if (ref < static_cast<int>(points_per_view.size())) {
    for (int p : points_per_view[ref]) {
      const SparsePoint& sp = scene.points[p];
      bool seen = false;
      for (const Observation& o : sp.track) seen |= o.view == view;
      if (!seen) continue;
      const double zr = cr.Depth(sp.xyz), zv = cv.Depth(sp.xyz);
      if (zr <= 0 || zv <= 0) continue;
      sum += FeatureScale(cr, sp.xyz) / FeatureScale(cv, sp.xyz);
      ++n;
    }
  }
  if (n > 0) return sum / n;
  if (fallback_point && cr.Depth(*fallback_point) > 0 &&
      cv.Depth(*fallback_point) > 0)
    return FeatureScale(cr, *fallback_point) /
           FeatureScale(cv, *fallback_point);
  return 1.0;
}

RescalingPlan PlanRescaling(const Scene& scene, int ref,
                            const std::vector<int>& neighbors,
                            const std::vector<double>& scales, bool rescale,
                            int max_image_size) {
  Require(scales.size() == neighbors.size(),
          "PlanRescaling: one scale per neighbour expected");
  RescalingPlan plan;
  plan.scales = scales;
  const Camera& cr = scene.views[ref].camera;
  double f = 1.0;
  if (rescale && !scales.empty()) {
    const double smin = *std::min_element(scales.begin(), scales.end());
    if (smin < kRescaleMinScale) f = smin / kRescaleMinScale;
  }
  if (max_image_size > 0) {
    const int longest = std::max(cr.width, cr.height);
    if (longest * f > max_image_size)
      f = static_cast<double>(max_image_size) / longest;
  }
  f = std::min(f, 1.0);
  plan.ref_factor = f;
  plan.ref_camera = f < 1.0 ? cr.Scaled(f) : cr;
  // Effective factor after rounding to whole pixels.
  const double fr = static_cast<double>(plan.ref_camera.width) / cr.width;
  for (size_t i = 0; i < neighbors.size(); ++i) {
    const Camera& cv = scene.views[neighbors[i]].camera;
    // After R's rescale, scale_R(V) becomes scales[i] / fr; a neighbour
    // above max_scale is downsampled to R's new scale (ratio 1).
    const double s = scales[i] / fr;
    if (rescale && s > kRescaleMaxScale) {
      plan.neighbor_cameras.push_back(cv.Scaled(1.0 / s));
    } else if (max_image_size > 0 &&
               std::max(cv.width, cv.height) > max_image_size) {
      const double g =
          static_cast<double>(max_image_size) / std::max(cv.width, cv.height);
      plan.neighbor_cameras.push_back(cv.Scaled(g));
    } else {
      plan.neighbor_cameras.push_back(cv);
    }
  }
  return plan;
}

}  // namespace wild_mvs
