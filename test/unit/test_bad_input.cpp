// Copyright wild_mvs authors. The README's bad-input table, library level:
// each row has a test here that feeds the bad input to the library function
// the tools call and checks what the user gets (an Error naming the file /
// line and the problem, nothing half-written, earlier results untouched).
// The tool-level rows (exit codes, config files) are in test/cli/.
#include <gtest/gtest.h>
#include <sys/resource.h>

#include <csignal>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <opencv2/imgcodecs.hpp>
#include <regex>
#include <sstream>
#include <string>

#include "synthetic_scene.h"
#include "test_paths.h"
#include "wild_mvs/cli/scene_setup.h"
#include "wild_mvs/core/camera.h"
#include "wild_mvs/core/error.h"
#include "wild_mvs/core/image.h"
#include "wild_mvs/core/reconstruct_view.h"
#include "wild_mvs/core/scene.h"
#include "wild_mvs/io/atomic_file.h"
#include "wild_mvs/io/colmap.h"
#include "wild_mvs/io/image_files.h"
#include "wild_mvs/io/pfm.h"

namespace fs = std::filesystem;

namespace wild_mvs {
namespace {

void WriteText(const std::string& path, const std::string& s) {
  std::ofstream f(path, std::ios::binary);
  f << s;
  ASSERT_TRUE(f.good()) << path;
}

std::string ReadText(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  std::stringstream ss;
  ss << f.rdbuf();
  return ss.str();
}

// Runs fn, expects wild_mvs::Error whose message matches every regex.
template <typename F>
void ExpectError(F fn, const std::vector<std::string>& patterns) {
  try {
    fn();
  } catch (const Error& e) {
    std::cout << "  -> " << e.what() << "\n";  // what the user reads
    for (const std::string& p : patterns)
      EXPECT_TRUE(std::regex_search(std::string(e.what()), std::regex(p)))
          << "message '" << e.what() << "' does not match '" << p << "'";
    return;
  } catch (const std::exception& e) {
    ADD_FAILURE() << "not a wild_mvs::Error: " << e.what();
    return;
  }
  ADD_FAILURE() << "no error thrown";
}

// Files in dir (names only), to check nothing half-written stays behind.
std::vector<std::string> ListDir(const std::string& dir) {
  std::vector<std::string> names;
  for (const auto& e : fs::directory_iterator(dir))
    names.push_back(e.path().filename().string());
  std::sort(names.begin(), names.end());
  return names;
}

View MakeView(const std::string& dir, int w, int h) {
  View v;
  v.name = "a.png";
  v.image_path = dir + "/a.png";
  v.camera.fx = v.camera.fy = 100;
  v.camera.cx = w / 2.0;
  v.camera.cy = h / 2.0;
  v.camera.width = w;
  v.camera.height = h;
  return v;
}

cv::Mat Pattern(int w, int h) {
  cv::Mat m(h, w, CV_8UC3);
  for (int r = 0; r < h; ++r)
    for (int c = 0; c < w; ++c)
      m.at<cv::Vec3b>(r, c) =
          cv::Vec3b(r * 5 % 256, c * 3 % 256, (r + c) % 256);
  return m;
}

// A valid two-image COLMAP text model; tests replace one file.
struct Model {
  std::string dir;
  std::string cameras = "1 PINHOLE 80 60 100 100 40 30\n";
  std::string images =
      "1 1 0 0 0 0 0 0 1 a.png\n10 20 1 30 40 -1\n"
      "2 1 0 0 0 -1 0 0 1 b.png\n12 20 1\n";
  std::string points = "1 0.1 0.2 3 255 0 0 0.5 1 0 2 0\n";
  void Write() const {
    WriteText(dir + "/cameras.txt", cameras);
    WriteText(dir + "/images.txt", images);
    WriteText(dir + "/points3D.txt", points);
  }
};

class BadInput : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = testing::MakeTempDir("bad_input");
    model_.dir = dir_;
  }
  void TearDown() override { fs::remove_all(dir_); }
  std::string dir_;
  Model model_;
};

TEST_F(BadInput, GoodModelReads) {  // the baseline the rows below break
  model_.Write();
  const Scene s = ReadColmapText(dir_);
  ASSERT_EQ(s.views.size(), 2u);
  ASSERT_EQ(s.points.size(), 1u);
  EXPECT_EQ(s.points[0].track.size(), 2u);
}

