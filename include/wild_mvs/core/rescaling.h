// Copyright wild_mvs authors. Rescaling (paper section 5.1 / ALGORITHM.md
// section 2): match R and its neighbours at comparable resolutions.
#pragma once

#include <vector>

#include "wild_mvs/core/scene.h"

namespace wild_mvs {

// t: R is downsampled when scale_R(V_min) < t (paper: 0.6).
constexpr double kRescaleMinScale = 0.6;
// Neighbours whose scale exceeds this are downsampled (paper: 1.2).
constexpr double kRescaleMaxScale = 1.2;

// scale_R(V) = mean over shared features of s_R(f) / s_V(f). Without shared
// features, the ratio of the pixel footprints at `fallback_point` (a point
// in front of both) is used; 1 when that is not possible either.
double ScaleRatio(const Scene& scene, int ref, int view,
                  const std::vector<std::vector<int>>& points_per_view,
                  const Eigen::Vector3d* fallback_point);

struct RescalingPlan {
  Camera ref_camera;                     // R at its working resolution
  double ref_factor = 1;                 // working / original size of R
  std::vector<Camera> neighbor_cameras;  // per neighbour, matching size
  std::vector<double> scales;            // scale_R(V) before rescaling
};

// Decides the working resolutions: with `rescale` (false = the ablation)
// R is downsampled when its coarsest neighbour's scale is below
// kRescaleMinScale and neighbours above kRescaleMaxScale to R's scale.
// max_image_size > 0 additionally limits
// the longest side of R's working image.
RescalingPlan PlanRescaling(const Scene& scene, int ref,
                            const std::vector<int>& neighbors,
                            const std::vector<double>& scales, bool rescale,
                            int max_image_size);

}  // namespace wild_mvs
