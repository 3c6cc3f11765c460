// Copyright wild_mvs authors. COLMAP reader / writer tests.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <filesystem>
#include <fstream>
#include <opencv2/calib3d.hpp>
#include <random>
#include <sstream>

#include "test_paths.h"
#include "wild_mvs/core/error.h"
#include "wild_mvs/io/colmap.h"

namespace wild_mvs {
namespace {

namespace fs = std::filesystem;

std::string DataDir() { return testing::SourceDir() + "/test/data/io"; }

std::string ReadText(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}
void WriteText(const std::string& path, const std::string& s) {
  std::ofstream out(path, std::ios::binary);
  out << s;
}

// Expects ReadColmapModel(dir) to throw an Error whose message contains all
// of `parts`.
void ExpectError(const std::string& dir,
                 const std::vector<std::string>& parts) {
  try {
    ReadColmapModel(dir);
    ADD_FAILURE() << "no error for " << dir << " (expected '" << parts[0]
                  << "')";
  } catch (const Error& e) {
    const std::string msg = e.what();
    for (const std::string& p : parts)
      EXPECT_NE(msg.find(p), std::string::npos)
          << "message '" << msg << "' lacks '" << p << "'";
  }
}

// A scene of `nv` cameras on an arc looking at points near the origin, with
// exact observations.
Scene MakeScene(int nv, int np, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-0.5, 0.5);
  Scene s;
  s.source = "synthetic";
  for (int i = 0; i < nv; ++i) {
    View v;
    v.name = "img_" + std::to_string(i) + ".png";
    Camera& c = v.camera;
    c.width = 640;
    c.height = 480;
    c.fx = 500 + 10 * i;
    c.fy = 505 + 10 * i;
    c.cx = 320.25 + i;
    c.cy = 240.5 - i;
    const double a = 0.2 * (i - nv / 2.0);
    c.R = Eigen::AngleAxisd(a, Eigen::Vector3d::UnitY()).toRotationMatrix() *
          Eigen::AngleAxisd(0.05 * i, Eigen::Vector3d::UnitX())
              .toRotationMatrix();
    const Eigen::Vector3d centre(-4 * std::sin(a), 0.1 * i, -4 * std::cos(a));
    c.t = -c.R * centre;
    s.views.push_back(v);
  }
  for (int p = 0; p < np; ++p) {
    SparsePoint sp;
    sp.xyz = Eigen::Vector3d(u(rng), u(rng), u(rng));
    sp.rgb = Eigen::Vector3f(p % 256 / 255.0f, 0.5f, 1.0f);
    sp.error = 0.25;
    for (int i = 0; i < nv; ++i) {
      if ((p + i) % 3 == 0) continue;  // varied tracks
      Observation o;
      o.view = i;
      EXPECT_TRUE(s.views[i].camera.Project(sp.xyz, &o.xy));
      sp.track.push_back(o);
    }
    s.points.push_back(sp);
  }
  return s;
}

void ExpectSameScene(const Scene& a, const Scene& b, double px_tol) {
  ASSERT_EQ(a.views.size(), b.views.size());
  for (size_t i = 0; i < a.views.size(); ++i) {
    const Camera& ca = a.views[i].camera;
    const Camera& cb = b.views[i].camera;
    EXPECT_EQ(a.views[i].name, b.views[i].name);
    EXPECT_EQ(ca.width, cb.width);
    EXPECT_EQ(ca.height, cb.height);
    EXPECT_NEAR(ca.fx, cb.fx, 1e-9);
    EXPECT_NEAR(ca.fy, cb.fy, 1e-9);
    EXPECT_NEAR(ca.cx, cb.cx, 1e-9);
    EXPECT_NEAR(ca.cy, cb.cy, 1e-9);
    EXPECT_LT((ca.R - cb.R).norm(), 1e-12);
    EXPECT_LT((ca.t - cb.t).norm(), 1e-12);
  }
  ASSERT_EQ(a.points.size(), b.points.size());
  for (size_t p = 0; p < a.points.size(); ++p) {
    EXPECT_LT((a.points[p].xyz - b.points[p].xyz).norm(), 1e-12);
    ASSERT_EQ(a.points[p].track.size(), b.points[p].track.size());
    for (size_t k = 0; k < a.points[p].track.size(); ++k) {
      EXPECT_EQ(a.points[p].track[k].view, b.points[p].track[k].view);
      EXPECT_LT((a.points[p].track[k].xy - b.points[p].track[k].xy).norm(),
                px_tol);
    }
  }
}

TEST(ColmapText, RoundTripExact) {
  const Scene s = MakeScene(5, 200, 1);
  const std::string dir = testing::MakeTempDir("colmap_rt");
  WriteColmapText(s, dir);
  EXPECT_EQ(DetectColmapModel(dir), ColmapFormat::kText);
  const Scene r = ReadColmapModel(dir, "/imgs");
  ExpectSameScene(s, r, 1e-9);
  EXPECT_EQ(r.views[2].image_path, "/imgs/img_2.png");
  EXPECT_NEAR(r.points[7].rgb[0], 7 / 255.0f, 1e-6);
  // Reprojection of every observation is exact.
  for (const SparsePoint& p : r.points)
    for (const Observation& o : p.track) {
      Eigen::Vector2d px;
      ASSERT_TRUE(r.views[o.view].camera.Project(p.xyz, &px));
      EXPECT_LT((px - o.xy).norm(), 1e-6);
      EXPECT_EQ(o.scale, 0);
    }
  fs::remove_all(dir);
}

TEST(ColmapText, ReadsStaticSample) {
  const Scene s = ReadColmapText(DataDir() + "/colmap_text_good");
  ASSERT_EQ(s.views.size(), 3u);
  EXPECT_EQ(s.views[0].name, "a.png");
  EXPECT_EQ(s.views[1].distortion.model, Distortion::Model::kRadial);
  EXPECT_DOUBLE_EQ(s.views[1].distortion.k1, -0.1);
  EXPECT_DOUBLE_EQ(s.views[1].camera.fx, 55);
  EXPECT_DOUBLE_EQ(s.views[1].camera.cx, 31.5);
  EXPECT_EQ(s.views[2].distortion.model, Distortion::Model::kNone);
  ASSERT_EQ(s.points.size(), 2u);
  ASSERT_EQ(s.points[1].track.size(), 2u);
  EXPECT_EQ(s.points[1].track[0].view, 0);
  EXPECT_EQ(s.points[1].track[0].xy, Eigen::Vector2d(42, 24));
  // Observation (40, 22) in the distorted view b.png was undistorted:
  // distorting it again gives (40, 22).
  const Eigen::Vector2d u = s.points[1].track[1].xy;
  const double x = (u.x() - 31.5) / 55, y = (u.y() - 24.5) / 55;
  const double f = 1 - 0.1 * (x * x + y * y);
  EXPECT_NEAR(55 * x * f + 31.5, 40, 1e-6);
  EXPECT_NEAR(55 * y * f + 24.5, 22, 1e-6);
  EXPECT_GT((u - Eigen::Vector2d(40, 22)).norm(), 0.01);  // it did move
}

// Distorted observations (made with OpenCV's projectPoints, pixel centres
// shifted by 0.5) are undistorted back to the exact pinhole projection.
TEST(ColmapText, UndistortsObservationsOpenCVModel) {
  Scene s = MakeScene(3, 50, 2);
  const double k[4] = {-0.2, 0.05, 0.001, -0.002};
  const std::string dir = testing::MakeTempDir("colmap_dist");
  std::ostringstream cams, imgs, pts;
  cams.precision(17);
  imgs.precision(17);
  pts.precision(17);
  std::vector<std::vector<Eigen::Vector2d>> obs(3);
  std::vector<std::vector<std::pair<int, int>>> tracks(s.points.size());
  for (size_t p = 0; p < s.points.size(); ++p)
    for (const Observation& o : s.points[p].track) {
      const Camera& c = s.views[o.view].camera;
      cv::Mat K = (cv::Mat_<double>(3, 3) << c.fx, 0, c.cx - 0.5, 0, c.fy,
                   c.cy - 0.5, 0, 0, 1);
      cv::Mat D = (cv::Mat_<double>(1, 4) << k[0], k[1], k[2], k[3]);
      const Eigen::Vector3d xc = c.WorldToCamera(s.points[p].xyz);
      std::vector<cv::Point3d> X{{xc.x(), xc.y(), xc.z()}};
      std::vector<cv::Point2d> x;
      cv::projectPoints(X, cv::Vec3d(0, 0, 0), cv::Vec3d(0, 0, 0), K, D, x);
      tracks[p].emplace_back(o.view + 1, obs[o.view].size());
      obs[o.view].emplace_back(x[0].x + 0.5, x[0].y + 0.5);
    }
  for (int i = 0; i < 3; ++i) {
    const Camera& c = s.views[i].camera;
    cams << i + 1 << " OPENCV " << c.width << " " << c.height << " " << c.fx
         << " " << c.fy << " " << c.cx << " " << c.cy << " " << k[0] << " "
         << k[1] << " " << k[2] << " " << k[3] << "\n";
    const Eigen::Quaterniond q(c.R);
    imgs << i + 1 << " " << q.w() << " " << q.x() << " " << q.y() << " "
         << q.z() << " " << c.t.x() << " " << c.t.y() << " " << c.t.z() << " "
         << i + 1 << " " << s.views[i].name << "\n";
    for (const auto& o : obs[i]) imgs << o.x() << " " << o.y() << " -1 ";
    imgs << "\n";
  }
  for (size_t p = 0; p < s.points.size(); ++p) {
    pts << p + 1 << " " << s.points[p].xyz.x() << " " << s.points[p].xyz.y()
        << " " << s.points[p].xyz.z() << " 1 2 3 0.1";
    for (auto [i, j] : tracks[p]) pts << " " << i << " " << j;
    pts << "\n";
  }
  WriteText(dir + "/cameras.txt", cams.str());
  WriteText(dir + "/images.txt", imgs.str());
  WriteText(dir + "/points3D.txt", pts.str());
  const Scene r = ReadColmapModel(dir);
  EXPECT_EQ(r.views[0].distortion.model, Distortion::Model::kOpenCV);
  EXPECT_DOUBLE_EQ(r.views[0].distortion.p2, k[3]);
  ExpectSameScene(s, r, 1e-5);
  // And the writer re-distorts: write + read gives the same again.
  const std::string dir2 = testing::MakeTempDir("colmap_dist2");
  WriteColmapText(r, dir2);
  const Scene r2 = ReadColmapModel(dir2);
  ExpectSameScene(s, r2, 1e-5);
  EXPECT_EQ(r2.views[1].distortion.model, Distortion::Model::kOpenCV);
  fs::remove_all(dir);
  fs::remove_all(dir2);
}

// ---------------------------------------------------------------- binary
template <typename T>
void Put(std::string* s, T v) {
  s->append(reinterpret_cast<const char*>(&v), sizeof(T));
}

void WriteBinary(const Scene& s, const std::string& dir) {
  std::string cams, imgs, pts;
  Put<uint64_t>(&cams, s.views.size());
  for (size_t i = 0; i < s.views.size(); ++i) {
    const Camera& c = s.views[i].camera;
    Put<uint32_t>(&cams, i + 1);
    Put<int32_t>(&cams, 1);  // PINHOLE
    Put<uint64_t>(&cams, c.width);
    Put<uint64_t>(&cams, c.height);
    for (double v : {c.fx, c.fy, c.cx, c.cy}) Put<double>(&cams, v);
  }
  std::vector<std::vector<std::pair<Eigen::Vector2d, uint64_t>>> obs(
      s.views.size());
  std::vector<std::vector<std::pair<uint32_t, uint32_t>>> tracks(
      s.points.size());
  for (size_t p = 0; p < s.points.size(); ++p)
    for (const Observation& o : s.points[p].track) {
      tracks[p].emplace_back(o.view + 1, obs[o.view].size());
      obs[o.view].emplace_back(o.xy, p + 1);
    }
  Put<uint64_t>(&imgs, s.views.size());
  for (size_t i = 0; i < s.views.size(); ++i) {
    const Camera& c = s.views[i].camera;
    const Eigen::Quaterniond q(c.R);
    Put<uint32_t>(&imgs, i + 1);
    for (double v : {q.w(), q.x(), q.y(), q.z(), c.t.x(), c.t.y(), c.t.z()})
      Put<double>(&imgs, v);
    Put<uint32_t>(&imgs, i + 1);
    imgs += s.views[i].name;
    imgs.push_back('\0');
    Put<uint64_t>(&imgs, obs[i].size() + 1);
    for (const auto& [xy, id] : obs[i]) {
      Put<double>(&imgs, xy.x());
      Put<double>(&imgs, xy.y());
      Put<uint64_t>(&imgs, id);
    }
    Put<double>(&imgs, 1.0);  // an untriangulated feature
    Put<double>(&imgs, 2.0);
    Put<uint64_t>(&imgs, ~uint64_t(0));
  }
  Put<uint64_t>(&pts, s.points.size());
  for (size_t p = 0; p < s.points.size(); ++p) {
    Put<uint64_t>(&pts, p + 1);
    for (int k = 0; k < 3; ++k) Put<double>(&pts, s.points[p].xyz[k]);
    for (int k = 0; k < 3; ++k) Put<uint8_t>(&pts, 100 + k);
    Put<double>(&pts, s.points[p].error);
    Put<uint64_t>(&pts, tracks[p].size());
    for (auto [i, j] : tracks[p]) {
      Put<uint32_t>(&pts, i);
      Put<uint32_t>(&pts, j);
    }
  }
  WriteText(dir + "/cameras.bin", cams);
  WriteText(dir + "/images.bin", imgs);
  WriteText(dir + "/points3D.bin", pts);
}

TEST(ColmapBinary, ReadsWhatTextReads) {
  const Scene s = MakeScene(4, 100, 3);
  const std::string dir = testing::MakeTempDir("colmap_bin");
  WriteBinary(s, dir);
  EXPECT_EQ(DetectColmapModel(dir), ColmapFormat::kBinary);
  const Scene r = ReadColmapModel(dir);
  ExpectSameScene(s, r, 1e-12);
  EXPECT_NEAR(r.points[0].rgb[2], 102 / 255.0f, 1e-6);
  fs::remove_all(dir);
}

TEST(ColmapBinary, TruncatedFilesAlwaysGiveErrors) {
  const Scene s = MakeScene(3, 20, 4);
  const std::string dir = testing::MakeTempDir("colmap_trunc");
  WriteBinary(s, dir);
  for (const char* file : {"cameras.bin", "images.bin", "points3D.bin"}) {
    const std::string path = dir + "/" + file;
    const std::string full = ReadText(path);
    // Every truncation length in the first 200 bytes, then a stride.
    for (size_t len = 0; len < full.size(); len += (len < 120 ? 1 : 13)) {
      WriteText(path, full.substr(0, len));
      try {
        ReadColmapModel(dir);
        ADD_FAILURE() << file << " truncated to " << len << " bytes: no error";
      } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find(file), std::string::npos)
            << e.what();
      }
    }
    WriteText(path, full + "x");  // trailing garbage
    ExpectError(dir, {file, "unexpected bytes"});
    WriteText(path, full);
  }
  ReadColmapModel(dir);  // intact again
  fs::remove_all(dir);
}

