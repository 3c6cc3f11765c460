// Copyright wild_mvs authors. Undistorter: map caching, pass-through and
// recovery of a synthetically distorted image.
#include <gtest/gtest.h>

#include <cmath>
#include <opencv2/calib3d.hpp>
#include <vector>

#include "wild_mvs/core/error.h"
#include "wild_mvs/core/scene.h"
#include "wild_mvs/ros/conversions.h"
#include "wild_mvs/ros/undistorter.h"

namespace wild_mvs {
namespace ros1 {
namespace {

sensor_msgs::CameraInfo MakeInfo(int w, int h, double f, double cx, double cy,
                                 std::vector<double> D) {
  sensor_msgs::CameraInfo info;
  info.width = w;
  info.height = h;
  info.K = {f, 0, cx, 0, f, cy, 0, 0, 1};
  info.P = {f, 0, cx, 0, 0, f, cy, 0, 0, 0, 1, 0};
  info.distortion_model = "plumb_bob";
  info.D = std::move(D);
  return info;
}

const std::vector<double> kD = {-0.2, 0.05, 0.001, -0.0005, 0.0};

// The undistorted scene: a smooth pattern in ROS pixel coordinates.
float Pattern(double x, double y) {
  return static_cast<float>(0.5 + 0.2 * std::sin(x / 9) +
                            0.2 * std::cos(y / 11));
}

TEST(Undistorter, BuildsMapsOncePerCameraInfo) {
  auto info = MakeInfo(160, 120, 150, 79.5, 59.5, kD);
  cv::Mat image(120, 160, CV_32FC3, cv::Scalar(0.5, 0.5, 0.5));
  Undistorter u;
  Camera cam;
  for (int i = 0; i < 50; ++i) {
    info.header.seq = i;  // the header does not matter
    cv::Mat out = u.Apply(info, image, &cam);
    ASSERT_EQ(out.size(), image.size());
    ASSERT_NE(out.data, image.data);
  }
  EXPECT_EQ(u.maps_built(), 1u);
  info.K[0] = 151;  // K changes: a new map
  u.Apply(info, image, &cam);
  u.Apply(info, image, &cam);
  EXPECT_EQ(u.maps_built(), 2u);
  EXPECT_DOUBLE_EQ(cam.fx, 151.0);
  info.D[0] = -0.21;  // D changes
  u.Apply(info, image, &cam);
  EXPECT_EQ(u.maps_built(), 3u);
  info.binning_x = info.binning_y = 2;  // binning changes (and the size)
  cv::Mat half(60, 80, CV_32FC3, cv::Scalar(0.5, 0.5, 0.5));
  cv::Mat out = u.Apply(info, half, &cam);
  EXPECT_EQ(u.maps_built(), 4u);
  EXPECT_EQ(out.size(), half.size());
  EXPECT_EQ(cam.width, 80);
  info.roi.x_offset = 20;  // roi changes
  info.roi.width = 100;
  cv::Mat roi(60, 50, CV_32FC3, cv::Scalar(0.5, 0.5, 0.5));
  u.Apply(info, roi, &cam);
  EXPECT_EQ(u.maps_built(), 5u);
  EXPECT_EQ(cam.width, 50);
  // An image of the wrong size for the info is an Error.
  EXPECT_THROW(u.Apply(info, image, &cam), Error);
}

TEST(Undistorter, NoDistortionIsPassThrough) {
  cv::Mat image(120, 160, CV_8UC3, cv::Scalar(1, 2, 3));
  Camera cam;
  for (const std::vector<double>& D :
       {std::vector<double>(5, 0.0), std::vector<double>()}) {
    Undistorter u;
    auto info = MakeInfo(160, 120, 150, 79.5, 59.5, D);
    cv::Mat out = u.Apply(info, image, &cam);
    EXPECT_EQ(out.data, image.data);  // no remap
    EXPECT_EQ(u.maps_built(), 0u);
    EXPECT_DOUBLE_EQ(cam.fx, 150.0);
    EXPECT_DOUBLE_EQ(cam.cx, 80.0);
  }
  // Rectified mode ignores D and takes the camera from P.
  Undistorter rect(true);
  auto info = MakeInfo(160, 120, 150, 79.5, 59.5, kD);
  info.P[0] = 140;
  cv::Mat out = rect.Apply(info, image, &cam);
  EXPECT_EQ(out.data, image.data);
  EXPECT_EQ(rect.maps_built(), 0u);
  EXPECT_DOUBLE_EQ(cam.fx, 140.0);
}

// Renders the distorted image of Pattern for `info` (each distorted pixel
// takes the pattern's value at its undistorted position, found with
// iterative cv::undistortPoints and checked with cv::projectPoints), undistorts
// it and compares with Pattern away from the border.
void CheckRecovers(const sensor_msgs::CameraInfo& info) {
  Camera cam;
  Distortion d;
  CameraFromCameraInfo(info, &cam, &d);
  const cv::Matx33d K(cam.fx, 0, cam.cx - 0.5, 0, cam.fy, cam.cy - 0.5, 0, 0,
                      1);
  const std::vector<double> D = {d.k1, d.k2, d.p1, d.p2, d.k3};
  std::vector<cv::Point2f> distorted;
  for (int y = 0; y < cam.height; ++y)
    for (int x = 0; x < cam.width; ++x) distorted.emplace_back(x, y);
  std::vector<cv::Point2f> undistorted;
  cv::undistortPoints(
      distorted, undistorted, K, D, cv::noArray(), K,
      cv::TermCriteria(cv::TermCriteria::COUNT | cv::TermCriteria::EPS, 100,
                       1e-10));
  // Forward check: distorting the undistorted points gives the pixels back.
  std::vector<cv::Point3f> rays;
  for (const auto& p : undistorted)
    rays.emplace_back((p.x - K(0, 2)) / K(0, 0), (p.y - K(1, 2)) / K(1, 1),
                      1.f);
  std::vector<cv::Point2f> back;
  cv::projectPoints(rays, cv::Vec3d(0, 0, 0), cv::Vec3d(0, 0, 0), K, D, back);
  cv::Mat image(cam.height, cam.width, CV_32FC1);
  for (int y = 0; y < cam.height; ++y) {
    for (int x = 0; x < cam.width; ++x) {
      const size_t i = static_cast<size_t>(y) * cam.width + x;
      ASSERT_NEAR(back[i].x, x, 1e-2);
      ASSERT_NEAR(back[i].y, y, 1e-2);
      image.at<float>(y, x) = Pattern(undistorted[i].x, undistorted[i].y);
    }
  }
  Undistorter u;
  Camera out_cam;
  cv::Mat out = u.Apply(info, image, &out_cam);
  EXPECT_EQ(u.maps_built(), 1u);
  EXPECT_DOUBLE_EQ(out_cam.fx, cam.fx);
  EXPECT_DOUBLE_EQ(out_cam.cx, cam.cx);
  ASSERT_EQ(out.type(), CV_32FC1);
  const int border = cam.width / 8;
  double sum = 0, worst = 0;
  int n = 0;
  for (int y = border; y < cam.height - border; ++y) {
    for (int x = border; x < cam.width - border; ++x) {
      const double e = std::abs(out.at<float>(y, x) - Pattern(x, y));
      sum += e;
      worst = std::max(worst, e);
      ++n;
    }
  }
  EXPECT_LT(sum / n, 1e-3);
  EXPECT_LT(worst, 5e-3);
  // Without undistortion the difference is large (the test has teeth).
  double raw = 0;
  for (int y = border; y < cam.height - border; ++y)
    for (int x = border; x < cam.width - border; ++x)
      raw += std::abs(image.at<float>(y, x) - Pattern(x, y));
  EXPECT_GT(raw / n, 1e-2);
}

TEST(Undistorter, RecoversSyntheticallyDistortedImage) {
  CheckRecovers(MakeInfo(320, 240, 300, 161.3, 118.2, kD));
}

TEST(Undistorter, RecoversWithBinningAndRoi) {
  auto info = MakeInfo(640, 480, 600, 322.6, 236.4, kD);
  info.binning_x = info.binning_y = 2;
  info.roi.x_offset = 40;
  info.roi.y_offset = 20;
  info.roi.width = 560;
  info.roi.height = 440;
  CheckRecovers(info);
}

}  // namespace
}  // namespace ros1
}  // namespace wild_mvs
