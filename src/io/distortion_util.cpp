// Copyright wild_mvs authors.
#include "distortion_util.h"

#include <opencv2/calib3d.hpp>

namespace wild_mvs {
namespace io_detail {

void UndistortPixels(const Camera& cam, const Distortion& d,
                     std::vector<Eigen::Vector2d>* pixels) {
  if (d.IsNone() || pixels->empty()) return;
  // OpenCV puts the top-left pixel centre at (0, 0): shift by 0.5.
  const cv::Mat K = (cv::Mat_<double>(3, 3) << cam.fx, 0, cam.cx - 0.5, 0,
                     cam.fy, cam.cy - 0.5, 0, 0, 1);
  const cv::Mat dist = (cv::Mat_<double>(1, 5) << d.k1, d.k2, d.p1, d.p2, d.k3);
  std::vector<cv::Point2d> src, dst;
  src.reserve(pixels->size());
  for (const auto& p : *pixels) src.emplace_back(p.x() - 0.5, p.y() - 0.5);
  cv::undistortPoints(
      src, dst, K, dist, cv::noArray(), K,
      cv::TermCriteria(cv::TermCriteria::COUNT | cv::TermCriteria::EPS, 50,
                       1e-10));
  for (size_t i = 0; i < dst.size(); ++i)
    (*pixels)[i] = Eigen::Vector2d(dst[i].x + 0.5, dst[i].y + 0.5);
}

Eigen::Vector2d DistortPixel(const Camera& cam, const Distortion& d,
                             const Eigen::Vector2d& px) {
  if (d.IsNone()) return px;
  const double x = (px.x() - cam.cx) / cam.fx;
  const double y = (px.y() - cam.cy) / cam.fy;
  const double r2 = x * x + y * y;
  const double radial = 1 + d.k1 * r2 + d.k2 * r2 * r2 + d.k3 * r2 * r2 * r2;
  const double xd = x * radial + 2 * d.p1 * x * y + d.p2 * (r2 + 2 * x * x);
  const double yd = y * radial + d.p1 * (r2 + 2 * y * y) + 2 * d.p2 * x * y;
  return {cam.fx * xd + cam.cx, cam.fy * yd + cam.cy};
}

}  // namespace io_detail
}  // namespace wild_mvs
