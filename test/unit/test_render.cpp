// Copyright wild_mvs authors. Offscreen renderer: a sphere (mesh and point
// cloud) covers exactly the pixels whose rays hit it, the z-buffer keeps the
// nearest surface, lighting comes from the configured side, fitted cameras
// see every point, and `wild_mvs render` writes a PNG.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <opencv2/imgcodecs.hpp>
#include <random>

#include "wild_mvs/core/error.h"
#include "wild_mvs/io/ply.h"
#include "wild_mvs/io/render.h"

namespace wild_mvs {
namespace {

constexpr double kRadius = 1.0;
constexpr double kDistance = 5.0;  // camera centre to sphere centre

// Camera on -z looking at the origin along +z (identity rotation).
Camera FrontCamera(int w = 160, int h = 120) {
  Camera c;
  c.width = w;
  c.height = h;
  c.fx = c.fy = 150;
  c.cx = 0.5 * w;
  c.cy = 0.5 * h;
  c.t = Eigen::Vector3d(0, 0, kDistance);
  return c;
}

// UV sphere (outward counter-clockwise faces).
Mesh Sphere(int stacks, int slices) {
  Mesh m;
  for (int i = 0; i <= stacks; ++i) {
    const double th = M_PI * i / stacks;
    for (int j = 0; j < slices; ++j) {
      const double ph = 2 * M_PI * j / slices;
      const Eigen::Vector3f p(std::sin(th) * std::cos(ph),
                              std::sin(th) * std::sin(ph), std::cos(th));
      m.vertices.xyz.push_back(static_cast<float>(kRadius) * p);
      m.vertices.normal.push_back(p);
    }
  }
  auto id = [&](int i, int j) { return i * slices + (j % slices); };
  for (int i = 0; i < stacks; ++i) {
    for (int j = 0; j < slices; ++j) {
      if (i > 0) m.faces.emplace_back(id(i, j), id(i + 1, j), id(i, j + 1));
      if (i + 1 < stacks) {
        m.faces.emplace_back(id(i, j + 1), id(i + 1, j), id(i + 1, j + 1));
      }
    }
  }
  return m;
}

PointCloud SpherePoints(int n, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<float> g;
  PointCloud c;
  for (int i = 0; i < n; ++i) {
    Eigen::Vector3f p(g(rng), g(rng), g(rng));
    p.normalize();
    c.xyz.push_back(static_cast<float>(kRadius) * p);
    c.normal.push_back(p);
  }
  return c;
}

// Distance from the sphere centre (origin) to the ray through pixel (x, y).
double RayDistance(const Camera& cam, int x, int y) {
  const Eigen::Vector3d d =
      cam.RayWorld(Eigen::Vector2d(x + 0.5, y + 0.5)).normalized();
  const Eigen::Vector3d C = cam.Center();
  return (C - C.dot(d) * d).norm();
}

bool IsBackground(const cv::Vec3b& p) {
  return p[0] == 255 && p[1] == 255 && p[2] == 255;
}

// Counts pixels that break the analytic silhouette: ray distance below
// inner x radius but background, or above outer x radius but covered.
struct Coverage {
  int missed_inside = 0, spilled_outside = 0, inside = 0;
};
Coverage CheckSilhouette(const cv::Mat& img, const Camera& cam, double inner,
                         double outer) {
  Coverage c;
  for (int y = 0; y < img.rows; ++y) {
    for (int x = 0; x < img.cols; ++x) {
      const double d = RayDistance(cam, x, y);
      const bool bg = IsBackground(img.at<cv::Vec3b>(y, x));
      if (d < inner * kRadius) {
        ++c.inside;
        if (bg) ++c.missed_inside;
      } else if (d > outer * kRadius && !bg) {
        ++c.spilled_outside;
      }
    }
  }
  return c;
}

TEST(Render, MeshSphereCoversItsSilhouette) {
  const Camera cam = FrontCamera();
  RenderOptions opt;
  opt.supersample = 1;
  const cv::Mat img = RenderMesh(Sphere(48, 96), cam, opt);
  ASSERT_EQ(img.cols, cam.width);
  ASSERT_EQ(img.rows, cam.height);
  ASSERT_EQ(img.type(), CV_8UC3);
  // The silhouette radius is ~30 px; the UV sphere's chords lie within
  // 1 - cos(pi / 96) = 0.05 % of the radius.
  const Coverage c = CheckSilhouette(img, cam, 0.98, 1.02);
  EXPECT_GT(c.inside, 2500);
  EXPECT_EQ(c.missed_inside, 0);
  EXPECT_EQ(c.spilled_outside, 0);
}

TEST(Render, MeshLightComesFromTheUpperLeftByDefault) {
  const Camera cam = FrontCamera();
  RenderOptions opt;
  opt.supersample = 1;
  const cv::Mat img = RenderMesh(Sphere(48, 96), cam, opt);
  // Light from the upper left (light_dir_cam = (0.4, 0.6, 1) points down
  // right, into the scene): the upper-left part of the sphere is brighter.
  const int cx = cam.width / 2, cy = cam.height / 2, r = 15;
  const int upper_left = img.at<cv::Vec3b>(cy - r, cx - r)[1];
  const int lower_right = img.at<cv::Vec3b>(cy + r, cx + r)[1];
  EXPECT_GT(upper_left, lower_right + 60);
  // Grey: equal channels.
  const cv::Vec3b p = img.at<cv::Vec3b>(cy, cx);
  EXPECT_EQ(p[0], p[1]);
  EXPECT_EQ(p[1], p[2]);
  // Fully lit surface normal (0.4, 0.6, 1) reversed = albedo x 1.
  const Eigen::Vector3d to_light =
      -opt.light_dir_cam.normalized();  // camera frame, towards the light
  // The sphere point whose normal is to_light, projected.
  const Eigen::Vector3d X = kRadius * to_light;
  const Eigen::Vector2d px = cam.ProjectCam(cam.WorldToCamera(X));
  const int brightest =
      img.at<cv::Vec3b>(static_cast<int>(px.y()), static_cast<int>(px.x()))[1];
  EXPECT_NEAR(brightest, 255 * opt.albedo, 6);
}

TEST(Render, PointSphereCoversItsSilhouette) {
  const Camera cam = FrontCamera();
  RenderOptions opt;
  opt.supersample = 1;
  const PointCloud cloud = SpherePoints(200000, 7);
  const cv::Mat img = RenderPointCloud(cloud, cam, opt);
  // 200k random samples: >= 11 per pixel even at the disc centre, where the
  // projected density is lowest, so 1-px splats (the automatic size, 1.5 x
  // the median spacing, is below a pixel here) leave almost no pinholes;
  // a splat spills at most 1 px (0.03 r at 30 px radius) past the limb.
  const Coverage c = CheckSilhouette(img, cam, 0.9, 1.08);
  EXPECT_GT(c.inside, 2000);
  EXPECT_LE(c.missed_inside, c.inside / 200);  // <= 0.5 % pinholes
  EXPECT_EQ(c.spilled_outside, 0);
}

TEST(Render, PointColoursAreDrawnAsIs) {
  const Camera cam = FrontCamera();
  RenderOptions opt;
  opt.supersample = 1;
  PointCloud cloud = SpherePoints(200000, 8);
  cloud.rgb.assign(cloud.size(), Eigen::Vector3f(1.0f, 0.5f, 0.0f));
  const cv::Mat img = RenderPointCloud(cloud, cam, opt);
  const cv::Vec3b p = img.at<cv::Vec3b>(cam.height / 2, cam.width / 2);
  EXPECT_EQ(p[2], 255);       // R
  EXPECT_NEAR(p[1], 128, 1);  // G
  EXPECT_EQ(p[0], 0);         // B
}

TEST(Render, ZBufferKeepsTheNearestSurface) {
  // A red square at z = 1 in front of a blue square at z = 2 (world = camera
  // frame), both covering the image centre; drawn far-last.
  Camera cam = FrontCamera();
  cam.t.setZero();
  Mesh m;
  auto square = [&](float z, float half, const Eigen::Vector3f& rgb) {
    const int b = static_cast<int>(m.vertices.size());
    for (const auto& xy :
         {Eigen::Vector2f(-half, -half), Eigen::Vector2f(half, -half),
          Eigen::Vector2f(half, half), Eigen::Vector2f(-half, half)}) {
      m.vertices.xyz.emplace_back(xy.x(), xy.y(), z);
      m.vertices.rgb.push_back(rgb);
    }
    m.faces.emplace_back(b, b + 1, b + 2);
    m.faces.emplace_back(b, b + 2, b + 3);
  };
  square(1.0f, 0.1f, Eigen::Vector3f(1, 0, 0));
  square(2.0f, 1.0f, Eigen::Vector3f(0, 0, 1));
  RenderOptions opt;
  opt.supersample = 1;
  opt.mesh_vertex_colors = true;
  opt.ambient = 1.0;  // unshaded: colours exact
  const cv::Mat img = RenderMesh(m, cam, opt);
  const cv::Vec3b centre = img.at<cv::Vec3b>(cam.height / 2, cam.width / 2);
  EXPECT_EQ(centre, cv::Vec3b(0, 0, 255));  // red (BGR)
  // 0.1 / 1 x 150 = 15 px half width: 20 px off-centre is the blue square.
  const cv::Vec3b side = img.at<cv::Vec3b>(cam.height / 2, cam.width / 2 + 20);
  EXPECT_EQ(side, cv::Vec3b(255, 0, 0));
  // Same with points (splats of 0.02 world units).
  PointCloud pts;
  for (int i = 0; i < 2; ++i) {
    pts.xyz.emplace_back(0, 0, i == 0 ? 2.0f : 1.0f);
    pts.rgb.emplace_back(i == 0 ? 0 : 1, 0, i == 0 ? 1 : 0);
  }
  opt.point_size = 0.05;
  const cv::Mat dots = RenderPointCloud(pts, cam, opt);
  EXPECT_EQ(dots.at<cv::Vec3b>(cam.height / 2, cam.width / 2),
            cv::Vec3b(0, 0, 255));
}

TEST(Render, FittedCameraSeesEveryPointAndFillsTheImage) {
  PointCloud cloud = SpherePoints(5000, 9);
  for (auto& p : cloud.xyz) p = p.cwiseProduct(Eigen::Vector3f(3, 1, 0.5f));
  for (auto& p : cloud.xyz) p += Eigen::Vector3f(10, -4, 2);
  const Eigen::Matrix3d R = AutoViewRotation(cloud, Eigen::Vector3d(0, 1, 0));
  // Least spread is z: the camera looks along +-z; up (-y row) is +y (up to
  // the sampling noise of the PCA axes).
  EXPECT_NEAR(std::abs(R(2, 2)), 1.0, 1e-3);
  EXPECT_NEAR(-R(1, 1), 1.0, 1e-3);
  const Camera cam = FitCameraToPoints(cloud.xyz, R, 400, 300, 40, 0.05);
  double min_x = 1e9, max_x = -1e9;
  int outside = 0;
  for (const auto& p : cloud.xyz) {
    Eigen::Vector2d px;
    ASSERT_TRUE(cam.Project(p.cast<double>(), &px));
    if (!cam.InImage(px)) ++outside;
    min_x = std::min(min_x, px.x());
    max_x = std::max(max_x, px.x());
  }
  // The robust box (2..98 %) is fitted: a few extreme points may leave it.
  EXPECT_LE(outside, 50);
  // The long axis (x, 3 units) spans most of the width.
  EXPECT_GT(max_x - min_x, 0.8 * 400);
}

TEST(Render, BadInputThrows) {
  RenderOptions opt;
  opt.ambient = 2;
  EXPECT_THROW(opt.Check(), Error);
  EXPECT_THROW(FitCameraToPoints({}, Eigen::Matrix3d::Identity(), 10, 10),
               Error);
  Mesh m = Sphere(4, 8);
  m.faces.emplace_back(0, 1, 1000);
  EXPECT_THROW(RenderMesh(m, FrontCamera(), {}), Error);
}

TEST(Render, CommandWritesPng) {
  namespace fs = std::filesystem;
  const fs::path dir = fs::temp_directory_path() / "wild_mvs_test_render";
  fs::remove_all(dir);
  fs::create_directories(dir);
  const std::string ply = (dir / "mesh.ply").string();
  WritePly(ply, Sphere(16, 32));
  const std::string png = (dir / "mesh.png").string();
  const std::string cmd = std::string(WILD_MVS_CLI) + " render " + ply + " " +
                          png + " --width 120 --up 0,1,0 > /dev/null";
  ASSERT_EQ(std::system(cmd.c_str()), 0);
  const cv::Mat img = cv::imread(png);
  ASSERT_FALSE(img.empty());
  EXPECT_EQ(img.cols, 120);
  EXPECT_EQ(img.rows, 90);
  int covered = 0;
  for (int y = 0; y < img.rows; ++y) {
    for (int x = 0; x < img.cols; ++x) {
      covered += !IsBackground(img.at<cv::Vec3b>(y, x));
    }
  }
  EXPECT_GT(covered, 1000);
  // Bad usage exits with 2.
  const std::string bad = std::string(WILD_MVS_CLI) + " render " + ply + " " +
                          png + " --hfov 0 > /dev/null 2>&1";
  EXPECT_EQ(WEXITSTATUS(std::system(bad.c_str())), 2);
  fs::remove_all(dir);
}

}  // namespace
}  // namespace wild_mvs
