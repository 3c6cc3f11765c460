// Copyright wild_mvs authors. ROS message <-> core conversions.
#include <gtest/gtest.h>
#include <sensor_msgs/image_encodings.h>
#include <sensor_msgs/point_cloud2_iterator.h>

#include <cmath>
#include <cstring>
#include <opencv2/imgcodecs.hpp>

#include "wild_mvs/core/error.h"
#include "wild_mvs/core/image.h"
#include "wild_mvs/ros/conversions.h"

namespace wild_mvs {
namespace ros1 {
namespace {

sensor_msgs::CameraInfo MakeInfo(int w, int h, double f, double cx, double cy) {
  sensor_msgs::CameraInfo info;
  info.width = w;
  info.height = h;
  info.K = {f, 0, cx, 0, f, cy, 0, 0, 1};
  info.distortion_model = "plumb_bob";
  info.D.assign(5, 0.0);
  return info;
}

TEST(Conversions, CameraInfoPrincipalPointShiftsByHalfPixel) {
  // In ROS the centre of a 640x480 image is at (319.5, 239.5); in the core
  // it is at (320, 240).
  Camera cam;
  CameraFromCameraInfo(MakeInfo(640, 480, 500, 319.5, 239.5), &cam, nullptr);
  EXPECT_DOUBLE_EQ(cam.cx, 320.0);
  EXPECT_DOUBLE_EQ(cam.cy, 240.0);
  EXPECT_EQ(cam.width, 640);
  EXPECT_EQ(cam.height, 480);
  // A point on the optical axis lands on the image centre: (320, 240) in
  // the core, (319.5, 239.5) in ROS.
  Eigen::Vector2d px = cam.ProjectCam({0, 0, 2});
  EXPECT_DOUBLE_EQ(px.x(), 320.0);
  // A point that ROS projects to the centre of pixel (10, 20) projects in
  // the core to (10.5, 20.5), the same pixel's centre.
  const Eigen::Vector3d Xc((10 - 319.5) / 500.0, (20 - 239.5) / 500.0, 1.0);
  px = cam.ProjectCam(Xc);
  EXPECT_NEAR(px.x(), 10.5, 1e-9);
  EXPECT_NEAR(px.y(), 20.5, 1e-9);
  // And back.
  sensor_msgs::CameraInfo back = CameraInfoFromCamera(cam);
  EXPECT_DOUBLE_EQ(back.K[2], 319.5);
  EXPECT_DOUBLE_EQ(back.K[5], 239.5);
  EXPECT_DOUBLE_EQ(back.P[2], 319.5);
  EXPECT_DOUBLE_EQ(back.P[6], 239.5);
  EXPECT_DOUBLE_EQ(back.K[0], 500.0);
}

TEST(Conversions, CameraInfoRejectsBadIntrinsics) {
  Camera cam;
  EXPECT_THROW(
      CameraFromCameraInfo(MakeInfo(640, 480, 0, 319.5, 239.5), &cam, nullptr),
      Error);
  EXPECT_THROW(
      CameraFromCameraInfo(MakeInfo(0, 480, 500, 319.5, 239.5), &cam, nullptr),
      Error);
  EXPECT_THROW(CameraFromCameraInfo(MakeInfo(640, 480, NAN, 319.5, 239.5), &cam,
                                    nullptr),
               Error);
  // fuzz_ros_messages regression (corpus crash_camera_info_height_over_
  // int_max): a height of 2885681632 passed the `> 0` check as uint32 and
  // became a negative Camera::height. Sizes above 32768 are refused.
  auto huge = MakeInfo(640, 480, 500, 319.5, 239.5);
  huge.height = 2885681632u;
  try {
    CameraFromCameraInfo(huge, &cam, nullptr);
    ADD_FAILURE() << "huge camera_info accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("640x2885681632 is too large"),
              std::string::npos)
        << e.what();
  }
  huge.height = 32769;
  EXPECT_THROW(CameraFromCameraInfo(huge, &cam, nullptr), Error);
  huge.height = 32768;  // the largest accepted
  CameraFromCameraInfo(huge, &cam, nullptr);
  EXPECT_EQ(cam.height, 32768);
  auto fisheye = MakeInfo(640, 480, 500, 319.5, 239.5);
  fisheye.distortion_model = "equidistant";
  fisheye.D = {0.1, 0.01, 0, 0};
  EXPECT_THROW(CameraFromCameraInfo(fisheye, &cam, nullptr), Error);
  auto plumb = MakeInfo(640, 480, 500, 319.5, 239.5);
  plumb.D = {-0.2, 0.05, 0.001, 0.002, 0.0};
  Distortion d;
  CameraFromCameraInfo(plumb, &cam, &d);
  EXPECT_FALSE(d.IsNone());
  EXPECT_DOUBLE_EQ(d.k1, -0.2);
  EXPECT_DOUBLE_EQ(d.p2, 0.002);
}

TEST(Conversions, PoseRoundTripAndMeaning) {
  // Camera at (1, 2, 3) looking along world +x (optical z = world x), image
  // x = world -y, image y = world -z.
  geometry_msgs::Pose p;
  p.position.x = 1;
  p.position.y = 2;
  p.position.z = 3;
  Eigen::Matrix3d R_wc;
  R_wc.col(0) = Eigen::Vector3d(0, -1, 0);
  R_wc.col(1) = Eigen::Vector3d(0, 0, -1);
  R_wc.col(2) = Eigen::Vector3d(1, 0, 0);
  Eigen::Quaterniond q(R_wc);
  p.orientation.x = q.x();
  p.orientation.y = q.y();
  p.orientation.z = q.z();
  p.orientation.w = q.w();
  Camera cam;
  SetCameraPose(p, &cam);
  EXPECT_NEAR((cam.Center() - Eigen::Vector3d(1, 2, 3)).norm(), 0, 1e-12);
  // A world point 5 m ahead is on the optical axis at depth 5.
  Eigen::Vector3d Xc = cam.WorldToCamera({6, 2, 3});
  EXPECT_NEAR((Xc - Eigen::Vector3d(0, 0, 5)).norm(), 0, 1e-12);
  // World -y is image right (+x_cam).
  Xc = cam.WorldToCamera({6, 1, 3});
  EXPECT_NEAR(Xc.x(), 1, 1e-12);
  const geometry_msgs::Pose back = PoseFromCamera(cam);
  EXPECT_NEAR(back.position.y, 2, 1e-12);
  Camera cam2;
  SetCameraPose(back, &cam2);
  EXPECT_NEAR((cam2.R - cam.R).norm(), 0, 1e-12);
}

TEST(Conversions, PoseRejectsNaNAndNonRotations) {
  geometry_msgs::Pose p;
  p.orientation.w = 1;
  p.position.x = NAN;
  Camera cam;
  EXPECT_THROW(SetCameraPose(p, &cam), Error);
  p.position.x = 0;
  p.orientation.w = 0;  // zero quaternion
  EXPECT_THROW(SetCameraPose(p, &cam), Error);
  p.orientation.w = 1.02;  // nearly unit: normalised
  EXPECT_NO_THROW(SetCameraPose(p, &cam));
}

sensor_msgs::Image MakeImage(int w, int h, const std::string& encoding,
                             int bytes_per_pixel) {
  sensor_msgs::Image img;
  img.width = w;
  img.height = h;
  img.encoding = encoding;
  img.step = w * bytes_per_pixel;
  img.data.assign(static_cast<size_t>(img.step) * h, 0);
  return img;
}

TEST(Conversions, ImageEncodings) {
  namespace enc = sensor_msgs::image_encodings;
  // rgb8: red pixel stays red (channel 0 of the core's RGB).
  auto rgb = MakeImage(4, 3, enc::RGB8, 3);
  rgb.data[0] = 255;
  cv::Mat out = ImageToLinearRgb(rgb, true);
  ASSERT_EQ(out.type(), CV_32FC3);
  EXPECT_FLOAT_EQ(out.at<cv::Vec3f>(0, 0)[0], 1.0f);
  EXPECT_FLOAT_EQ(out.at<cv::Vec3f>(0, 0)[2], 0.0f);
  // bgr8: byte 0 is blue.
  auto bgr = MakeImage(4, 3, enc::BGR8, 3);
  bgr.data[0] = 255;
  out = ImageToLinearRgb(bgr, true);
  EXPECT_FLOAT_EQ(out.at<cv::Vec3f>(0, 0)[2], 1.0f);
  EXPECT_FLOAT_EQ(out.at<cv::Vec3f>(0, 0)[0], 0.0f);
  // mono8 mid grey: linearised.
  auto mono = MakeImage(4, 3, enc::MONO8, 1);
  mono.data[5] = 128;
  out = ImageToLinearRgb(mono, true);
  EXPECT_NEAR(out.at<cv::Vec3f>(1, 1)[1], SrgbToLinear(128 / 255.0f), 1e-6);
  // Padded rows (step > width * 3) are honoured.
  auto padded = MakeImage(2, 2, enc::RGB8, 4);  // step = 8 > 6
  padded.data[8 + 3] = 255;                     // row 1, pixel 1, red
  out = ImageToLinearRgb(padded, false);
  EXPECT_FLOAT_EQ(out.at<cv::Vec3f>(1, 1)[0], 1.0f);
}

TEST(Conversions, ImageRejectsMalformed) {
  namespace enc = sensor_msgs::image_encodings;
  auto depth16 = MakeImage(4, 3, enc::TYPE_16UC1, 2);
  EXPECT_THROW(ImageToLinearRgb(depth16, true), Error);
  auto unknown = MakeImage(4, 3, "yuv422", 2);
  EXPECT_THROW(ImageToLinearRgb(unknown, true), Error);
  auto short_data = MakeImage(4, 3, enc::RGB8, 3);
  short_data.data.resize(10);
  EXPECT_THROW(ImageToLinearRgb(short_data, true), Error);
  auto short_step = MakeImage(4, 3, enc::RGB8, 3);
  short_step.step = 5;
  EXPECT_THROW(ImageToLinearRgb(short_step, true), Error);
  auto empty = MakeImage(0, 0, enc::RGB8, 3);
  EXPECT_THROW(ImageToLinearRgb(empty, true), Error);
  auto big_endian = MakeImage(4, 3, enc::MONO16, 2);
  big_endian.is_bigendian = 1;
  EXPECT_THROW(ImageToLinearRgb(big_endian, true), Error);
}

TEST(Conversions, CompressedImage) {
  cv::Mat bgr(6, 8, CV_8UC3, cv::Scalar(0, 0, 255));  // red
  std::vector<uint8_t> png;
  ASSERT_TRUE(cv::imencode(".png", bgr, png));
  sensor_msgs::CompressedImage msg;
  msg.format = "png";
  msg.data = png;
  cv::Mat out = CompressedToLinearRgb(msg, true);
  ASSERT_EQ(out.rows, 6);
  ASSERT_EQ(out.cols, 8);
  EXPECT_FLOAT_EQ(out.at<cv::Vec3f>(2, 3)[0], 1.0f);
  msg.data.resize(20);  // truncated
  EXPECT_THROW(CompressedToLinearRgb(msg, true), Error);
  msg.data.clear();
  EXPECT_THROW(CompressedToLinearRgb(msg, true), Error);
}

DepthMap MakeDepthMap() {
  DepthMap dm;
  dm.view = 3;
  dm.camera.fx = dm.camera.fy = 100;
  dm.camera.cx = 8;
  dm.camera.cy = 6;
  dm.camera.width = 16;
  dm.camera.height = 12;
  dm.camera.t = Eigen::Vector3d(0.1, -0.2, 0.3);
  dm.depth = cv::Mat(12, 16, CV_32FC1, cv::Scalar(2.0f));
  dm.depth.at<float>(0, 0) = 0;  // unknown
  dm.confidence = cv::Mat(12, 16, CV_32FC1, cv::Scalar(0.75f));
  dm.confidence.at<float>(0, 0) = 0;
  dm.normal = cv::Mat(12, 16, CV_32FC3, cv::Scalar(0, 0, -1));
  dm.normal.at<cv::Vec3f>(0, 0) = cv::Vec3f(0, 0, 0);
  dm.neighbors = {1, 2};
  return dm;
}

TEST(Conversions, DepthIsRep118) {
  DepthMap dm = MakeDepthMap();
  sensor_msgs::Image d = DepthToMsg(dm.depth);
  EXPECT_EQ(d.encoding, "32FC1");
  EXPECT_EQ(d.step, 16u * 4u);
  float v0, v1;
  std::memcpy(&v0, &d.data[0], 4);
  std::memcpy(&v1, &d.data[4], 4);
  EXPECT_TRUE(std::isnan(v0));  // unknown = NaN
  EXPECT_FLOAT_EQ(v1, 2.0f);
  sensor_msgs::Image n = NormalsToMsg(dm.normal);
  EXPECT_EQ(n.encoding, "32FC3");
  std::memcpy(&v0, &n.data[0], 4);
  EXPECT_TRUE(std::isnan(v0));
}

TEST(Conversions, DepthViewRoundTrip) {
  DepthMap dm = MakeDepthMap();
  wild_mvs::DepthView msg;
  msg.header.frame_id = "camera";
  msg.keyframe_id = 3;
  msg.neighbor_ids = {1, 2};
  FillDepthView(dm, "world", &msg);
  EXPECT_EQ(msg.camera_pose.header.frame_id, "world");
  EXPECT_DOUBLE_EQ(msg.camera_info.K[2], 7.5);
  DepthMap back = DepthMapFromDepthView(msg);
  EXPECT_EQ(back.view, 3);
  EXPECT_DOUBLE_EQ(back.camera.cx, 8.0);
  EXPECT_NEAR((back.camera.t - dm.camera.t).norm(), 0, 1e-9);
  EXPECT_EQ(back.depth.at<float>(0, 0), 0.0f);
  EXPECT_EQ(back.depth.at<float>(5, 5), 2.0f);
  EXPECT_EQ(back.confidence.at<float>(5, 5), 0.75f);
  EXPECT_EQ(back.normal.at<cv::Vec3f>(5, 5)[2], -1.0f);
  EXPECT_EQ(back.CountValid(), dm.CountValid());
  EXPECT_EQ(back.neighbors, (std::vector<int>{1, 2}));
}

TEST(Conversions, DepthViewRejectsInconsistentMessages) {
  DepthMap dm = MakeDepthMap();
  wild_mvs::DepthView msg;
  FillDepthView(dm, "world", &msg);
  auto bad = msg;
  bad.camera_info.width = 20;  // size mismatch
  EXPECT_THROW(DepthMapFromDepthView(bad), Error);
  bad = msg;
  bad.depth.encoding = "16UC1";
  EXPECT_THROW(DepthMapFromDepthView(bad), Error);
  bad = msg;
  bad.normals.data.resize(4);
  EXPECT_THROW(DepthMapFromDepthView(bad), Error);
  bad = msg;
  bad.camera_pose.pose.orientation.w = NAN;
  EXPECT_THROW(DepthMapFromDepthView(bad), Error);
  bad = msg;
  bad.camera_info.K[0] = 0;
  EXPECT_THROW(DepthMapFromDepthView(bad), Error);
}

TEST(Conversions, CloudToPointCloud2) {
  PointCloud cloud;
  for (int i = 0; i < 10; ++i) {
    cloud.xyz.emplace_back(i, 2 * i, 3 * i);
    cloud.rgb.emplace_back(1, 0, 0);
    cloud.normal.emplace_back(0, 0, 1);
  }
  sensor_msgs::PointCloud2 msg = CloudToMsg(cloud);
  EXPECT_EQ(msg.width * msg.height, 10u);
  sensor_msgs::PointCloud2ConstIterator<float> x(msg, "x"), z(msg, "z"),
      nz(msg, "normal_z");
  sensor_msgs::PointCloud2ConstIterator<uint8_t> r(msg, "rgb");
  x += 4;
  z += 4;
  nz += 4;
  r += 4;
  EXPECT_FLOAT_EQ(*x, 4.0f);
  EXPECT_FLOAT_EQ(*z, 12.0f);
  EXPECT_FLOAT_EQ(*nz, 1.0f);
  EXPECT_EQ(r[2], 255);  // packed 0x00RRGGBB little endian: R is byte 2
  EXPECT_EQ(r[0], 0);
  sensor_msgs::PointCloud2 sub = CloudToMsg(cloud, 5);
  EXPECT_EQ(sub.width, 5u);
  // rviz (RGB8 colour transformer) needs the packed float "rgb" field in
  // every cloud, also an empty one or one without colours (grey).
  for (const PointCloud& c : {PointCloud(), [] {
                                PointCloud p;
                                p.xyz.emplace_back(1, 2, 3);
                                return p;
                              }()}) {
    const sensor_msgs::PointCloud2 m = CloudToMsg(c);
    bool has_rgb = false;
    for (const auto& f : m.fields)
      if (f.name == "rgb" && f.datatype == sensor_msgs::PointField::FLOAT32 &&
          f.count == 1 && f.offset == 12)
        has_rgb = true;
    EXPECT_TRUE(has_rgb);
    EXPECT_EQ(m.point_step, 16u);
    if (!c.empty()) {
      sensor_msgs::PointCloud2ConstIterator<uint8_t> g(m, "rgb");
      EXPECT_EQ(g[0], 128);
      EXPECT_EQ(g[1], 128);
      EXPECT_EQ(g[2], 128);
    }
  }
}

TEST(Conversions, DepthMapToCloudIsInWorldFrame) {
  DepthMap dm = MakeDepthMap();
  PointCloud cloud = DepthMapToCloud(dm, cv::Mat());
  EXPECT_EQ(cloud.size(), static_cast<size_t>(dm.CountValid()));
  // Every point projects back to depth 2.
  for (const auto& p : cloud.xyz)
    EXPECT_NEAR(dm.camera.Depth(p.cast<double>()), 2.0, 1e-5);
}

}  // namespace
}  // namespace ros1
}  // namespace wild_mvs
