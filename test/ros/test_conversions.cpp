// Copyright wild_mvs authors. ROS message <-> core conversions.
#include <gtest/gtest.h>
#include <sensor_msgs/image_encodings.h>
#include <sensor_msgs/point_cloud2_iterator.h>

#include <cmath>
#include <cstring>
#include <opencv2/imgcodecs.hpp>
#include <string>
#include <vector>

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

// Every plain encoding the brief lists: one known pixel, read without
// linearisation, comes out as the core's RGB.
TEST(Conversions, AllPlainEncodings) {
  namespace enc = sensor_msgs::image_encodings;
  const float r = 200 / 255.f, g = 100 / 255.f, b = 50 / 255.f;
  struct Case {
    std::string encoding;
    std::vector<uint8_t> pixel;
  };
  const std::vector<Case> cases = {{enc::RGB8, {200, 100, 50}},
                                   {enc::BGR8, {50, 100, 200}},
                                   {enc::RGBA8, {200, 100, 50, 255}},
                                   {enc::BGRA8, {50, 100, 200, 255}}};
  for (const Case& c : cases) {
    auto img = MakeImage(3, 2, c.encoding, int(c.pixel.size()));
    std::memcpy(&img.data[img.step + c.pixel.size()], c.pixel.data(),
                c.pixel.size());  // pixel (1, 1)
    cv::Mat out = ImageToLinearRgb(img, false);
    ASSERT_EQ(out.type(), CV_32FC3) << c.encoding;
    ASSERT_EQ(out.size(), cv::Size(3, 2)) << c.encoding;
    const cv::Vec3f v = out.at<cv::Vec3f>(1, 1);
    EXPECT_NEAR(v[0], r, 1e-6) << c.encoding;
    EXPECT_NEAR(v[1], g, 1e-6) << c.encoding;
    EXPECT_NEAR(v[2], b, 1e-6) << c.encoding;
    EXPECT_EQ(out.at<cv::Vec3f>(0, 0), cv::Vec3f(0, 0, 0)) << c.encoding;
  }
  auto mono8 = MakeImage(3, 2, enc::MONO8, 1);
  mono8.data[4] = 100;
  cv::Mat out = ImageToLinearRgb(mono8, false);
  EXPECT_NEAR(out.at<cv::Vec3f>(1, 1)[0], g, 1e-6);
  EXPECT_NEAR(out.at<cv::Vec3f>(1, 1)[2], g, 1e-6);
  auto mono16 = MakeImage(3, 2, enc::MONO16, 2);
  const uint16_t v16 = 30000;
  std::memcpy(&mono16.data[mono16.step + 2], &v16, 2);
  out = ImageToLinearRgb(mono16, false);
  EXPECT_NEAR(out.at<cv::Vec3f>(1, 1)[1], 30000 / 65535.f, 1e-5);
}

// A flat colour mosaiced in each ROS Bayer pattern (pattern letters name
// pixels (0,0) (0,1) (1,0) (1,1)) demosaics back to that colour: catches
// OpenCV's shifted COLOR_Bayer* names.
TEST(Conversions, BayerDemosaic) {
  namespace enc = sensor_msgs::image_encodings;
  const int w = 16, h = 12;
  const double rgb[3] = {200, 100, 30};  // fraction of full scale: /255
  for (const std::string pattern : {"rggb", "bggr", "gbrg", "grbg"}) {
    for (int bits : {8, 16}) {
      const std::string e = "bayer_" + pattern + std::to_string(bits);
      const int bpp = bits / 8;
      auto img = MakeImage(w, h, e, bpp);
      const double scale = bits == 8 ? 1.0 : 257.0;  // 255 -> 65535
      for (int y = 0; y < h; ++y) {
        for (int x = 0; x < w; ++x) {
          const char ch = pattern[2 * (y % 2) + (x % 2)];
          const int c = ch == 'r' ? 0 : ch == 'g' ? 1 : 2;
          const double v = rgb[c] * scale;
          uint8_t* p = &img.data[y * img.step + x * bpp];
          if (bits == 8) {
            *p = static_cast<uint8_t>(v);
          } else {
            const uint16_t v16 = static_cast<uint16_t>(v);
            std::memcpy(p, &v16, 2);
          }
        }
      }
      cv::Mat out = ImageToLinearRgb(img, false);
      ASSERT_EQ(out.type(), CV_32FC3) << e;
      ASSERT_EQ(out.size(), cv::Size(w, h)) << e;
      for (int y = 2; y < h - 2; ++y)
        for (int x = 2; x < w - 2; ++x)
          for (int c = 0; c < 3; ++c)
            ASSERT_NEAR(out.at<cv::Vec3f>(y, x)[c], rgb[c] / 255.0, 2e-3)
                << e << " pixel (" << x << ", " << y << ") channel " << c;
    }
  }
  // Any other encoding: an Error naming it.
  try {
    ImageToLinearRgb(MakeImage(4, 4, "bayer_xyzw8", 1), false);
    ADD_FAILURE() << "bayer_xyzw8 accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("'bayer_xyzw8'"), std::string::npos)
        << e.what();
  }
  try {
    ImageToLinearRgb(MakeImage(4, 4, "yuv422", 2), false);
    ADD_FAILURE() << "yuv422 accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("'yuv422'"), std::string::npos)
        << e.what();
  }
}

