// Copyright wild_mvs authors. COLMAP's dense workspace files: the array
// format of depth and normal maps (round trip, a hand-written file, bad
// headers), the visibility file, the stereo configuration, and the
// workspace writer of `wild_mvs reconstruct` on a rendered scene with
// fx != fy and an off-centre principal point.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "synthetic_lens.h"
#include "synthetic_scene.h"
#include "test_paths.h"
#include "wild_mvs/cli/colmap_export.h"
#include "wild_mvs/core/error.h"
#include "wild_mvs/io/colmap.h"
#include "wild_mvs/io/colmap_dense.h"
#include "wild_mvs/io/dataset.h"
#include "wild_mvs/io/depth_map_io.h"
#include "wild_mvs/io/ply.h"

namespace wild_mvs {
namespace {

namespace fs = std::filesystem;

void WriteBytes(const std::string& path, const std::string& s) {
  std::ofstream out(path, std::ios::binary);
  out << s;
}

std::string FloatBytes(const std::vector<float>& v) {
  std::string s(v.size() * 4, '\0');
  std::memcpy(s.data(), v.data(), s.size());
  return s;
}

// The error message of f(), or "" when it does not throw.
template <typename F>
std::string ErrorOf(F f) {
  try {
    f();
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

TEST(ColmapArray, RoundTripOneAndThreeChannels) {
  const std::string dir = testing::MakeTempDir("colmap_array");
  cv::Mat d(5, 7, CV_32F);
  cv::randu(d, 0.5, 3.0);
  d.at<float>(1, 2) = 0;  // unknown stays 0
  WriteColmapArray(dir + "/d.bin", d);
  const cv::Mat d2 = ReadColmapArray(dir + "/d.bin");
  ASSERT_EQ(d2.type(), CV_32F);
  EXPECT_EQ(cv::norm(d, d2, cv::NORM_INF), 0);
  cv::Mat n(4, 3, CV_32FC3);
  cv::randu(n, -1, 1);
  WriteColmapArray(dir + "/n.bin", n);
  const cv::Mat n2 = ReadColmapArray(dir + "/n.bin");
  ASSERT_EQ(n2.type(), CV_32FC3);
  EXPECT_EQ(cv::norm(n, n2, cv::NORM_INF), 0);
  // Header then planar data: the file is exactly that long.
  EXPECT_EQ(fs::file_size(dir + "/n.bin"),
            std::string("3&4&3&").size() + 3 * 4 * 3 * 4u);
  fs::remove_all(dir);
}

// A file written by hand in COLMAP's layout: x fastest, then y, then
// channel.
TEST(ColmapArray, ReadsAHandWrittenFile) {
  const std::string dir = testing::MakeTempDir("colmap_array_hand");
  std::vector<float> v;
  for (int c = 0; c < 2; ++c)
    for (int y = 0; y < 2; ++y)
      for (int x = 0; x < 3; ++x) v.push_back(100.f * c + 10.f * y + x);
  WriteBytes(dir + "/a.bin", "3&2&2&" + FloatBytes(v));
  const cv::Mat a = ReadColmapArray(dir + "/a.bin");
  ASSERT_EQ(a.cols, 3);
  ASSERT_EQ(a.rows, 2);
  ASSERT_EQ(a.channels(), 2);
  for (int y = 0; y < 2; ++y)
    for (int x = 0; x < 3; ++x) {
      EXPECT_EQ(a.at<cv::Vec2f>(y, x)[0], 10.f * y + x);
      EXPECT_EQ(a.at<cv::Vec2f>(y, x)[1], 100.f + 10.f * y + x);
    }
  fs::remove_all(dir);
}

TEST(ColmapArray, BadFilesGiveErrorsNamingTheFile) {
  const std::string dir = testing::MakeTempDir("colmap_array_bad");
  const std::string p = dir + "/bad.bin";
  WriteBytes(p, "Pf\n3 2\n-1\n" + FloatBytes(std::vector<float>(6, 1.f)));
  std::string e = ErrorOf([&] { ReadColmapArray(p); });
  EXPECT_NE(e.find(p), std::string::npos) << e;
  EXPECT_NE(e.find("not a COLMAP array file"), std::string::npos) << e;
  WriteBytes(p, "3&2&1&" + FloatBytes(std::vector<float>(4, 1.f)));
  e = ErrorOf([&] { ReadColmapArray(p); });
  EXPECT_NE(e.find(p + ": COLMAP array 3x2x1 needs 24 bytes"),
            std::string::npos)
      << e;
  EXPECT_NE(e.find("truncated"), std::string::npos) << e;
  WriteBytes(p, "0&2&1&");
  e = ErrorOf([&] { ReadColmapArray(p); });
  EXPECT_NE(e.find(p + ": invalid COLMAP array size 0x2"), std::string::npos)
      << e;
  WriteBytes(p, "2&2&9&");
  e = ErrorOf([&] { ReadColmapArray(p); });
  EXPECT_NE(e.find("9 channels"), std::string::npos) << e;
  e = ErrorOf([&] { ReadColmapArray(dir + "/missing.bin"); });
  EXPECT_NE(e.find(dir + "/missing.bin: cannot open"), std::string::npos) << e;
  fs::remove_all(dir);
}

TEST(ColmapVisibility, RoundTripAndTruncation) {
  const std::string dir = testing::MakeTempDir("colmap_vis");
  PointCloud c;
  c.xyz = {{0, 0, 1}, {1, 2, 3}, {4, 5, 6}};
  c.rgb = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  const std::vector<std::vector<uint32_t>> vis = {{0, 3}, {}, {1, 2, 7}};
  WriteColmapFusedCloud(dir + "/fused.ply", c, vis);
  EXPECT_EQ(ReadColmapVisibility(dir + "/fused.ply.vis"), vis);
  // uint64 count, then per point uint32 n and n uint32 indices.
  EXPECT_EQ(fs::file_size(dir + "/fused.ply.vis"), 8 + 3 * 4 + 5 * 4u);
  const PointCloud back = ReadPlyCloud(dir + "/fused.ply");
  ASSERT_EQ(back.size(), 3u);
  EXPECT_EQ(back.xyz[2], c.xyz[2]);
  ASSERT_TRUE(back.has_rgb());
  EXPECT_NEAR(back.rgb[1].y(), 1.0f, 1e-6);
  fs::resize_file(dir + "/fused.ply.vis", 20);
  const std::string e =
      ErrorOf([&] { ReadColmapVisibility(dir + "/fused.ply.vis"); });
  EXPECT_NE(e.find(dir + "/fused.ply.vis"), std::string::npos) << e;
  EXPECT_NE(e.find("truncated"), std::string::npos) << e;
  fs::remove_all(dir);
}

TEST(ColmapStereoConfig, WritesAndReadsSourcesAndFusionList) {
  const std::string dir = testing::MakeTempDir("colmap_cfg");
  WriteColmapStereoConfig(dir,
                          {{"a.jpg", {"b.jpg", "c d.jpg"}}, {"b.jpg", {}}});
  const auto e = ReadColmapPatchMatchConfig(dir + "/stereo/patch-match.cfg");
  ASSERT_EQ(e.size(), 2u);
  EXPECT_EQ(e[0].name, "a.jpg");
  EXPECT_EQ(e[0].sources, (std::vector<std::string>{"b.jpg", "c d.jpg"}));
  EXPECT_TRUE(e[1].sources.empty());
  std::ifstream in(dir + "/stereo/patch-match.cfg");
  std::stringstream ss;
  ss << in.rdbuf();
  EXPECT_EQ(ss.str(), "a.jpg\nb.jpg, c d.jpg\nb.jpg\n__auto__, 20\n");
  std::ifstream f(dir + "/stereo/fusion.cfg");
  std::stringstream fs2;
  fs2 << f.rdbuf();
  EXPECT_EQ(fs2.str(), "a.jpg\nb.jpg\n");
  fs::remove_all(dir);
}

// The workspace writer on a rendered scene whose cameras have fx != fy and
// an off-centre principal point: the ground-truth maps go into OUT as
// `reconstruct` writes them (full size for views 0 and 2, half size for
// view 1), are exported, and then interpreted the way COLMAP does (its
// model's camera scaled per axis to the map, normals rotated by R^T): every
// depth gives a point on the true surface, every normal the true normal
// facing the camera; and the visibility names the views that see a point.
TEST(ColmapWorkspaceWriter, RenderedSceneWithAnisotropicFocal) {
  testing::SyntheticSpec spec = testing::SlantedPlaneSpec(25, 3);
  spec.width = 96;
  spec.height = 72;
  spec.focal = 90;
  spec.num_sparse_points = 60;
  testing::SyntheticLens lens;
  lens.focal_y_ratio = 1.25;
  lens.principal_offset = {3.0, -2.0};
  const testing::SyntheticScene s = testing::Render(spec, lens);
  const std::string root = testing::MakeTempDir("colmap_ws_writer");
  const std::string ws = root + "/dense", out = root + "/out";
  testing::WriteDataset(s, ws);  // ws/images, ws/sparse (PINHOLE)
  fs::create_directories(ws + "/stereo");
  ASSERT_TRUE(IsColmapDenseWorkspace(ws));
  EXPECT_FALSE(IsColmapDenseWorkspace(ws + "/sparse"));
  {  // The dataset detection reads the workspace as it is.
    DatasetOptions o;
    o.path = ws;
    const Scene loaded = LoadDataset(o);
    ASSERT_EQ(loaded.views.size(), s.scene.views.size());
    EXPECT_EQ(fs::path(loaded.views[0].image_path).parent_path().filename(),
              "images");
  }
  const int n = static_cast<int>(s.scene.views.size());
  // The plane passes through the origin (SlantedPlaneSpec).
  const Eigen::Vector3d plane_normal =
      spec.objects[0].axis_u.cross(spec.objects[0].axis_v).normalized();
  for (int v = 0; v < n; ++v) {
    DepthMap m;
    m.view = v;
    m.camera = s.scene.views[v].camera;
    m.depth = s.depth[v].clone();
    m.normal = s.normals[v].clone();
    if (v == 1) {  // half size: the plane intersected at its pixel centres
      m.camera = m.camera.Resized(spec.width / 2, spec.height / 2);
      m.depth = cv::Mat::zeros(m.camera.height, m.camera.width, CV_32F);
      m.normal = cv::Mat::zeros(m.camera.height, m.camera.width, CV_32FC3);
      Eigen::Vector3d nc = m.camera.R * plane_normal;
      for (int r = 0; r < m.depth.rows; ++r)
        for (int c = 0; c < m.depth.cols; ++c) {
          const Eigen::Vector3d d =
              m.camera.BackprojectCam({c + 0.5, r + 0.5}, 1);
          const double z = nc.dot(m.camera.t) / nc.dot(d);
          if (!(z > 0)) continue;
          const Eigen::Vector3d n = nc.dot(d) < 0 ? nc : -nc;
          m.depth.at<float>(r, c) = static_cast<float>(z);
          m.normal.at<cv::Vec3f>(r, c) = cv::Vec3f(n.x(), n.y(), n.z());
        }
    }
    std::vector<std::string> nb;
    for (int u = 0; u < n; ++u)
      if (u != v) nb.push_back(s.scene.views[u].name);
    WriteDepthMapFiles(out, s.scene.views[v].Stem(), m, nb, false);
  }
  // A cloud on the surface, as OUT/fused.ply.
  const PointCloud gt = s.GroundTruthCloud(4);
  WritePly(out + "/fused.ply", gt);
  std::ostringstream log;
  const cli::ColmapExportResult r =
      cli::ExportToColmapWorkspace(s.scene, {0, 1, 2}, out, ws, 0.01, log);
  EXPECT_EQ(r.views, 3);
  EXPECT_EQ(r.points, gt.size());
  EXPECT_FALSE(r.photometric_from_raw);

  const Scene model = ReadColmapModel(ws + "/sparse");
  ASSERT_EQ(static_cast<int>(model.views.size()), n);
  for (int v = 0; v < n; ++v) {
    const Camera& cam = model.views[v].camera;
    EXPECT_NEAR(cam.fy / cam.fx, 1.25, 1e-9);
    const std::string name = model.views[v].name;
    const cv::Mat d = ReadColmapArray(
        ColmapDepthMapPath(ws, name, ColmapMapKind::kGeometric));
    const cv::Mat nm = ReadColmapArray(
        ColmapNormalMapPath(ws, name, ColmapMapKind::kGeometric));
    EXPECT_EQ(cv::norm(d,
                       ReadColmapArray(ColmapDepthMapPath(
                           ws, name, ColmapMapKind::kPhotometric)),
                       cv::NORM_INF),
              0);
    ASSERT_EQ(d.type(), CV_32F);
    ASSERT_EQ(nm.type(), CV_32FC3);
    const int step = v == 1 ? 2 : 1;
    ASSERT_EQ(d.cols * step, spec.width);
    ASSERT_EQ(d.rows * step, spec.height);
    // COLMAP's reading: K scaled by the size ratio per axis.
    const double sx = static_cast<double>(d.cols) / cam.width;
    const double sy = static_cast<double>(d.rows) / cam.height;
    int checked = 0;
    for (int r = 0; r < d.rows; ++r)
      for (int c = 0; c < d.cols; ++c) {
        const float z = d.at<float>(r, c);
        if (z <= 0) continue;
        const double u = (c + 0.5) / sx, w = (r + 0.5) / sy;  // full-size px
        // On the true surface.
        const Eigen::Vector3d X = cam.Backproject({u, w}, z);
        ASSERT_LT(std::abs(X.dot(plane_normal)), 1e-5) << name;
        const cv::Vec3f nc = nm.at<cv::Vec3f>(r, c);
        const Eigen::Vector3d ncam(nc[0], nc[1], nc[2]);
        EXPECT_NEAR(ncam.norm(), 1.0, 1e-4);
        EXPECT_LT(ncam.dot(cam.BackprojectCam({u, w}, 1)), 0)
            << "faces the camera";
        EXPECT_NEAR(std::abs((cam.R.transpose() * ncam).dot(plane_normal)), 1.0,
                    1e-5);
        ++checked;
      }
    EXPECT_GT(checked, d.rows * d.cols / 3) << name;
  }
  // Stereo configuration: every view with its neighbours.
  const auto cfg = ReadColmapPatchMatchConfig(ws + "/stereo/patch-match.cfg");
  ASSERT_EQ(cfg.size(), 3u);
  EXPECT_EQ(cfg[0].name, model.views[0].name);
  EXPECT_EQ(cfg[0].sources.size(), 2u);
  // Visibility: each point is seen by the views whose true depth agrees.
  const auto vis = ReadColmapVisibility(ws + "/fused.ply.vis");
  ASSERT_EQ(vis.size(), gt.size());
  size_t seen_by_two = 0;
  for (size_t i = 0; i < vis.size(); ++i) {
    ASSERT_FALSE(vis[i].empty()) << "a surface point seen by no view";
    for (size_t k = 0; k < vis[i].size(); ++k) {
      const uint32_t v = vis[i][k];
      ASSERT_LT(v, static_cast<uint32_t>(n));
      if (k) {
        EXPECT_LT(vis[i][k - 1], v);
      }
      Eigen::Vector2d px;
      ASSERT_TRUE(model.views[v].camera.Project(gt.xyz[i].cast<double>(), &px));
      EXPECT_TRUE(model.views[v].camera.InImage(px));
    }
    seen_by_two += vis[i].size() >= 2;
  }
  EXPECT_GT(seen_by_two, vis.size() / 2);
  EXPECT_EQ(ReadPlyCloud(ws + "/fused.ply").size(), gt.size());

  // A map computed for another camera is refused, naming the file.
  DepthMap wrong;
  wrong.camera = s.scene.views[0].camera;
  wrong.camera.fx *= 1.1;
  wrong.depth = s.depth[0].clone();
  WriteDepthMapFiles(out, s.scene.views[0].Stem(), wrong, {}, false);
  const std::string e = ErrorOf(
      [&] { cli::ExportToColmapWorkspace(s.scene, {0}, out, ws, 0.01, log); });
  EXPECT_NE(e.find("is not the camera of " + ws + "/sparse"), std::string::npos)
      << e;
  fs::remove_all(root);
}

}  // namespace
}  // namespace wild_mvs
