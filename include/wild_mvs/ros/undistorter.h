// Copyright wild_mvs authors. Per-frame undistortion of camera images with
// maps built once per camera_info.
//
// Undistorter::Apply turns an image and its CameraInfo into the undistorted
// image and its pinhole camera, for the node's front end to call once per
// frame. Non-rectified mode (the default): the camera is K adjusted for
// binning / ROI (CameraFromCameraInfo), and the image is undistorted with
// cv::initUndistortRectifyMap(K', D, no R, K') + cv::remap (bilinear,
// constant-zero border), i.e. the same result as cv::undistort(image, und,
// K', D, K'). The maps are cached by the camera_info's K, D,
// distortion_model, width, height, binning and roi, and rebuilt only when
// one of them changes (maps_built() counts the builds). An image without
// distortion (empty D, or all zeros, e.g. plumb_bob with five zeros) is
// returned as is, with no remap. Rectified mode (constructor argument): the
// camera comes from P and D is ignored, so the image is always returned as
// is. Apply throws wild_mvs::Error when the info is invalid or the image
// size is not the size the info describes.
#pragma once

#include <sensor_msgs/CameraInfo.h>

#include <cstdint>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "wild_mvs/core/camera.h"

namespace wild_mvs {
namespace ros1 {

class Undistorter {
 public:
  explicit Undistorter(bool rectified = false) : rectified_(rectified) {}

  // The undistorted image (a new buffer when remapped; `image` itself, not
  // copied, when there is nothing to undo) and, in *camera, its intrinsics
  // and size (the pose is left untouched).
  cv::Mat Apply(const sensor_msgs::CameraInfo& info, const cv::Mat& image,
                Camera* camera);

  // How many times the undistortion maps have been built.
  uint64_t maps_built() const { return maps_built_; }

 private:
  // The camera_info fields the maps depend on.
  struct Key {
    std::vector<double> K, D;
    std::string model;
    uint32_t width = 0, height = 0, binning_x = 0, binning_y = 0;
    uint32_t roi_x = 0, roi_y = 0, roi_w = 0, roi_h = 0;
    bool operator==(const Key& o) const;
  };
  static Key KeyOf(const sensor_msgs::CameraInfo& info);

  bool rectified_;
  bool have_maps_ = false;
  Key key_;
  cv::Mat map_x_, map_y_;  // CV_32FC1
  uint64_t maps_built_ = 0;
};

}  // namespace ros1
}  // namespace wild_mvs
