// Copyright wild_mvs authors. The photos-only pipeline with the real tools:
// `wild_mvs photos` on the bundled templeSparseRing photos without their
// poses (COLMAP finds the cameras), then COLMAP's own stereo_fusion and
// poisson_mesher on the workspace wild_mvs wrote.
// Skipped (visibly) when the colmap program is not installed
// (scripts/install_deps.sh --extra installs it).
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <opencv2/imgcodecs.hpp>
#include <regex>
#include <string>
#include <vector>

#include "test_paths.h"
#include "wild_mvs/cli/subprocess.h"
#include "wild_mvs/core/fusion.h"
#include "wild_mvs/core/metrics.h"
#include "wild_mvs/io/colmap.h"
#include "wild_mvs/io/colmap_dense.h"
#include "wild_mvs/io/depth_map_io.h"
#include "wild_mvs/io/pfm.h"
#include "wild_mvs/io/ply.h"

namespace wild_mvs {
namespace {

namespace fs = std::filesystem;

struct RunResult {
  int status = -1;
  std::string output;
};

RunResult RunCommand(const std::string& cmd) {
  RunResult r;
  FILE* p = popen((cmd + " 2>&1").c_str(), "r");
  if (!p) return r;
  char buf[4096];
  size_t n;
  while ((n = fread(buf, 1, sizeof(buf), p)) > 0) r.output.append(buf, n);
  const int st = pclose(p);
  r.status = WIFEXITED(st) ? WEXITSTATUS(st) : 128 + WTERMSIG(st);
  return r;
}

class ColmapPhotos : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    colmap_ = cli::FindExecutable("colmap");
    if (colmap_.empty()) return;
    root_ = testing::MakeTempDir("wild_mvs_colmap_photos");
    const std::string photos = root_ + "/photos";
    fs::create_directories(photos);
    // Only the photos: no *_par.txt, no poses.
    for (const auto& e : fs::directory_iterator(testing::SourceDir() +
                                                "/data/templeSparseRing"))
      if (e.path().extension() == ".png")
        fs::copy_file(e.path(), photos + "/" + e.path().filename().string());
    out_ = root_ + "/out";
    photos_run_ =
        RunCommand(std::string("'") + WILD_MVS_CLI + "' photos '" + photos +
                   "' '" + out_ + "' --max-image-size 320 --threads 2");
    ws_ = out_ + "/dense";
    // COLMAP's own dense tools on the maps wild_mvs wrote. Fusion with
    // wild_mvs's fusion thresholds (COLMAP's defaults, 5 pixels and 10
    // degrees, keep a quarter of the points of these noisier normals); a
    // coarse single-threaded Poisson (fast; its default trim of 10 would
    // remove every vertex of a cloud this small).
    const FusionOptions fusion;
    fusion_run_ =
        RunCommand("'" + colmap_ + "' stereo_fusion --workspace_path '" + ws_ +
                   "' --input_type geometric --StereoFusion.num_threads 2 "
                   "--StereoFusion.min_num_pixels " +
                   std::to_string(fusion.min_support) +
                   " --StereoFusion.max_normal_error " +
                   std::to_string(fusion.normal_tolerance_deg) +
                   " --output_path '" + root_ + "/colmap_fused.ply'");
    const std::string poisson =
        " --PoissonMeshing.depth 7 --PoissonMeshing.trim 4 "
        "--PoissonMeshing.num_threads 1";
    poisson_run_ =
        RunCommand("'" + colmap_ + "' poisson_mesher --input_path '" + root_ +
                   "/colmap_fused.ply' --output_path '" + root_ +
                   "/colmap_poisson.ply'" + poisson);
    // Our fused.ply in the workspace, in COLMAP's format.
    poisson_ours_run_ =
        RunCommand("'" + colmap_ + "' poisson_mesher --input_path '" + ws_ +
                   "/fused.ply' --output_path '" + root_ +
                   "/colmap_poisson_ours.ply'" + poisson);
  }
  static void TearDownTestSuite() {
    if (root_.empty()) return;
    std::error_code ec;
    fs::remove_all(root_, ec);
  }
  void SetUp() override {
    if (colmap_.empty()) {
      GTEST_SKIP() << "colmap is not installed (apt-get install colmap, or "
                      "scripts/install_deps.sh --extra)";
    }
  }
  static std::string colmap_, root_, out_, ws_;
  static RunResult photos_run_, fusion_run_, poisson_run_, poisson_ours_run_;
};
std::string ColmapPhotos::colmap_, ColmapPhotos::root_, ColmapPhotos::out_,
    ColmapPhotos::ws_;
