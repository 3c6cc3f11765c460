// Copyright wild_mvs authors. Private helpers: move pixel observations
// between a distorted image and its pinhole (undistorted) camera.
#pragma once

#include <Eigen/Core>
#include <vector>

#include "wild_mvs/core/scene.h"

namespace wild_mvs {
namespace io_detail {

// Undistorts pixel coordinates (wild_mvs convention, centres at +0.5) of an
// image with distortion `d` whose pinhole camera is `cam` (same fx, fy, cx,
// cy). In-place; no-op when d.IsNone().
void UndistortPixels(const Camera& cam, const Distortion& d,
                     std::vector<Eigen::Vector2d>* pixels);
// The inverse: pinhole pixel -> pixel in the distorted image.
Eigen::Vector2d DistortPixel(const Camera& cam, const Distortion& d,
                             const Eigen::Vector2d& px);

}  // namespace io_detail
}  // namespace wild_mvs