TEST(ColmapBinary, CorruptCountsDoNotAllocate) {
  const Scene s = MakeScene(3, 20, 5);
  const std::string dir = testing::MakeTempDir("colmap_count");
  WriteBinary(s, dir);
  for (const char* file : {"cameras.bin", "images.bin", "points3D.bin"}) {
    const std::string path = dir + "/" + file;
    const std::string full = ReadText(path);
    std::string bad = full;
    const uint64_t huge = uint64_t(1) << 60;
    std::memcpy(&bad[0], &huge, 8);
    WriteText(path, bad);
    ExpectError(dir, {file, "corrupt or truncated"});
    WriteText(path, full);
  }
  // A corrupt track length inside points3D.bin (first point's track length
  // sits after id, xyz, rgb, error: 8 + 8 + 24 + 3 + 8 bytes).
  const std::string path = dir + "/points3D.bin";
  std::string bad = ReadText(path);
  const uint64_t huge = ~uint64_t(0) - 5;
  std::memcpy(&bad[8 + 8 + 24 + 3 + 8], &huge, 8);
  WriteText(path, bad);
  ExpectError(dir, {"points3D.bin", "track length"});
  fs::remove_all(dir);
}

TEST(ColmapBinary, RejectsFisheyeModel) {
  const Scene s = MakeScene(2, 5, 6);
  const std::string dir = testing::MakeTempDir("colmap_fish");
  WriteBinary(s, dir);
  std::string cams = ReadText(dir + "/cameras.bin");
  const int32_t fisheye = 5;  // OPENCV_FISHEYE (8 params: we wrote 4)
  std::memcpy(&cams[8 + 4], &fisheye, 4);
  WriteText(dir + "/cameras.bin", cams);
  ExpectError(dir, {"cameras.bin"});
  fs::remove_all(dir);
}

