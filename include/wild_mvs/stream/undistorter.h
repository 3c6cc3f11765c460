// Copyright wild_mvs authors. Per-frame undistortion of camera images with
// maps built once per camera (ROS-free; the depth node's front end gets the
// camera and its distortion from the camera_info, CameraFromCameraInfo).
//
// Undistorter::Apply turns an image of `camera` with lens distortion `d`
// into the undistorted image of the same pinhole camera:
// cv::initUndistortRectifyMap(K, D, no R, K) + cv::remap (bilinear,
// constant-zero border), i.e. the same result as cv::undistort(image, und,
// K, D, K), with K in OpenCV's pixel convention (core cx - 0.5) and D =
// k1 k2 p1 p2 k3. The maps are cached by the camera's intrinsics and size
// and the distortion, and rebuilt only when one of them changes
// (maps_built() counts the builds). An image without distortion
// (Distortion::IsNone: kNone, or all coefficients zero; a rectified camera)
// is returned as is, with no remap. Apply throws wild_mvs::Error when the
// image is empty or not of the camera's size.
#pragma once

#include <cstdint>
#include <opencv2/core.hpp>

#include "wild_mvs/core/camera.h"
#include "wild_mvs/core/scene.h"

namespace wild_mvs {

class Undistorter {
 public:
  // The undistorted image (a new buffer when remapped; `image` itself, not
  // copied, when there is nothing to undo).
  cv::Mat Apply(const Camera& camera, const Distortion& d,
                const cv::Mat& image);

  // How many times the undistortion maps have been built.
  uint64_t maps_built() const { return maps_built_; }

 private:
  // What the maps depend on.
  struct Key {
    double fx = 0, fy = 0, cx = 0, cy = 0;
    int width = 0, height = 0;
    Distortion::Model model = Distortion::Model::kNone;
    double k1 = 0, k2 = 0, p1 = 0, p2 = 0, k3 = 0;
    bool operator==(const Key& o) const;
  };

  bool have_maps_ = false;
  Key key_;
  cv::Mat map_x_, map_y_;  // CV_32FC1
  uint64_t maps_built_ = 0;
};

}  // namespace wild_mvs
