// Copyright wild_mvs authors. Re-seeding and refining a view's depth map
// after the geometric-consistency filter (beyond the paper; docs/ALGORITHM.md
// section 5.4), inside the region-growing framework.
//
// The first pass (ReconstructView) leaves holes: pixels growth never
// reached, and pixels whose depth the consistency filter removed. The
// second pass grows R's map again, starting from the filtered map itself:
//  (a) every consistent sample of R that borders an empty pixel is a held
//      seed (Seed::held): its empty 4-neighbours are queued with its plane,
//      as if it had just been grown;
//  (b) the neighbours' consistent samples are reprojected into R (nearest
//      depth per pixel, their normals rotated into R's frame); one per
//      `neighbor_seed_stride` x `neighbor_seed_stride` block of R's empty
//      pixels is a seed, matched from the reprojected plane.
// Every candidate still goes through MPGC and its acceptance rule, and the
// result is filtered again by the pipeline (like OpenMVS's geometric
// iterations fill holes from the neighbours' estimates, but without a
// geometric term in the cost).
#pragma once

#include <atomic>
#include <string>
#include <vector>

#include "wild_mvs/core/depth_map.h"
#include "wild_mvs/core/option_registry.h"
#include "wild_mvs/core/region_growing.h"

namespace wild_mvs {

struct RefinementOptions {
  // (beyond the paper) Run the second growing pass after the consistency
  // filter, then the filter again (`wild_mvs reconstruct`; needs
  // mvs.consistency.enabled, ignored without it). Off by default and in
  // --preset paper: measured (docs/EVALUATION.md) fountain-P11 +0.8 points
  // of completeness at the same accuracy for +25 % CPU, but the rendered
  // `clutter` scene regresses (off by more than 5 %: 1.85 -> 2.07 %;
  // growth from samples of the background confirmed behind one-view
  // occluders).
  bool enabled = false;
  // (a) Grow from R's own consistent samples into the empty pixels.
  bool grow_from_consistent = true;
  // (b) Seeds from the neighbours' consistent samples reprojected into R's
  // empty pixels: one per block of this many pixels square; 0 = none. Off
  // by default: behind an occluder seen by R alone, the neighbours'
  // background is matched and confirmed (test_view_refinement); measured
  // on fountain-P11 (docs/EVALUATION.md) 4: completeness +0.7 points more
  // than without, background estimates 1.60 -> 1.99 %, +30 CPU-s.
  int neighbor_seed_stride = 0;
  // The filter after the second pass: a sample it added (or changed) must
  // be confirmed by this many neighbours' maps (the others by
  // consistency.min_consistent). With 1, fountain-P11's accuracy fell to
  // 96.9 % within 1 % (from 97.1 %).
  int min_consistent_new = 2;
  void Check() const;
};
// Registers the fields under `prefix` (option_registry.h), e.g. "mvs.refine".
void RegisterOptions(OptionRegistry* registry, const std::string& prefix,
                     RefinementOptions* options);

struct RefinementSeedStats {
  int held = 0;      // (a) consistent samples that border an empty pixel
  int neighbor = 0;  // (b) seeds from the neighbours' reprojected samples
};

// The seeds of R's second pass: (a) and (b) above, in a fixed order (held
// seeds row-major, then the neighbour seeds block-row-major). `own`: R's
// filtered map at R's working resolution; `neighbors`: the neighbours'
// filtered maps (any resolution; null or empty ones are skipped); mask
// (CV_8U of own's size, may be empty): 0 = never seed there.
std::vector<Seed> RefinementSeeds(const DepthMap& own,
                                  const std::vector<const DepthMap*>& neighbors,
                                  const cv::Mat& mask,
                                  const RefinementOptions& options,
                                  RefinementSeedStats* stats);

}  // namespace wild_mvs