// ---------------------------------------------------------------- malformed
struct Case {
  const char* file;
  int line;             // 1-based line to replace (of the good sample)
  const char* content;  // replacement ("" = delete the line)
  std::vector<std::string> expect;
};

TEST(ColmapText, MalformedInputsNameFileLineAndProblem) {
  const std::string good = DataDir() + "/colmap_text_good";
  const std::vector<Case> cases = {
      {"cameras.txt",
       3,
       "1 PINHOLE 64 48 50 52 32",
       {"cameras.txt line 3", "truncated"}},
      {"cameras.txt",
       3,
       "1 PINHOLE 64 48 nan 52 32 24",
       {"cameras.txt line 3", "not a finite"}},
      {"cameras.txt",
       3,
       "1 PINHOLE 64 48 inf 52 32 24",
       {"cameras.txt line 3", "not a finite"}},
      {"cameras.txt",
       3,
       "1 PINHOLE 64 48 0 52 32 24",
       {"cameras.txt line 3", "focal length"}},
      {"cameras.txt",
       3,
       "1 PINHOLE 64 48 -50 52 32 24",
       {"cameras.txt line 3", "focal length"}},
      {"cameras.txt",
       3,
       "1 PINHOLE 0 48 50 52 32 24",
       {"cameras.txt line 3", "image size"}},
      {"cameras.txt",
       3,
       "1 OPENCV_FISHEYE 64 48 50 52 32 24 0 0 0 0",
       {"cameras.txt line 3", "fisheye"}},
      {"cameras.txt",
       3,
       "1 FULL_OPENCV 64 48 50 52 32 24 0 0 0 0 0 0 0 0",
       {"cameras.txt line 3", "not supported"}},
      {"cameras.txt",
       3,
       "1 BROWN 64 48 50 52 32 24",
       {"cameras.txt line 3", "unknown camera model 'BROWN'"}},
      {"cameras.txt",
       4,
       "1 PINHOLE 64 48 50 52 32 24",
       {"cameras.txt line 4", "duplicate CAMERA_ID"}},
      {"images.txt",
       4,
       "1 1 0 0 0 0 0 0 1",
       {"images.txt line 4", "truncated"}},
      {"images.txt",
       4,
       "1 1 0 0 0 0 NaN 0 1 a.png",
       {"images.txt line 4", "not a finite"}},
      {"images.txt",
       4,
       "1 2 0 0 0 0 0 0 1 a.png",
       {"images.txt line 4", "not a rotation"}},
      {"images.txt",
       4,
       "1 1 0 0 0 0 0 0 7 a.png",
       {"images.txt line 4", "CAMERA_ID 7"}},
      {"images.txt",
       5,
       "32 24 1 42 24",
       {"images.txt line 5", "multiple of 3"}},
      {"images.txt",
       6,
       "2 0.99500416527802582 0 0.099833416646828155 0 -0.5 0 0.1 2 a.png",
       {"images.txt line 6", "duplicate image name 'a.png'"}},
      {"images.txt",
       8,
       "1 1 0 0 0 -1 0 0 1 c.png",
       {"images.txt line 8", "duplicate IMAGE_ID 1"}},
      {"points3D.txt",
       3,
       "1 0 0 5 255 0 0 0.5 1 0 9 0",
       {"points3D.txt line 3", "IMAGE_ID 9"}},
      {"points3D.txt",
       3,
       "1 0 0 5 255 0 0 0.5 1 0 2 5",
       {"points3D.txt line 3", "POINT2D_IDX 5"}},
      {"points3D.txt",
       3,
       "1 0 0 5 255 0 0 0.5 1 0 2",
       {"points3D.txt line 3", "odd number"}},
      {"points3D.txt",
       3,
       "1 0 0 inf 255 0 0 0.5 1 0 2 0",
       {"points3D.txt line 3", "not a finite"}},
      {"points3D.txt",
       3,
       "1 0 0 5 256 0 0 0.5 1 0 2 0",
       {"points3D.txt line 3", "outside 0..255"}},
      {"points3D.txt",
       4,
       "1 1 0 5 0 255 0 0.25 1 1 2 1",
       {"points3D.txt line 4", "duplicate POINT3D_ID"}},
      {"points3D.txt", 3, "1 0 0", {"points3D.txt line 3", "truncated"}},
  };
  const std::string dir = testing::MakeTempDir("colmap_bad");
  for (const Case& c : cases) {
    for (const char* f : {"cameras.txt", "images.txt", "points3D.txt"})
      fs::copy_file(good + "/" + f, dir + "/" + f,
                    fs::copy_options::overwrite_existing);
    std::istringstream in(ReadText(good + "/" + c.file));
    std::string line, out;
    for (int n = 1; std::getline(in, line); ++n)
      out += (n == c.line ? std::string(c.content) : line) + "\n";
    WriteText(dir + "/" + c.file, out);
    SCOPED_TRACE(std::string(c.file) + ": " + c.content);
    ExpectError(dir, c.expect);
  }
  fs::remove_all(dir);
}