// --- images ------------------------------------------------------------------
TEST_F(BadInput, CorruptImageFile) {
  const View v = MakeView(dir_, 80, 60);
  WriteText(v.image_path, "this is not a PNG file at all");
  ExpectError([&] { LoadViewImage(v, ImageOptions()); },
              {"a\\.png: cannot read image"});
}

TEST_F(BadInput, TruncatedImageFile) {
  const View v = MakeView(dir_, 80, 60);
  ASSERT_TRUE(cv::imwrite(v.image_path, Pattern(80, 60)));
  const std::string bytes = ReadText(v.image_path);
  WriteText(v.image_path, bytes.substr(0, bytes.size() / 2));
  ExpectError([&] { LoadViewImage(v, ImageOptions()); },
              {"a\\.png: cannot read image"});
}

TEST_F(BadInput, MissingImageFile) {
  const View v = MakeView(dir_, 80, 60);
  ExpectError([&] { LoadViewImage(v, ImageOptions()); },
              {"a\\.png: cannot read image"});
}

TEST_F(BadInput, ImageSizeDiffersFromCamera) {
  const View v = MakeView(dir_, 80, 60);
  ASSERT_TRUE(cv::imwrite(v.image_path, Pattern(64, 48)));
  ExpectError([&] { LoadViewImage(v, ImageOptions()); },
              {"a\\.png: image is 64x48 but its camera says 80x60"});
}

TEST_F(BadInput, MaskOfWrongSize) {
  View v = MakeView(dir_, 80, 60);
  v.mask_path = dir_ + "/a_mask.png";
  ASSERT_TRUE(
      cv::imwrite(v.mask_path, cv::Mat(30, 40, CV_8U, cv::Scalar(255))));
  ExpectError([&] { LoadViewMask(v); },
              {"a_mask\\.png: mask is 40x30 but image 'a\\.png' is 80x60"});
}

// --- cameras
// -------------------------------------------------------------------
TEST_F(BadInput, ZeroNanInfFocalLength) {
  for (const char* f : {"0", "-100", "nan", "inf", "1e999"}) {
    model_.cameras =
        std::string("# comment\n1 PINHOLE 80 60 ") + f + " 100 40 30\n";
    model_.Write();
    ExpectError([&] { ReadColmapText(dir_); }, {"cameras\\.txt line 2"});
  }
}

TEST_F(BadInput, NonOrthonormalRotation) {
  // COLMAP stores quaternions: one far from unit norm is refused.
  model_.images = "1 2 0 0 0 0 0 0 1 a.png\n\n";
  model_.Write();
  ExpectError([&] { ReadColmapText(dir_); },
              {"images\\.txt line 1", "quaternion"});
  // Rotation matrices (Middlebury, Strecha, ROS) go through Camera::Validate.
  Camera c = MakeView(dir_, 80, 60).camera;
  c.R(0, 1) = 0.3;
  ExpectError([&] { c.Validate("templeSR_par.txt line 3"); },
              {"templeSR_par\\.txt line 3"});
  c.R = -Eigen::Matrix3d::Identity();  // a reflection
  ExpectError([&] { c.Validate("view 7"); }, {"view 7"});
}

TEST_F(BadInput, UnsupportedCameraModel) {
  model_.cameras = "1 OPENCV_FISHEYE 80 60 100 100 40 30 0 0 0 0\n";
  model_.Write();
  ExpectError([&] { ReadColmapText(dir_); },
              {"cameras\\.txt line 1", "fisheye"});
}

// --- model structure -------------------------------------------------------
TEST_F(BadInput, DuplicateImageNames) {
  model_.images = "1 1 0 0 0 0 0 0 1 a.png\n\n2 1 0 0 0 1 0 0 1 a.png\n\n";
  model_.points = "";
  model_.Write();
  ExpectError([&] { ReadColmapText(dir_); },
              {"images\\.txt line 3", "duplicate image name 'a\\.png'"});
  // In-memory scenes (ROS keyframes, tests) are checked by Scene::Validate.
  Scene s;
  s.views = {MakeView(dir_, 80, 60), MakeView(dir_, 80, 60)};
  ExpectError([&] { s.Validate(); }, {"a\\.png"});
}

