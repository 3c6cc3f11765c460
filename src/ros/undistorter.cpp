// Copyright wild_mvs authors.
#include "wild_mvs/ros/undistorter.h"

#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>

#include "wild_mvs/core/error.h"
#include "wild_mvs/core/scene.h"
#include "wild_mvs/ros/conversions.h"

namespace wild_mvs {
namespace ros1 {

bool Undistorter::Key::operator==(const Key& o) const {
  return K == o.K && D == o.D && model == o.model && width == o.width &&
         height == o.height && binning_x == o.binning_x &&
         binning_y == o.binning_y && roi_x == o.roi_x && roi_y == o.roi_y &&
         roi_w == o.roi_w && roi_h == o.roi_h;
}

Undistorter::Key Undistorter::KeyOf(const sensor_msgs::CameraInfo& info) {
  Key k;
  k.K.assign(info.K.begin(), info.K.end());
  k.D = info.D;
  k.model = info.distortion_model;
  k.width = info.width;
  k.height = info.height;
  k.binning_x = info.binning_x;
  k.binning_y = info.binning_y;
  k.roi_x = info.roi.x_offset;
  k.roi_y = info.roi.y_offset;
  k.roi_w = info.roi.width;
  k.roi_h = info.roi.height;
  return k;
}

cv::Mat Undistorter::Apply(const sensor_msgs::CameraInfo& info,
                           const cv::Mat& image, Camera* camera) {
  Distortion d;
  CameraFromCameraInfo(info, camera, &d, rectified_);
  Require(!image.empty(), "undistort: empty image");
  Require(image.cols == camera->width && image.rows == camera->height,
          "undistort: image is ", image.cols, "x", image.rows,
          " but camera_info (after roi / binning) describes ", camera->width,
          "x", camera->height);
  if (rectified_ || d.IsNone()) return image;
  const Key key = KeyOf(info);
  if (!have_maps_ || !(key == key_)) {
    // ROS / OpenCV pixel centres: core cx - 0.5.
    const cv::Matx33d K(camera->fx, 0, camera->cx - 0.5, 0, camera->fy,
                        camera->cy - 0.5, 0, 0, 1);
    const cv::Matx<double, 1, 5> D(d.k1, d.k2, d.p1, d.p2, d.k3);
    cv::initUndistortRectifyMap(K, D, cv::noArray(), K, image.size(), CV_32FC1,
                                map_x_, map_y_);
    key_ = key;
    have_maps_ = true;
    ++maps_built_;
  }
  cv::Mat out;
  cv::remap(image, out, map_x_, map_y_, cv::INTER_LINEAR, cv::BORDER_CONSTANT);
  return out;
}

}  // namespace ros1
}  // namespace wild_mvs
