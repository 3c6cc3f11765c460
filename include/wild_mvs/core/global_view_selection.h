// Copyright wild_mvs authors. Global view selection (paper section 5.1 /
// docs/ALGORITHM.md section 1): the image-level neighbourhood N of a reference
// view R, chosen from the structure-from-motion features both views share.
#pragma once

#include <string>
#include <vector>

#include "wild_mvs/core/option_registry.h"
#include "wild_mvs/core/scene.h"

namespace wild_mvs {

struct GlobalViewSelectionOptions {
  int num_neighbors = 10;  // |N|, [1, 32] (paper: 10)
  // Not registered (the paper's and our fixed values; tests vary them):
  // max_parallax_deg, a_max of the parallax weight (paper: 10); a candidate
  // whose median triangulation angle with R is below min_baseline_deg
  // never enters N (twins add no depth information); the fallback without
  // shared features accepts at most fallback_max_baseline_deg.
  double max_parallax_deg = 10;
  double min_baseline_deg = 2.5;
  double fallback_max_baseline_deg = 45;
  void Check() const;
};
// Registers the fields under `prefix` (option_registry.h), e.g. "mvs.global".
void RegisterOptions(OptionRegistry* registry, const std::string& prefix,
                     GlobalViewSelectionOptions* options);

struct GlobalViewSelection {
  std::vector<int> neighbors;          // scene view indices, in selection order
  std::vector<double> scores;          // g_R(V) when V was selected (> 0)
  std::vector<std::string> fallbacks;  // "fallback: ..." notes
};

// Diameter of the sphere at X whose projection in `cam` is one pixel (the
// paper's s_X(f) = depth / focal).
double FeatureScale(const Camera& cam, const Eigen::Vector3d& X);

// The paper's greedy selection by shared-feature score g_R(V) with parallax
// weight w_N and resolution weight w_s. points_per_view is
// scene.PointsPerView(). Falls back to SelectViewsByFrustumOverlap (noted in
// `fallbacks`) when no candidate scores above zero.
GlobalViewSelection SelectGlobalViews(
    const Scene& scene, int ref,
    const std::vector<std::vector<int>>& points_per_view,
    const GlobalViewSelectionOptions& options);

// Fallback without shared features: neighbours scored by the overlap of
// their frustum with R's at `scene_depth` (z in R), the parallax weight of
// their baseline at that depth and the resolution weight.
GlobalViewSelection SelectViewsByFrustumOverlap(
    const Scene& scene, int ref, double scene_depth,
    const GlobalViewSelectionOptions& options);

// Views whose own points give the scene depth of a view that sees none.
constexpr int kNearestViewsForDepth = 3;

// A typical scene depth (z in R) for R: the median depth of the sparse points
// R sees; else of all sparse points inside R's frustum; else the depths of
// the points seen by the kNearestViewsForDepth views whose centres are
// nearest R's, each in its own view (a view whose texture gave no feature
// looks at a scene as far away as its nearest views do); else where the
// optical axes of R and the other views pass closest. Returns 0 when none
// of these exists.
double EstimateSceneDepth(const Scene& scene, int ref,
                          const std::vector<std::vector<int>>& points_per_view,
                          double* min_depth, double* max_depth);

}  // namespace wild_mvs