TEST_F(BadInput, TrackPointsAtMissingImage) {
  model_.points = "1 0.1 0.2 3 255 0 0 0.5 1 0 7 0\n";
  model_.Write();
  ExpectError([&] { ReadColmapText(dir_); }, {"points3D\\.txt line 1", "7"});
  Scene s;
  s.views = {MakeView(dir_, 80, 60)};
  SparsePoint p;
  p.track.push_back({3, {1, 1}, 0});
  s.points.push_back(p);
  ExpectError([&] { s.Validate(); }, {"3"});
}

TEST_F(BadInput, TrackPointsAtMissingObservation) {
  model_.points = "1 0.1 0.2 3 255 0 0 0.5 1 0 2 5\n";
  model_.Write();
  ExpectError([&] { ReadColmapText(dir_); }, {"points3D\\.txt line 1"});
}

TEST_F(BadInput, EmptyModel) {
  model_.cameras = "# no cameras\n";
  model_.images = "";
  model_.points = "";
  model_.Write();
  ExpectError([&] { ReadColmapText(dir_); }, {"empty model"});
  ExpectError([&] { ReadColmapModel(dir_ + "/nothing_here"); },
              {"nothing_here"});
}

TEST_F(BadInput, ModelWithoutSparsePoints) {
  // Not an error for the reader: cameras + poses only. The tool computes
  // sparse points first (see the README table).
  model_.images = "1 1 0 0 0 0 0 0 1 a.png\n\n2 1 0 0 0 -1 0 0 1 b.png\n\n";
  model_.Write();
  fs::remove(dir_ + "/points3D.txt");
  const Scene s = ReadColmapText(dir_);
  EXPECT_EQ(s.views.size(), 2u);
  EXPECT_TRUE(s.points.empty());
}

TEST_F(BadInput, NonFiniteSparsePoint) {
  model_.points = "1 nan 0.2 3 255 0 0 0.5 1 0 2 0\n";
  model_.Write();
  ExpectError([&] { ReadColmapText(dir_); }, {"points3D\\.txt line 1"});
}

TEST_F(BadInput, TruncatedTextLine) {
  model_.images = "1 1 0 0 0 0 0 0\n\n";
  model_.Write();
  ExpectError([&] { ReadColmapText(dir_); }, {"images\\.txt line 1"});
}

TEST_F(BadInput, TruncatedOrCorruptBinaryModel) {
  // A count field claiming 2^60 cameras in a 12-byte file: refused before
  // anything is allocated.
  std::string bytes(8, '\0');
  bytes[7] = 0x10;
  bytes += "abcd";
  WriteText(dir_ + "/cameras.bin", bytes);
  WriteText(dir_ + "/images.bin", std::string(8, '\0'));
  ExpectError([&] { ReadColmapBinary(dir_); }, {"cameras\\.bin", "byte"});
}

// --- geometry the algorithm cannot use ---------------------------------
TEST_F(BadInput, AllViewsFromOnePosition) {
  // Pure rotation / one tripod position: no parallax anywhere. No crash and
  // no invented depth: every view gets an empty depth map and the report
  // (log/<view>.json) says why.
  testing::SyntheticSpec spec = testing::SlantedPlaneSpec(20, 4);
  spec.width = 64;
  spec.height = 48;
  spec.focal = 60;
  spec.num_sparse_points = 60;
  spec.supersample = 1;
  for (Eigen::Vector3d& c : spec.camera_centers) c = spec.camera_centers[0];
  const testing::SyntheticScene s = testing::Render(spec);
  ImageCache cache(s.Loader(), 64);
  for (int ref = 0; ref < 2; ++ref) {
    ViewReport report;
    const DepthMap dm =
        ReconstructView(s.scene, ref, cache, MvsOptions(), nullptr, &report);
    EXPECT_EQ(dm.CountValid(), 0) << "view " << ref;
    ASSERT_FALSE(report.fallbacks.empty());
    bool said_why = false;
    for (const std::string& f : report.fallbacks) {
      std::cout << "  -> " << f << "\n";
      said_why = said_why || f.find("0 neighbours") != std::string::npos ||
                 f.find("no usable neighbour") != std::string::npos;
    }
    EXPECT_TRUE(said_why);
  }
}

