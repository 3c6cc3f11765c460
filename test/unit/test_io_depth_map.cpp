// Copyright wild_mvs authors. Reconstruct output layout round trip.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <filesystem>
#include <fstream>

#include "test_paths.h"
#include "wild_mvs/core/error.h"
#include "wild_mvs/io/depth_map_io.h"

namespace wild_mvs {
namespace {

namespace fs = std::filesystem;

DepthMap MakeMap() {
  DepthMap m;
  m.camera.width = 40;
  m.camera.height = 30;
  m.camera.fx = 35.5;
  m.camera.fy = 36.25;
  m.camera.cx = 20.125;
  m.camera.cy = 15.0625;
  m.camera.R = Eigen::AngleAxisd(0.3, Eigen::Vector3d(1, 2, 3).normalized())
                   .toRotationMatrix();
  m.camera.t = Eigen::Vector3d(0.1, -0.2, 1.0 / 3.0);
  m.depth.create(30, 40, CV_32F);
  m.normal.create(30, 40, CV_32FC3);
  m.confidence.create(30, 40, CV_32F);
  for (int r = 0; r < 30; ++r)
    for (int c = 0; c < 40; ++c) {
      const bool valid = (r + c) % 5 != 0;
      m.depth.at<float>(r, c) = valid ? 1.0f + 0.01f * r + 0.001f * c : 0.f;
      cv::Vec3f n(0.1f * (c - 20) / 20, 0.1f * (r - 15) / 15, -1);
      m.normal.at<cv::Vec3f>(r, c) =
          valid ? n / cv::norm(n) : cv::Vec3f(0, 0, 0);
      m.confidence.at<float>(r, c) = valid ? 0.02f * (r % 50) : 0.f;
    }
  return m;
}

TEST(DepthMapIo, RoundTrip) {
  const std::string out = testing::MakeTempDir("dmio");
  const DepthMap m = MakeMap();
  EXPECT_FALSE(DepthMapFilesExist(out, "v_01"));
  WriteDepthMapFiles(out, "v_01", m, {"b.png", "dir/c d.png"});
  EXPECT_TRUE(DepthMapFilesExist(out, "v_01"));
  const DepthMapPaths p = MakeDepthMapPaths(out, "v_01");
  EXPECT_EQ(p.depth, out + "/depth/v_01.pfm");
  EXPECT_EQ(p.camera, out + "/cameras/v_01.txt");
  for (const std::string& f :
       {p.depth, p.normal, p.confidence, p.camera, p.preview_depth,
        p.preview_confidence, p.preview_normal})
    EXPECT_TRUE(fs::exists(f)) << f;
  const DepthMapFiles r = ReadDepthMapFiles(out, "v_01");
  EXPECT_EQ(r.neighbor_names,
            (std::vector<std::string>{"b.png", "dir/c d.png"}));
  EXPECT_EQ(cv::norm(r.map.depth, m.depth, cv::NORM_INF), 0);
  EXPECT_EQ(cv::norm(r.map.normal, m.normal, cv::NORM_INF), 0);
  EXPECT_EQ(cv::norm(r.map.confidence, m.confidence, cv::NORM_INF), 0);
  EXPECT_EQ(r.map.camera.width, 40);
  EXPECT_EQ(r.map.camera.fx, m.camera.fx);
  EXPECT_EQ(r.map.camera.cy, m.camera.cy);
  EXPECT_LT((r.map.camera.R - m.camera.R).norm(), 1e-15);
  EXPECT_EQ(r.map.camera.t, m.camera.t);
  EXPECT_EQ(r.map.view, -1);

  // Resolved against a scene.
  Scene s;
  for (const char* n : {"a.png", "v_01.jpg", "dir/c d.png", "b.png"}) {
    View v;
    v.name = n;
    s.views.push_back(v);
  }
  const DepthMap rs = ReadDepthMapFiles(out, "v_01", s);
  EXPECT_EQ(rs.view, 1);
  EXPECT_EQ(rs.neighbors, (std::vector<int>{3, 2}));
  s.views.pop_back();
  EXPECT_THROW(ReadDepthMapFiles(out, "v_01", s), Error);
  fs::remove_all(out);
}

TEST(DepthMapIo, DepthOnlyAndErrors) {
  const std::string out = testing::MakeTempDir("dmio2");
  DepthMap m = MakeMap();
  m.normal.release();
  m.confidence.release();
  WriteDepthMapFiles(out, "x", m, {}, /*previews=*/false);
  EXPECT_FALSE(fs::exists(out + "/normal/x.pfm"));
  EXPECT_FALSE(fs::exists(out + "/preview"));
  const DepthMapFiles r = ReadDepthMapFiles(out, "x");
  EXPECT_TRUE(r.map.normal.empty());
  EXPECT_TRUE(r.neighbor_names.empty());
  // Mismatched sizes are refused on write.
  DepthMap bad = MakeMap();
  bad.camera.width = 41;
  EXPECT_THROW(WriteDepthMapFiles(out, "y", bad, {}), Error);
  EXPECT_FALSE(DepthMapFilesExist(out, "y"));
  // A camera file truncated / with NaN names file and line.
  const std::string cam = out + "/cameras/x.txt";
  std::ofstream(cam) << "# c\n40 30\n35 36 20 15\n1 0 0\n0 1 0\n";
  try {
    ReadDepthMapFiles(out, "x");
    ADD_FAILURE();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("x.txt line 6"), std::string::npos)
        << e.what();
  }
  std::ofstream(cam) << "40 30\n35 nan 20 15\n1 0 0\n0 1 0\n0 0 1\n0 0 0\n0\n";
  EXPECT_THROW(ReadDepthMapFiles(out, "x"), Error);
  std::ofstream(cam) << "41 30\n35 36 20 15\n1 0 0\n0 1 0\n0 0 1\n0 0 0\n0\n";
  try {
    ReadDepthMapFiles(out, "x");
    ADD_FAILURE();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("depth is 40x30"), std::string::npos)
        << e.what();
  }
  std::ofstream(cam)
      << "40 30\n35 36 20 15\n1 0 0\n0 1 0\n0 0 1\n0 0 0\n2\na\n";
  EXPECT_THROW(ReadDepthMapFiles(out, "x"), Error);
  std::ofstream(cam) << "40 30\n35 36 20 15\n1 0 0\n0 2 0\n0 0 1\n0 0 0\n0\n";
  EXPECT_THROW(ReadDepthMapFiles(out, "x"), Error);
  fs::remove_all(out);
}

}  // namespace
}  // namespace wild_mvs