RunResult ColmapPhotos::photos_run_, ColmapPhotos::fusion_run_,
    ColmapPhotos::poisson_run_, ColmapPhotos::poisson_ours_run_;

TEST_F(ColmapPhotos, RegistersTheViewsAndReconstructs) {
  ASSERT_EQ(photos_run_.status, 0) << photos_run_.output;
  std::smatch m;
  ASSERT_TRUE(std::regex_search(
      photos_run_.output, m,
      std::regex("photos summary: ([0-9]+) of 16 photos registered")))
      << photos_run_.output;
  EXPECT_GE(std::stoi(m[1]), 14) << photos_run_.output;
  std::cout << m.str(0) << "\n";
  const Scene model = ReadColmapModel(ws_ + "/sparse");
  EXPECT_GE(model.views.size(), 14u);
  const PointCloud ours = ReadPlyCloud(out_ + "/fused.ply");
  EXPECT_GT(ours.size(), 5000u);
  EXPECT_GT(ReadPlyMesh(out_ + "/mesh.ply").faces.size(), 10000u);
}

// Every map in the workspace equals the map wild_mvs wrote as PFM, value
// for value: geometric = OUT's, photometric = OUT/raw's (before the
// consistency filter).
TEST_F(ColmapPhotos, WorkspaceMapsEqualOurMaps) {
  ASSERT_EQ(photos_run_.status, 0) << photos_run_.output;
  const Scene model = ReadColmapModel(ws_ + "/sparse");
  for (const View& v : model.views) {
    const std::string s = v.Stem();
    SCOPED_TRACE(v.name);
    const DepthMapPaths geo = MakeDepthMapPaths(out_, s);
    const DepthMapPaths raw = MakeDepthMapPaths(out_ + "/raw", s);
    ASSERT_TRUE(fs::exists(raw.depth));
    const auto same = [](const cv::Mat& a, const cv::Mat& b) {
      return a.size() == b.size() && a.type() == b.type() &&
             cv::norm(a, b, cv::NORM_INF) == 0;
    };
    EXPECT_TRUE(same(ReadColmapArray(ColmapDepthMapPath(
                         ws_, v.name, ColmapMapKind::kGeometric)),
                     ReadPfm(geo.depth)));
    EXPECT_TRUE(same(ReadColmapArray(ColmapNormalMapPath(
                         ws_, v.name, ColmapMapKind::kGeometric)),
                     ReadPfm(geo.normal)));
    EXPECT_TRUE(same(ReadColmapArray(ColmapDepthMapPath(
                         ws_, v.name, ColmapMapKind::kPhotometric)),
                     ReadPfm(raw.depth)));
    EXPECT_TRUE(same(ReadColmapArray(ColmapNormalMapPath(
                         ws_, v.name, ColmapMapKind::kPhotometric)),
                     ReadPfm(raw.normal)));
  }
}