TEST(ColmapText, EmptyModelAndMissingFiles) {
  const std::string dir = testing::MakeTempDir("colmap_empty");
  ExpectError(dir, {"no COLMAP model"});
  WriteText(dir + "/cameras.txt", "# nothing\n");
  WriteText(dir + "/images.txt", "# nothing\n");
  ExpectError(dir, {"cameras.txt", "empty model"});
  WriteText(dir + "/cameras.txt", "1 PINHOLE 10 10 5 5 5 5\n");
  ExpectError(dir, {"images.txt", "empty model"});
  // Cameras + images without points3D.txt is a valid model without points.
  WriteText(dir + "/images.txt", "1 1 0 0 0 0 0 0 1 x.png\n\n");
  const Scene s = ReadColmapModel(dir);
  EXPECT_EQ(s.views.size(), 1u);
  EXPECT_TRUE(s.points.empty());
  fs::remove_all(dir);
}

// ---------------------------------------------------------------- shared
double MedianReprojectionError(const Scene& s) {
  std::vector<double> err;
  for (const SparsePoint& p : s.points)
    for (const Observation& o : p.track) {
      Eigen::Vector2d px;
      if (!s.views[o.view].camera.Project(p.xyz, &px)) {
        err.push_back(1e9);
        continue;
      }
      err.push_back((px - o.xy).norm());
    }
  if (err.empty()) return 1e9;
  std::nth_element(err.begin(), err.begin() + err.size() / 2, err.end());
  return err[err.size() / 2];
}

