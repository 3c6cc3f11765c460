// Copyright wild_mvs authors. Undistorter: map caching, pass-through and
// recovery of a synthetically distorted image (no ROS).
#include <gtest/gtest.h>

#include <cmath>
#include <opencv2/calib3d.hpp>
#include <vector>

#include "wild_mvs/core/error.h"
#include "wild_mvs/stream/undistorter.h"

namespace wild_mvs {
namespace {

// A camera as CameraFromCameraInfo makes it (core pixel centres: cx = ROS
// K[2] + 0.5).
Camera MakeCamera(int w, int h, double f, double cx, double cy) {
  Camera c;
  c.width = w;
  c.height = h;
  c.fx = c.fy = f;
  c.cx = cx;
  c.cy = cy;
  return c;
}

Distortion MakeDistortion(double k1, double k2, double p1, double p2,
                          double k3) {
  Distortion d;
  d.model = Distortion::Model::kOpenCV;
  d.k1 = k1;
  d.k2 = k2;
  d.p1 = p1;
  d.p2 = p2;
  d.k3 = k3;
  return d;
}

const Distortion kD = MakeDistortion(-0.2, 0.05, 0.001, -0.0005, 0.0);

// The undistorted scene: a smooth pattern in OpenCV pixel coordinates.
float Pattern(double x, double y) {
  return static_cast<float>(0.5 + 0.2 * std::sin(x / 9) +
                            0.2 * std::cos(y / 11));
}

TEST(Undistorter, BuildsMapsOncePerCamera) {
  Camera cam = MakeCamera(160, 120, 150, 80, 60);
  Distortion d = kD;
  cv::Mat image(120, 160, CV_32FC3, cv::Scalar(0.5, 0.5, 0.5));
  Undistorter u;
  for (int i = 0; i < 50; ++i) {
    cam.t = Eigen::Vector3d(i, 0, 0);  // the pose does not matter
    cv::Mat out = u.Apply(cam, d, image);
    ASSERT_EQ(out.size(), image.size());
    ASSERT_NE(out.data, image.data);
  }
  EXPECT_EQ(u.maps_built(), 1u);
  cam.fx = 151;  // the intrinsics change: a new map
  u.Apply(cam, d, image);
  u.Apply(cam, d, image);
  EXPECT_EQ(u.maps_built(), 2u);
  d.k1 = -0.21;  // the distortion changes
  u.Apply(cam, d, image);
  EXPECT_EQ(u.maps_built(), 3u);
  // A binned camera (half the size, as CameraFromCameraInfo gives it).
  Camera half = MakeCamera(80, 60, 75.5, 40, 30);
  cv::Mat small(60, 80, CV_32FC3, cv::Scalar(0.5, 0.5, 0.5));
  cv::Mat out = u.Apply(half, d, small);
  EXPECT_EQ(u.maps_built(), 4u);
  EXPECT_EQ(out.size(), small.size());
  half.cx = 30;  // a region of interest moves the principal point
  u.Apply(half, d, small);
  EXPECT_EQ(u.maps_built(), 5u);
  // An image of the wrong size for the camera is an Error, so is none.
  EXPECT_THROW(u.Apply(half, d, image), Error);
  EXPECT_THROW(u.Apply(half, d, cv::Mat()), Error);
}

TEST(Undistorter, NoDistortionIsPassThrough) {
  cv::Mat image(120, 160, CV_8UC3, cv::Scalar(1, 2, 3));
  const Camera cam = MakeCamera(160, 120, 150, 80, 60);
  for (const Distortion& d : {MakeDistortion(0, 0, 0, 0, 0), Distortion(), [] {
                                Distortion none =
                                    kD;  // a rectified camera: kNone
                                none.model = Distortion::Model::kNone;
                                return none;
                              }()}) {
    Undistorter u;
    cv::Mat out = u.Apply(cam, d, image);
    EXPECT_EQ(out.data, image.data);  // no remap
    EXPECT_EQ(u.maps_built(), 0u);
  }
}

// Renders the distorted image of Pattern for `cam` and `d` (each distorted
// pixel takes the pattern's value at its undistorted position, found with
// iterative cv::undistortPoints and checked with cv::projectPoints),
// undistorts it and compares with Pattern away from the border.
void CheckRecovers(const Camera& cam, const Distortion& d) {
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
  cv::Mat out = u.Apply(cam, d, image);
  EXPECT_EQ(u.maps_built(), 1u);
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
  // ROS K: f 300, principal point (161.3, 118.2).
  CheckRecovers(MakeCamera(320, 240, 300, 161.8, 118.7), kD);
}

TEST(Undistorter, RecoversWithBinningAndRoi) {
  // A 640x480 sensor (ROS K: f 600, (322.6, 236.4)) binned 2x2 with the roi
  // x 40, y 20, 560x440: 280x220, f 300, cx (322.6 + 0.5 - 40) / 2.
  CheckRecovers(MakeCamera(280, 220, 300, 141.55, 108.45), kD);
}

}  // namespace
}  // namespace wild_mvs