// COLMAP's fusion accepts the maps and agrees with our own cloud at the
// scene's 2-pixel footprint; its Poisson mesher accepts its cloud and ours.
// (Debian's colmap is built without CGAL: no delaunay_mesher, the reader
// of fused.ply.vis; the format is checked against stereo_fusion's own .vis
// file here and in test_io_colmap_dense.)
TEST_F(ColmapPhotos, ColmapFusionAndMeshersAcceptOurMaps) {
  ASSERT_EQ(photos_run_.status, 0) << photos_run_.output;
  ASSERT_EQ(fusion_run_.status, 0) << fusion_run_.output;
  const PointCloud theirs = ReadPlyCloud(root_ + "/colmap_fused.ply");
  const PointCloud ours = ReadPlyCloud(out_ + "/fused.ply");
  ASSERT_GT(theirs.size(), 5000u);
  // 2 pixels at the median depth of the first view's map.
  const Scene model = ReadColmapModel(ws_ + "/sparse");
  const DepthMapFiles f = ReadDepthMapFiles(out_, model.views[0].Stem());
  std::vector<float> z;
  for (int r = 0; r < f.map.depth.rows; ++r)
    for (int c = 0; c < f.map.depth.cols; ++c)
      if (f.map.depth.at<float>(r, c) > 0)
        z.push_back(f.map.depth.at<float>(r, c));
  ASSERT_FALSE(z.empty());
  std::nth_element(z.begin(), z.begin() + z.size() / 2, z.end());
  const double tau = 2 * z[z.size() / 2] / f.map.camera.fx;
  CloudMetricsOptions o;
  o.taus = {tau};
  o.num_threads = 2;
  const CloudMetrics cm = EvaluateCloud(theirs, ours, o);
  SCOPED_TRACE(cm.ToString());
  EXPECT_GE(cm.fscore[0], 0.9);
  std::cout << "COLMAP's fusion of our maps (" << theirs.size()
            << " points) vs our fused cloud (" << ours.size()
            << " points) at tau " << tau << ": F " << cm.fscore[0]
            << ", precision " << cm.precision[0] << ", recall " << cm.recall[0]
            << "\n";
  // COLMAP's image indices are the model's order: each image a COLMAP
  // point lists sees it in our geometric map.
  const auto vis = ReadColmapVisibility(root_ + "/colmap_fused.ply.vis");
  ASSERT_EQ(vis.size(), theirs.size());
  std::vector<DepthMap> maps;
  for (const View& v : model.views)
    maps.push_back(ReadDepthMapFiles(out_, v.Stem()).map);
  size_t pairs = 0, agree = 0;
  for (size_t i = 0; i < vis.size(); i += 7) {
    for (uint32_t idx : vis[i]) {
      ASSERT_LT(idx, maps.size());
      ++pairs;
      agree +=
          AgreesWithDepthMap(theirs.xyz[i].cast<double>(), maps[idx], 0.01);
    }
  }
  ASSERT_GT(pairs, 1000u);
  EXPECT_GT(static_cast<double>(agree) / pairs, 0.95);

  ASSERT_EQ(poisson_run_.status, 0) << poisson_run_.output;
  EXPECT_GT(ReadPlyMesh(root_ + "/colmap_poisson.ply").faces.size(), 1000u);
  ASSERT_EQ(poisson_ours_run_.status, 0) << poisson_ours_run_.output;
  EXPECT_GT(ReadPlyMesh(root_ + "/colmap_poisson_ours.ply").faces.size(),
            1000u);
}

// Without colmap, or with photos that COLMAP cannot connect: a clear error
// and exit status 1, before or instead of any reconstruction.
TEST(ColmapPhotosErrors, MissingColmapAndUnrelatedPhotos) {
  const std::string root = testing::MakeTempDir("wild_mvs_photos_errors");
  const std::string photos = root + "/photos";
  fs::create_directories(photos);
  cv::RNG rng(5);
  for (int i = 0; i < 3; ++i) {  // noise: nothing matches between them
    cv::Mat img(120, 160, CV_8UC3);
    rng.fill(img, cv::RNG::UNIFORM, 0, 256);
    cv::imwrite(photos + "/noise" + std::to_string(i) + ".png", img);
  }
  const std::string cli = std::string("'") + WILD_MVS_CLI + "' photos '" +
                          photos + "' '" + root + "/out' --threads 2";
  RunResult r = RunCommand(cli + " --colmap /nonexistent/colmap");
  EXPECT_EQ(r.status, 1) << r.output;
  EXPECT_NE(r.output.find("wild_mvs photos: /nonexistent/colmap: not an "
                          "executable file"),
            std::string::npos)
      << r.output;
  r = RunCommand(cli + " --colmap no-such-colmap-program");
  EXPECT_EQ(r.status, 1) << r.output;
  EXPECT_NE(r.output.find("no-such-colmap-program: not found in PATH: "
                          "install COLMAP (Debian: apt-get install colmap)"),
            std::string::npos)
      << r.output;
  fs::create_directories(root + "/two");
  fs::copy_file(photos + "/noise0.png", root + "/two/a.png");
  r = RunCommand(std::string("'") + WILD_MVS_CLI + "' photos '" + root +
                 "/two' '" + root + "/out'");
  EXPECT_EQ(r.status, 1) << r.output;
  EXPECT_NE(r.output.find("1 photos (.jpg, .png, .tif, ...) found; at least 3"),
            std::string::npos)
      << r.output;
  if (!cli::FindExecutable("colmap").empty()) {
    r = RunCommand(cli);
    EXPECT_EQ(r.status, 1) << r.output;
    EXPECT_NE(r.output.find("COLMAP could not register any photos"),
              std::string::npos)
        << r.output;
    EXPECT_FALSE(fs::exists(root + "/out/fused.ply"));
  }
  fs::remove_all(root);
}

}  // namespace
}  // namespace wild_mvs
