// Copyright wild_mvs authors. Rendering with cameras as real ones are (an
// addition to synthetic_scene.h, kept apart so that the many tests that
// include that header need not change).
#pragma once

#include <Eigen/Core>

#include "synthetic_scene.h"
#include "wild_mvs/core/scene.h"

namespace wild_mvs {
namespace testing {

// fy = focal_y_ratio * fx, the principal point `principal_offset` pixels
// from the image centre, and lens distortion (OpenCV model, as
// View::distortion: k1, k2, p1, p2, k3 on normalised coordinates).
struct SyntheticLens {
  double focal_y_ratio = 1.0;
  Eigen::Vector2d principal_offset{0, 0};
  Distortion distortion;
};

// Render(spec) with every camera made by `lens`. With distortion the images
// are rendered distorted (each sub-sample ray goes through the undistorted
// position of its pixel position) and View::distortion is set, while the
// cameras, the ground-truth depth / normals / object ids and the sparse
// observations stay those of the pinhole (undistorted) camera, i.e. what a
// loader that undistorts at load (LoadViewImage) gives. Loader() then
// serves the distorted images; WriteDataset writes OPENCV cameras.
SyntheticScene Render(const SyntheticSpec& spec, const SyntheticLens& lens);

}  // namespace testing
}  // namespace wild_mvs