TEST_F(BadInput, ImageTooLargeIsDownscaledWithItsCamera) {
  // --max-image-size (image.max_image_size): the camera is scaled and the
  // image downscaled at load; the tool prints how many views were scaled.
  Scene scene;
  scene.views = {MakeView(dir_, 200, 100)};
  ASSERT_TRUE(cv::imwrite(scene.views[0].image_path, Pattern(200, 100)));
  EXPECT_EQ(cli::LimitImageSize(&scene, 50), 1);
  const View& v = scene.views[0];
  EXPECT_EQ(v.camera.width, 50);
  EXPECT_EQ(v.camera.height, 25);
  EXPECT_NEAR(v.camera.fx, 25.0, 1e-9);
  EXPECT_EQ(v.file_width, 200);
  const cv::Mat img = LoadViewImage(v, ImageOptions());
  EXPECT_EQ(img.cols, 50);
  EXPECT_EQ(img.rows, 25);
  cli::LimitImageSize(&scene, 50);  // idempotent
  EXPECT_EQ(scene.views[0].camera.width, 50);
  EXPECT_EQ(scene.views[0].camera.height, 25);
}

// --- depth maps ------------------------------------------------------------
TEST_F(BadInput, TruncatedOrCorruptPfm) {
  const std::string p = dir_ + "/d.pfm";
  WriteText(p, "Pf\n4 3\n-1\n" + std::string(20, '\0'));  // needs 48 bytes
  ExpectError([&] { ReadPfm(p); }, {"d\\.pfm"});
  WriteText(p, "Pf\n-4 3\n-1\n");
  ExpectError([&] { ReadPfm(p); }, {"d\\.pfm"});
  WriteText(p, "P6\n4 3\n255\n");
  ExpectError([&] { ReadPfm(p); }, {"d\\.pfm"});
}

// --- outputs ---------------------------------------------------------------
TEST_F(BadInput, UnwritableOutputFolder) {
  // A parent that is a file cannot become a folder (works as root, too).
  WriteText(dir_ + "/blocker", "x");
  ExpectError(
      [&] {
        WriteFileAtomically(dir_ + "/blocker/out/fused.ply",
                            [](std::ostream& os) { os << "data"; });
      },
      {"blocker/out/fused\\.ply"});
  EXPECT_EQ(ListDir(dir_), std::vector<std::string>{"blocker"});
  EXPECT_EQ(ReadText(dir_ + "/blocker"), "x");
}

TEST_F(BadInput, FullDiskWhileWriting) {
  // The file-size limit makes write() fail with EFBIG exactly like a full
  // disk fails with ENOSPC: mid-file, after some bytes went out.
  const std::string path = dir_ + "/fused.ply";
  WriteText(path, "earlier result");
  struct rlimit old;
  ASSERT_EQ(getrlimit(RLIMIT_FSIZE, &old), 0);
  auto old_handler = std::signal(SIGXFSZ, SIG_IGN);
  struct rlimit lim = old;
  lim.rlim_cur = 4096;
  ASSERT_EQ(setrlimit(RLIMIT_FSIZE, &lim), 0);
  bool threw = false;
  std::string what;
  try {
    WriteFileAtomically(path, [](std::ostream& os) {
      const std::string block(1000, 'x');
      for (int i = 0; i < 100; ++i) os << block;  // 100 KB > 4 KB
    });
  } catch (const Error& e) {
    threw = true;
    what = e.what();
  }
  setrlimit(RLIMIT_FSIZE, &old);
  std::signal(SIGXFSZ, old_handler);
  std::cout << "  -> " << what << "\n";
  EXPECT_TRUE(threw);
  EXPECT_NE(what.find("fused.ply"), std::string::npos) << what;
  EXPECT_NE(what.find("File too large"), std::string::npos) << what;
  EXPECT_EQ(ReadText(path), "earlier result");                      // untouched
  EXPECT_EQ(ListDir(dir_), std::vector<std::string>{"fused.ply"});  // no tmp
}

TEST_F(BadInput, FailedProducerLeavesEarlierResult) {
  const std::string path = dir_ + "/depth.png";
  WriteText(path, "earlier result");
  ExpectError(
      [&] {
        ProduceFileAtomically(path, [](const std::string& tmp) {
          std::ofstream(tmp) << "half";
          return false;  // e.g. cv::imwrite failed
        });
      },
      {"depth\\.png: cannot write$"});  // no stale errno text
  EXPECT_EQ(ReadText(path), "earlier result");
  EXPECT_EQ(ListDir(dir_), std::vector<std::string>{"depth.png"});
}

}  // namespace
}  // namespace wild_mvs