TEST(ColmapShared, SiftGtModels) {
  WILD_MVS_REQUIRE_SHARED(root, "datasets");
  struct Expect {
    const char* dir;
    size_t views, points, observations;
  };
  for (const Expect& e : std::vector<Expect>{
           {"middlebury_templeSparseRing/colmap_sift_gt", 16, 3544, 9332},
           {"middlebury_dinoSparseRing/colmap_sift_gt", 16, 1348, 3288},
           {"middlebury_templeRing/colmap_sift_gt", 47, 3822, 12048},
           {"strecha_Herz-Jesus-P8/colmap_sift_gt", 8, 12073, 36744},
           {"strecha_fountain-P11/colmap_sift_gt", 11, 17558, 63384},
           {"internet_sacre_coeur/colmap_estimated/sparse_pinhole_txt", 10,
            1455, 0}}) {
    SCOPED_TRACE(e.dir);
    const Scene s = ReadColmapModel(root + "/" + e.dir);
    EXPECT_EQ(s.views.size(), e.views);
    EXPECT_EQ(s.points.size(), e.points);
    size_t obs = 0;
    for (const SparsePoint& p : s.points) obs += p.track.size();
    if (e.observations) {
      EXPECT_EQ(obs, e.observations);
    }
    EXPECT_LT(MedianReprojectionError(s), 0.5);
  }
}

}  // namespace
}  // namespace wild_mvs
