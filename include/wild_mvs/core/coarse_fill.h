// Copyright wild_mvs authors. Multi-scale: a view's map matched at half its
// working size fills the pixels its full-size map left empty. A window of
// the same pixel count covers four times the surface at half size, so it
// matches where the texture is too weak for the full-size window
// (docs/ALGORITHM.md, "Coarse fill").
#pragma once

#include <opencv2/core.hpp>

#include "wild_mvs/core/depth_map.h"
#include "wild_mvs/core/image_noise.h"

namespace wild_mvs {

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
// `fillable` (CV_8U of the fine map's size, empty = everywhere): only its
// nonzero pixels are filled.
int FillFromCoarse(const DepthMap& coarse, double max_spread,
                   int interior_radius, const cv::Mat& fillable,
                   DepthMap* fine);

// The pixels of `image` (CV_32FC3, linear) whose window x window window
// cannot reach NCC `kappa` against a noisy copy of itself: its reliability
// S / (S + N) (image_noise.h; N from `noise` at the window's brightness) is
// below kappa. There the full-size window cannot match even at the true
// plane, so a hole says nothing against the coarse map. CV_8U, 255 = such a
// pixel.
cv::Mat WindowsBelowNoise(const cv::Mat& image, const NoiseProfile& noise,
                          int window, double kappa);

}  // namespace wild_mvs
