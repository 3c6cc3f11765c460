// Copyright wild_mvs authors. Every shared dataset loads, in every format it
// has, with consistent cameras; layout detection and overrides.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <opencv2/imgcodecs.hpp>

#include "test_paths.h"
#include "wild_mvs/core/error.h"
#include "wild_mvs/io/colmap.h"
#include "wild_mvs/io/dataset.h"
#include "wild_mvs/io/image_size.h"

namespace wild_mvs {
namespace {

namespace fs = std::filesystem;

// Median reprojection error of `points` (from `ref`, a scene with the same
// view names) seen through the cameras of `s`.
double MedianReprojection(const Scene& s, const Scene& ref) {
  std::vector<double> err;
  for (const SparsePoint& p : ref.points)
    for (const Observation& o : p.track) {
      const int v = s.FindView(ref.views[o.view].name);
      if (v < 0) continue;
      Eigen::Vector2d px;
      if (!s.views[v].camera.Project(p.xyz, &px)) {
        err.push_back(1e9);
        continue;
      }
      err.push_back((px - o.xy).norm());
    }
  if (err.empty()) return 1e9;
  std::nth_element(err.begin(), err.begin() + err.size() / 2, err.end());
  return err[err.size() / 2];
}

Scene Load(const std::string& path, DatasetFormat f = DatasetFormat::kAuto) {
  DatasetOptions o;
  o.path = path;
  o.format = f;
  return LoadDataset(o);
}

TEST(DatasetShared, EveryDatasetLoads) {
  WILD_MVS_REQUIRE_SHARED(root, "datasets");
  struct Expect {
    const char* dir;
    DatasetFormat format;
    size_t views, points;
  };
  const std::vector<Expect> all = {
      {"middlebury_templeSparseRing", DatasetFormat::kAuto, 16, 3544},
      {"middlebury_templeSparseRing", DatasetFormat::kMiddlebury, 16, 0},
      {"middlebury_dinoSparseRing", DatasetFormat::kAuto, 16, 1348},
      {"middlebury_dinoSparseRing", DatasetFormat::kMiddlebury, 16, 0},
      {"middlebury_templeRing", DatasetFormat::kAuto, 47, 3822},
      {"middlebury_templeRing", DatasetFormat::kMiddlebury, 47, 0},
      {"strecha_fountain-P11", DatasetFormat::kAuto, 11, 17558},
      {"strecha_fountain-P11", DatasetFormat::kStrecha, 11, 0},
      {"strecha_Herz-Jesus-P8", DatasetFormat::kAuto, 8, 12073},
      {"strecha_Herz-Jesus-P8", DatasetFormat::kStrecha, 8, 0},
      {"internet_sacre_coeur", DatasetFormat::kAuto, 10, 1455},
      {"pavilion_chair_sequence", DatasetFormat::kAuto, 102, 0},
  };
  for (const Expect& e : all) {
    SCOPED_TRACE(std::string(e.dir) + " " + DatasetFormatName(e.format));
    const Scene s = Load(root + "/" + e.dir, e.format);
    EXPECT_EQ(s.views.size(), e.views);
    EXPECT_EQ(s.points.size(), e.points);
    EXPECT_FALSE(s.source.empty());
    for (const View& v : s.views) {
      ASSERT_TRUE(fs::exists(v.image_path)) << v.image_path;
      const ImageSize sz = ReadImageSize(v.image_path);
      EXPECT_EQ(sz.width, v.camera.width) << v.image_path;
      EXPECT_EQ(sz.height, v.camera.height) << v.image_path;
    }
    if (!s.points.empty()) {
      EXPECT_LT(MedianReprojection(s, s), 0.5);
    }
  }
}

// The native camera files agree with the colmap_sift_gt models made from
// them (which state cx = K13 + 0.5): the tracks reproject through the native
// cameras with sub-pixel error, and the intrinsics agree exactly.
TEST(DatasetShared, NativeCamerasMatchColmapModels) {
  WILD_MVS_REQUIRE_SHARED(root, "datasets");
  for (const auto& [dir, fmt] :
       std::vector<std::pair<std::string, DatasetFormat>>{
           {"middlebury_templeSparseRing", DatasetFormat::kMiddlebury},
           {"middlebury_templeRing", DatasetFormat::kMiddlebury},
           {"middlebury_dinoSparseRing", DatasetFormat::kMiddlebury},
           {"strecha_fountain-P11", DatasetFormat::kStrecha},
           {"strecha_Herz-Jesus-P8", DatasetFormat::kStrecha}}) {
    SCOPED_TRACE(dir);
    const Scene native = Load(root + "/" + dir, fmt);
    const Scene colmap = Load(root + "/" + dir, DatasetFormat::kColmap);
    ASSERT_EQ(native.views.size(), colmap.views.size());
    for (const View& v : colmap.views) {
      const int i = native.FindView(v.name);
      ASSERT_GE(i, 0) << v.name;
      const Camera& a = native.views[i].camera;
      EXPECT_NEAR(a.fx, v.camera.fx, 1e-6);
      EXPECT_NEAR(a.cx, v.camera.cx, 1e-6);
      EXPECT_NEAR(a.cy, v.camera.cy, 1e-6);
      EXPECT_LT((a.Center() - v.camera.Center()).norm(),
                1e-5 * (1 + a.Center().norm()));
      EXPECT_EQ(native.views[i].image_path, v.image_path);
    }
    EXPECT_LT(MedianReprojection(native, colmap), 0.5);
  }
}

// Pavilion: P decomposed into K [R | t] reproduces P (with the +0.5 pixel
// shift), and the ground-truth curve points project into frame 1 as the
// staging notes say (94 %).
TEST(DatasetShared, PavilionProjectionMatrices) {
  WILD_MVS_REQUIRE_SHARED(root, "datasets/pavilion_chair_sequence");
  const Scene s = Load(root);
  // Three lightings per frame, same camera.
  const int a = s.FindView("midday/midday-640x-0001.png");
  const int b = s.FindView("night/night-640x-0001.png");
  ASSERT_GE(a, 0);
  ASSERT_GE(b, 0);
  EXPECT_LT((s.views[a].camera.P() - s.views[b].camera.P()).norm(), 1e-12);
  // Compare with the raw P of frame 1.
  std::ifstream pin(root + "/cameras/001.projmatrix");
  Eigen::Matrix<double, 3, 4> P;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 4; ++c) pin >> P(r, c);
  std::ifstream gin(root + "/gt_curves/gt-points.txt");
  int inside = 0, total = 0, behind = 0;
  double max_diff = 0;
  Eigen::Vector3d X;
  while (gin >> X.x() >> X.y() >> X.z()) {
    const Eigen::Vector3d h = P * X.homogeneous();
    const Eigen::Vector2d raw = h.hnormalized() + Eigen::Vector2d(0.5, 0.5);
    Eigen::Vector2d px;
    ++total;
    if (!s.views[a].camera.Project(X, &px)) {
      ++behind;
      continue;
    }
    max_diff = std::max(max_diff, (px - raw).norm());
    inside += s.views[a].camera.InImage(px);
  }
  ASSERT_GT(total, 10000);
  EXPECT_LT(max_diff, 0.05);  // a tiny skew in P is dropped
  EXPECT_LT(behind, total / 100) << behind << " of " << total;
  EXPECT_NEAR(double(inside) / total, 0.94, 0.02);
  // --images selects one lighting.
  DatasetOptions o;
  o.path = root;
  o.images_dir = root + "/images/midday";
  EXPECT_EQ(LoadDataset(o).views.size(), 34u);
}

// ------------------------------------------------------ layouts / overrides
void WriteImage(const std::string& path, int w, int h) {
  fs::create_directories(fs::path(path).parent_path());
  cv::imwrite(path, cv::Mat(h, w, CV_8UC3, cv::Scalar(10, 20, 30)));
}

Scene TinyScene() {
  Scene s;
  for (int i = 0; i < 2; ++i) {
    View v;
    v.name = "im" + std::to_string(i) + ".png";
    v.camera.width = 32;
    v.camera.height = 24;
    v.camera.fx = v.camera.fy = 30;
    v.camera.cx = 16;
    v.camera.cy = 12;
    v.camera.t = Eigen::Vector3d(-0.1 * i, 0, 0);
    s.views.push_back(v);
  }
  SparsePoint p;
  p.xyz = Eigen::Vector3d(0.1, 0.2, 2);
  for (int i = 0; i < 2; ++i) {
    Observation o;
    o.view = i;
    s.views[i].camera.Project(p.xyz, &o.xy);
    p.track.push_back(o);
  }
  s.points.push_back(p);
  return s;
}

TEST(Dataset, ColmapLayoutsAndOverrides) {
  const std::string d = testing::MakeTempDir("ds_layout");
  const Scene t = TinyScene();
  // DIR/sparse/0 + DIR/images
  WriteColmapText(t, d + "/a/sparse/0");
  WriteImage(d + "/a/images/im0.png", 32, 24);
  WriteImage(d + "/a/images/im1.png", 32, 24);
  Scene s = Load(d + "/a");
  EXPECT_EQ(s.views[1].image_path,
            (fs::path(d) / "a/images/im1.png").lexically_normal().string());
  EXPECT_NE(s.source.find("sparse/0"), std::string::npos) << s.source;
  // The model folder given as the dataset still finds DIR/images.
  EXPECT_EQ(Load(d + "/a/sparse/0").views[0].image_path,
            (fs::path(d) / "a/images/im0.png").lexically_normal().string());
  // DIR/sparse + images beside it.
  WriteColmapText(t, d + "/b/sparse");
  WriteImage(d + "/b/im0.png", 32, 24);
  WriteImage(d + "/b/im1.png", 32, 24);
  s = Load(d + "/b");
  EXPECT_EQ(s.views.size(), 2u);
  // Model files directly in DIR.
  WriteColmapText(t, d + "/c");
  WriteImage(d + "/c/images/im0.png", 32, 24);
  WriteImage(d + "/c/images/im1.png", 32, 24);
  EXPECT_EQ(Load(d + "/c").views.size(), 2u);
  // Overrides.
  DatasetOptions o;
  o.model_dir = d + "/a/sparse/0";
  o.images_dir = d + "/b";
  s = LoadDataset(o);
  EXPECT_EQ(s.views[0].image_path, (fs::path(d) / "b" / "im0.png").string());
  // Wrong image size: the error names the file.
  WriteImage(d + "/b/im1.png", 33, 24);
  try {
    LoadDataset(o);
    ADD_FAILURE();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("im1.png"), std::string::npos);
    EXPECT_NE(std::string(e.what()).find("33x24"), std::string::npos)
        << e.what();
  }
  // Missing image: auto-detection finds no folder; the error names it.
  fs::remove(d + "/a/images/im0.png");
  try {
    Load(d + "/a");
    ADD_FAILURE();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("im0.png"), std::string::npos)
        << e.what();
  }
  // Nothing there.
  fs::create_directories(d + "/empty");
  EXPECT_THROW(Load(d + "/empty"), Error);
  EXPECT_THROW(Load(d + "/nonexistent"), Error);
  EXPECT_THROW(ParseDatasetFormat("nvm"), Error);
  EXPECT_EQ(ParseDatasetFormat("bundler"), DatasetFormat::kBundler);
  fs::remove_all(d);
}

TEST(ImageSize, HeaderProbeMatchesDecoder) {
  const std::string d = testing::MakeTempDir("imsize");
  const cv::Mat img(37, 53, CV_8UC3, cv::Scalar(1, 2, 3));
  for (const char* ext : {".png", ".jpg", ".ppm", ".bmp", ".tif"}) {
    const std::string p = d + "/x" + ext;
    ASSERT_TRUE(cv::imwrite(p, img));
    const ImageSize s = ReadImageSize(p);
    EXPECT_EQ(s.width, 53) << ext;
    EXPECT_EQ(s.height, 37) << ext;
  }
  const cv::Mat g16(5, 7, CV_16U, cv::Scalar(1000));
  ASSERT_TRUE(cv::imwrite(d + "/g.png", g16));
  EXPECT_EQ(ReadImageSize(d + "/g.png").width, 7);
  std::ofstream(d + "/bad.png") << "not an image";
  EXPECT_THROW(ReadImageSize(d + "/bad.png"), Error);
  EXPECT_THROW(ReadImageSize(d + "/missing.png"), Error);
  fs::remove_all(d);
}

}  // namespace
}  // namespace wild_mvs