// Binning and ROI: the delivered image is the ROI of the sensor, binned.
TEST(Conversions, CameraInfoBinningAndRoi) {
  auto full_info = MakeInfo(640, 480, 500, 310.2, 245.7);
  Camera full;
  CameraFromCameraInfo(full_info, &full, nullptr);
  auto info = full_info;
  info.roi.x_offset = 100;
  info.roi.y_offset = 60;
  info.roi.width = 400;
  info.roi.height = 300;
  info.binning_x = 2;
  info.binning_y = 3;
  Camera cam;
  CameraFromCameraInfo(info, &cam, nullptr);
  EXPECT_EQ(cam.width, 200);
  EXPECT_EQ(cam.height, 100);
  EXPECT_DOUBLE_EQ(cam.fx, 250.0);
  EXPECT_NEAR(cam.fy, 500.0 / 3, 1e-12);
  // Binned pixel (j, i) covers sensor pixels x = 100 + 2j, 100 + 2j + 1 and
  // y = 60 + 3i .. 60 + 3i + 2; its centre (core j + 0.5, i + 0.5) is the
  // mean of their centres: core x = 100 + 2j + 1, y = 60 + 3i + 1.5. A 3D
  // point on that ray in the full camera lands on the binned pixel centre.
  for (int j : {0, 10, 199}) {
    for (int i : {0, 7, 99}) {
      const double u = 100 + 2 * j + 1, v = 60 + 3 * i + 1.5;
      const Eigen::Vector3d X((u - full.cx) / full.fx * 3.0,
                              (v - full.cy) / full.fy * 3.0, 3.0);
      ASSERT_NEAR(full.ProjectCam(X).x(), u, 1e-9);
      const Eigen::Vector2d px = cam.ProjectCam(X);
      EXPECT_NEAR(px.x(), j + 0.5, 1e-9) << j << " " << i;
      EXPECT_NEAR(px.y(), i + 0.5, 1e-9) << j << " " << i;
    }
  }
  // Binning 0 and 1 are both "none"; roi width/height 0 = full sensor.
  auto none = full_info;
  none.binning_x = 1;
  none.binning_y = 0;
  CameraFromCameraInfo(none, &cam, nullptr);
  EXPECT_EQ(cam.width, 640);
  EXPECT_EQ(cam.height, 480);
  EXPECT_DOUBLE_EQ(cam.cx, full.cx);
  EXPECT_DOUBLE_EQ(cam.fy, full.fy);
  // Binning only: odd widths round down.
  auto binned = MakeInfo(641, 481, 500, 320, 240);
  binned.binning_x = binned.binning_y = 2;
  CameraFromCameraInfo(binned, &cam, nullptr);
  EXPECT_EQ(cam.width, 320);
  EXPECT_EQ(cam.height, 240);
  EXPECT_DOUBLE_EQ(cam.cx, (320 + 0.5) / 2);
  // An ROI outside the sensor is refused.
  auto outside = info;
  outside.roi.x_offset = 300;  // 300 + 400 > 640
  EXPECT_THROW(CameraFromCameraInfo(outside, &cam, nullptr), Error);
}

