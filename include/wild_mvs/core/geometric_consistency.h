// Copyright wild_mvs authors. Geometric consistency of depth maps (beyond
// the paper; docs/ALGORITHM.md section 5.3): every depth sample of a view is
// checked against its neighbours' depth maps by forward-backward
// reprojection, as current systems (COLMAP's and OpenMVS's filtering) do.
//
// For a sample z at pixel p of R: X = the point it names; q = X projected
// into neighbour V; z_V = V's depth at the pixel containing q; Y = that
// depth's point; p', z' = Y projected into R. V confirms the sample when V
// has a depth there, |p' - p| <= max_reprojection_px (pixels of R) and
// |z' - z| <= max_relative_depth * z. A sample that fewer than
// min_consistent neighbours confirm is removed: a wrong depth is rarely
// confirmed by another view's independent estimate, a right one usually is.
#pragma once

#include <string>
#include <vector>

#include "wild_mvs/core/depth_map.h"
#include "wild_mvs/core/option_registry.h"

namespace wild_mvs {

struct GeometricConsistencyOptions {
  bool enabled = true;  // false = keep every sample (the paper)
  // Neighbours that must confirm a sample (COLMAP: 2 of its sources;
  // OpenMVS: 2 views in all).
  int min_consistent = 1;
  double max_reprojection_px = 1.0;  // forward-backward distance in R
  double max_relative_depth = 0.01;  // |z' - z| / z
  // Pixels of V tried around the one containing q: 0 = that pixel only; 1 =
  // its 3x3 neighbourhood (any of them confirming is enough), which forgives
  // the up to 0.7 px between q and the centre of the pixel containing it.
  int search_px = 0;
  void Check() const;
};

// Registers the fields under `prefix` (option_registry.h).
void RegisterOptions(OptionRegistry* registry, const std::string& prefix,
                     GeometricConsistencyOptions* options);

struct ConsistencyStats {
  long long samples = 0;  // valid samples before
  long long kept = 0;     // confirmed by >= min_consistent neighbours
  long long removed() const { return samples - kept; }
};

// Per pixel of ref, the number of `neighbors` (maps of other views, any
// resolution) that confirm its depth (CV_8U; 0 where ref has no depth).
cv::Mat CountConsistentViews(const DepthMap& ref,
                             const std::vector<const DepthMap*>& neighbors,
                             const GeometricConsistencyOptions& options);

// Removes the samples of *ref (depth, normal and confidence set to 0) that
// fewer than options.min_consistent of `neighbors` confirm. No-op when
// disabled or when no neighbour map is given (nothing to check against:
// stats->kept = samples).
// earlier (CV_32F of ref's size, may be empty): an earlier map of the same
// view (the second pass's start, view_refinement.h); the samples of *ref
// that differ from it (new or changed) need max(min_consistent,
// min_consistent_new) confirmations instead.
void FilterByConsistency(DepthMap* ref,
                         const std::vector<const DepthMap*>& neighbors,
                         const GeometricConsistencyOptions& options,
                         ConsistencyStats* stats,
                         const cv::Mat& earlier = cv::Mat(),
                         int min_consistent_new = 0);

}  // namespace wild_mvs
