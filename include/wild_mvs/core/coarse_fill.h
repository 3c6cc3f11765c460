// Copyright wild_mvs authors. Multi-scale: a view's map matched at half its
// working size fills the pixels its full-size map left empty. A window of
// the same pixel count covers four times the surface at half size, so it
// matches where the texture is too weak for the full-size window
// (docs/ALGORITHM.md, 5.4 "Coarse fill").
#pragma once

#include <opencv2/core.hpp>

#include "wild_mvs/core/depth_map.h"
#include "wild_mvs/core/image_noise.h"

namespace wild_mvs {

// The colour weight of a window pixel in the edge-aware texture test: a
// Gaussian of its colour distance to the centre's, of deviation
// kEdgeAwareSigma x the centre's brightness + 2 noise deviations. Chosen on
// the tuning seeds among 0.06 / 0.10 / 0.15 (docs/METHODS.md, "Coarse
// fill"): the smallest keeps every half-size sample beside a silhouette off
// the sky.
constexpr double kEdgeAwareSigma = 0.06;

// Where a fine map may be filled from its half-size map, and from which
// half-size samples.
struct CoarseFillMasks {
  // CV_8U of the fine map's size, 255 = fill: no estimate, the full-size
  // window cannot match (WindowsBelowNoise) and the pixel's half-size
  // window has texture on its own side of any edge.
  cv::Mat fillable;
  // CV_8U of the half-size map's size, 255 = a sample that may fill: its
  // own half-size window has texture on its side of any edge (a sample on
  // a textureless sky beside a silhouette, which the silhouette's edge
  // matched at the surface's depth, does not).
  cv::Mat usable;
  int count = 0;  // nonzero pixels of `fillable`
};

// The masks of `fine` (the map at full size) over its view's `image`
// (CV_32FC3, linear, the map's size); the half-size map will be
// (image.cols + 1) / 2 x (image.rows + 1) / 2. `window` and `kappa` as
// WindowsBelowNoise.
CoarseFillMasks PlanCoarseFill(const cv::Mat& image, const DepthMap& fine,
                               int window, double kappa);

// For every pixel of `fine` without an estimate: the four coarse samples
// around it (bilinear footprint) must all exist and their planes (depth and
// normal) must predict depths within `max_spread` (relative) of each other
// along the fine pixel's ray, i.e. lie on one continuous surface; then the
// pixel takes their bilinearly weighted prediction, the nearest coarse
// sample's normal and confidence. Both maps are of the same view (same
// pose); `coarse` at any smaller size. Returns the number of pixels filled.
// Only coarse samples whose neighbours within `interior_radius` (coarse
// pixels, square) all exist take part: the coarse window's half width keeps
// its fattening at silhouettes out. max_spread in (0, 1).
// `coarse_usable` (CV_8U of the coarse map's size, empty = every sample):
// only its nonzero samples take part. `fillable` (CV_8U of the fine map's
// size, empty = everywhere): only its nonzero pixels are filled.
int FillFromCoarse(const DepthMap& coarse, const cv::Mat& coarse_usable,
                   double max_spread, int interior_radius,
                   const cv::Mat& fillable, DepthMap* fine);

// The pixels of `image` (CV_32FC3, linear) whose window x window window
// cannot reach NCC `kappa` against a noisy copy of itself: its reliability
// S / (S + N) (image_noise.h; N from `noise` at the window's brightness) is
// below kappa. There the full-size window cannot match even at the true
// plane, so a hole says nothing against the coarse map. CV_8U, 255 = such a
// pixel. With edge_aware_sigma > 0 each window pixel is weighted by its
// colour's closeness to the centre's (a Gaussian of deviation
// edge_aware_sigma x the centre's brightness + 2 noise deviations): a
// window beside an edge is judged by the texture of its own side.
cv::Mat WindowsBelowNoise(const cv::Mat& image, const NoiseProfile& noise,
                          int window, double kappa,
                          double edge_aware_sigma = 0);

}  // namespace wild_mvs