// Rectified mode: the camera comes from P, D is ignored.
TEST(Conversions, CameraInfoRectifiedUsesP) {
  auto info = MakeInfo(640, 480, 500, 319.5, 239.5);
  info.D = {-0.2, 0.05, 0.001, 0.002, 0.0};
  info.P = {480, 0, 321.5, 0, 0, 470, 235.5, 0, 0, 0, 1, 0};
  Camera cam;
  Distortion d;
  CameraFromCameraInfo(info, &cam, &d, true);
  EXPECT_DOUBLE_EQ(cam.fx, 480.0);
  EXPECT_DOUBLE_EQ(cam.fy, 470.0);
  EXPECT_DOUBLE_EQ(cam.cx, 322.0);
  EXPECT_DOUBLE_EQ(cam.cy, 236.0);
  EXPECT_TRUE(d.IsNone());
  // Default mode still uses K and D.
  CameraFromCameraInfo(info, &cam, &d);
  EXPECT_DOUBLE_EQ(cam.fx, 500.0);
  EXPECT_DOUBLE_EQ(cam.cx, 320.0);
  EXPECT_FALSE(d.IsNone());
  // A stereo right camera's baseline term is accepted and ignored.
  auto right = info;
  right.P[3] = -480 * 0.12;
  CameraFromCameraInfo(right, &cam, &d, true);
  EXPECT_DOUBLE_EQ(cam.fx, 480.0);
  EXPECT_DOUBLE_EQ(cam.cx, 322.0);
  // Binning / ROI apply to P too.
  auto binned = info;
  binned.binning_x = binned.binning_y = 2;
  CameraFromCameraInfo(binned, &cam, &d, true);
  EXPECT_EQ(cam.width, 320);
  EXPECT_DOUBLE_EQ(cam.fx, 240.0);
  EXPECT_DOUBLE_EQ(cam.cx, 161.0);
  // An all-zero P is an error in rectified mode (not in the default mode).
  auto zero = info;
  zero.P.fill(0.0);
  try {
    CameraFromCameraInfo(zero, &cam, &d, true);
    ADD_FAILURE() << "all-zero P accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("P is all zero"), std::string::npos)
        << e.what();
  }
  CameraFromCameraInfo(zero, &cam, &d);
  EXPECT_DOUBLE_EQ(cam.fx, 500.0);
}

TEST(Conversions, Depth16IsRep118Millimetres) {
  cv::Mat depth(1, 9, CV_32FC1);
  const float in[9] = {0.f,  1.2344f, 1.2346f,  65.535f, 65.6f,
                       -1.f, NAN,     INFINITY, 0.0004f};
  const uint16_t want[9] = {0, 1234, 1235, 65535, 0, 0, 0, 0, 0};
  for (int i = 0; i < 9; ++i) depth.at<float>(0, i) = in[i];
  sensor_msgs::Image m = DepthToMsg16(depth);
  EXPECT_EQ(m.encoding, "16UC1");
  EXPECT_EQ(m.width, 9u);
  EXPECT_EQ(m.height, 1u);
  EXPECT_EQ(m.step, 18u);
  EXPECT_EQ(m.is_bigendian, 0);
  ASSERT_EQ(m.data.size(), 18u);
  for (int i = 0; i < 9; ++i) {
    uint16_t v;
    std::memcpy(&v, &m.data[2 * i], 2);
    EXPECT_EQ(v, want[i]) << "depth " << in[i];
  }
  // The 32FC1 output of the same map: metres, NaN where unknown.
  sensor_msgs::Image f = DepthToMsg(depth);
  EXPECT_EQ(f.encoding, "32FC1");
  for (int i = 0; i < 9; ++i) {
    float v;
    std::memcpy(&v, &f.data[4 * i], 4);
    if (in[i] > 0 && std::isfinite(in[i])) {
      EXPECT_FLOAT_EQ(v, in[i]);
    } else {
      EXPECT_TRUE(std::isnan(v)) << "depth " << in[i];
    }
  }
  EXPECT_THROW(DepthToMsg16(cv::Mat(2, 2, CV_64FC1)), Error);
}

TEST(Conversions, StripLeadingSlash) {
  EXPECT_EQ(StripLeadingSlash("/camera"), "camera");
  EXPECT_EQ(StripLeadingSlash("//a/b/"), "a/b/");
  EXPECT_EQ(StripLeadingSlash("map"), "map");
  EXPECT_EQ(StripLeadingSlash("/"), "");
  EXPECT_EQ(StripLeadingSlash(""), "");
}

}  // namespace
}  // namespace ros1
}  // namespace wild_mvs
