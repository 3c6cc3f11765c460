// Copyright wild_mvs authors.
#include "wild_mvs/stream/undistorter.h"

#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>

#include "wild_mvs/core/error.h"

namespace wild_mvs {

bool Undistorter::Key::operator==(const Key& o) const {
  return fx == o.fx && fy == o.fy && cx == o.cx && cy == o.cy &&
         width == o.width && height == o.height && model == o.model &&
         k1 == o.k1 && k2 == o.k2 && p1 == o.p1 && p2 == o.p2 && k3 == o.k3;
}

cv::Mat Undistorter::Apply(const Camera& camera, const Distortion& d,
                           const cv::Mat& image) {
  Require(!image.empty(), "undistort: empty image");
  Require(image.cols == camera.width && image.rows == camera.height,
          "undistort: image is ", image.cols, "x", image.rows,
          " but camera_info (after roi / binning) describes ", camera.width,
          "x", camera.height);
  if (d.IsNone()) return image;
  const Key key{camera.fx,    camera.fy,     camera.cx, camera.cy,
                camera.width, camera.height, d.model,   d.k1,
                d.k2,         d.p1,          d.p2,      d.k3};
  if (!have_maps_ || !(key == key_)) {
    // OpenCV pixel centres: core cx - 0.5.
    const cv::Matx33d K(camera.fx, 0, camera.cx - 0.5, 0, camera.fy,
                        camera.cy - 0.5, 0, 0, 1);
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

}  // namespace wild_mvs
