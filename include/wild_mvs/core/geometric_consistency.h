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
//
// Free-space violations (stability, as in Merrell et al., "Real-time
// visibility-based fusion of depth maps", ICCV 2007): V's depth at the pixel
// containing q lies beyond X by more than free_space_margin (z_V > (1 +
// margin) d_V(X)), so V sees through the sample: either the sample or V's
// depth is wrong. A sample also needs at least as many confirmations as
// violations. Wrong depths floating in front of
// the surface (sky, background seen through gaps) are contradicted by the
// many views that see past them; a right depth is at most contradicted by
// the few views whose own estimate there is wrong.
#pragma once

#include <string>
#include <vector>

#include "wild_mvs/core/depth_map.h"
#include "wild_mvs/core/option_registry.h"

namespace wild_mvs {

struct GeometricConsistencyOptions {
  int min_consistent = 1;  // neighbours that must confirm a sample, [1, 32]
  double max_reprojection_px = 1.0;  // forward-backward distance in R, px
  double max_relative_depth = 0.01;  // |z' - z| / z, (0, 1)
  // Free-space violations counted beyond this relative depth, [0, 1); a
  // sample needs confirmations >= violations.
  double free_space_margin = 0.01;
  // Pixels of V tried around the one containing q, [0, 3] (not registered;
  // tests vary it): 0 = that pixel only; 1 = its 3x3 neighbourhood (any of
  // them confirming is enough).
  int search_px = 1;
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
// violations (may be null): the number that see through it (CV_8U).
cv::Mat CountConsistentViews(const DepthMap& ref,
                             const std::vector<const DepthMap*>& neighbors,
                             const GeometricConsistencyOptions& options,
                             cv::Mat* violations = nullptr);

// Removes the samples of *ref (depth, normal and confidence set to 0) that
// fewer than options.min_consistent of `neighbors` confirm, or that more
// neighbours see through than confirm.
// No-op when no neighbour map is given (nothing to check against:
// stats->kept = samples).
void FilterByConsistency(DepthMap* ref,
                         const std::vector<const DepthMap*>& neighbors,
                         const GeometricConsistencyOptions& options,
                         ConsistencyStats* stats);

}  // namespace wild_mvs
