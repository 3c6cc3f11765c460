// Copyright wild_mvs authors. Cameras made the way the world makes them:
// fx != fy, an off-centre principal point and radial / tangential lens
// distortion. Rendered scenes (images rendered WITH the distortion, exact
// ground-truth depth of the undistorted camera) are written as datasets in
// COLMAP text (OPENCV and SIMPLE_RADIAL models), COLMAP binary (OPENCV) and
// Bundler (f k1 k2) formats; LoadDataset reads them (observations
// undistorted), LoadViewImage undistorts the images at load, and
// ReconstructView's depth map of one view is compared with the ground truth.
// A control reconstructs from the same files with the distortion ignored,
// which must be clearly worse (so the test sees undistortion at work).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>
#include <string>
#include <vector>

#include "synthetic_lens.h"
#include "synthetic_scene.h"
#include "test_paths.h"
#include "wild_mvs/core/image.h"
#include "wild_mvs/core/reconstruct_view.h"
#include "wild_mvs/core/thread_pool.h"
#include "wild_mvs/io/dataset.h"

namespace wild_mvs {
namespace {

namespace fs = std::filesystem;
using testing::SyntheticLens;
using testing::SyntheticScene;
using testing::SyntheticSpec;

constexpr int kRef = 3;

SyntheticSpec BaseSpec() {
  // Constant light, no occluder, 8 cameras 15 degrees apart.
  SyntheticSpec spec = testing::ClutteredSceneSpec(false, false, 105);
  spec.width = 160;
  spec.height = 120;
  spec.focal = 150;
  spec.num_sparse_points = 200;
  return spec;
}

// The distorted pixel of pinhole pixel px (OpenCV model on normalised
// coordinates; what a camera's lens does).
Eigen::Vector2d Distort(const Camera& c, const Distortion& d,
                        const Eigen::Vector2d& px) {
  const double x = (px.x() - c.cx) / c.fx, y = (px.y() - c.cy) / c.fy;
  const double r2 = x * x + y * y;
  const double radial = 1 + d.k1 * r2 + d.k2 * r2 * r2 + d.k3 * r2 * r2 * r2;
  const double xd = x * radial + 2 * d.p1 * x * y + d.p2 * (r2 + 2 * x * x);
  const double yd = y * radial + d.p1 * (r2 + 2 * y * y) + 2 * d.p2 * x * y;
  return {c.fx * xd + c.cx, c.fy * yd + c.cy};
}

// COLMAP text with SIMPLE_RADIAL cameras (f cx cy k): WriteDataset's OPENCV
// lines rewritten (needs fx = fy and k2 = p1 = p2 = 0).
void ToSimpleRadial(const SyntheticScene& s, const std::string& dir) {
  std::ofstream os(dir + "/sparse/cameras.txt");
  os.precision(17);
  for (size_t i = 0; i < s.scene.views.size(); ++i) {
    const Camera& c = s.scene.views[i].camera;
    os << i + 1 << " SIMPLE_RADIAL " << c.width << " " << c.height << " "
       << c.fx << " " << c.cx << " " << c.cy << " "
       << s.scene.views[i].distortion.k1 << "\n";
  }
}

template <typename T>
void Put(std::ofstream& os, T v) {
  os.write(reinterpret_cast<const char*>(&v), sizeof(T));
}

// COLMAP binary model (cameras.bin, images.bin, points3D.bin; OPENCV
// cameras) in dir/sparse/, images in dir/images/ (copied from `from`).
void WriteBinaryModel(const SyntheticScene& s, const std::string& from,
                      const std::string& dir) {
  fs::create_directories(dir + "/sparse");
  fs::copy(from + "/images", dir + "/images");
  const Scene& sc = s.scene;
  const size_t nv = sc.views.size();
  std::vector<std::vector<std::pair<Eigen::Vector2d, int64_t>>> obs(nv);
  std::vector<std::vector<std::pair<int32_t, int32_t>>> tracks(
      sc.points.size());
  for (size_t p = 0; p < sc.points.size(); ++p) {
    for (const Observation& o : sc.points[p].track) {
      const View& v = sc.views[o.view];
      tracks[p].emplace_back(o.view + 1,
                             static_cast<int32_t>(obs[o.view].size()));
      obs[o.view].emplace_back(Distort(v.camera, v.distortion, o.xy),
                               static_cast<int64_t>(p + 1));
    }
  }
  {
    std::ofstream os(dir + "/sparse/cameras.bin", std::ios::binary);
    Put<uint64_t>(os, nv);
    for (size_t i = 0; i < nv; ++i) {
      const Camera& c = sc.views[i].camera;
      const Distortion& d = sc.views[i].distortion;
      Put<int32_t>(os, static_cast<int32_t>(i + 1));
      Put<int32_t>(os, 4);  // OPENCV
      Put<uint64_t>(os, c.width);
      Put<uint64_t>(os, c.height);
      for (double v : {c.fx, c.fy, c.cx, c.cy, d.k1, d.k2, d.p1, d.p2})
        Put<double>(os, v);
    }
  }
  {
    std::ofstream os(dir + "/sparse/images.bin", std::ios::binary);
    Put<uint64_t>(os, nv);
    for (size_t i = 0; i < nv; ++i) {
      const Camera& c = sc.views[i].camera;
      Eigen::Quaterniond q(c.R);
      q.normalize();
      Put<int32_t>(os, static_cast<int32_t>(i + 1));
      for (double v : {q.w(), q.x(), q.y(), q.z(), c.t.x(), c.t.y(), c.t.z()})
        Put<double>(os, v);
      Put<int32_t>(os, static_cast<int32_t>(i + 1));
      os.write(sc.views[i].name.c_str(), sc.views[i].name.size() + 1);
      Put<uint64_t>(os, obs[i].size());
      for (const auto& [px, id] : obs[i]) {
        Put<double>(os, px.x());
        Put<double>(os, px.y());
        Put<int64_t>(os, id);
      }
    }
  }
  std::ofstream os(dir + "/sparse/points3D.bin", std::ios::binary);
  Put<uint64_t>(os, sc.points.size());
  for (size_t p = 0; p < sc.points.size(); ++p) {
    Put<uint64_t>(os, p + 1);
    for (int k = 0; k < 3; ++k) Put<double>(os, sc.points[p].xyz[k]);
    for (int k = 0; k < 3; ++k) Put<uint8_t>(os, 128);
    Put<double>(os, 0.5);
    Put<uint64_t>(os, tracks[p].size());
    for (const auto& [image, idx] : tracks[p]) {
      Put<int32_t>(os, image);
      Put<int32_t>(os, idx);
    }
  }
}

// Bundler v0.3 (bundle.out + list.txt in dir/, images in dir/images/):
// camera looking down -z with y up, fx = fy = f, principal point at the
// image centre, radial k1 k2; observations relative to the centre, y up.
void WriteBundler(const SyntheticScene& s, const std::string& dir) {
  const Scene& sc = s.scene;
  fs::remove_all(dir + "/sparse");  // so that the layout is Bundler's
  std::ofstream list(dir + "/list.txt");
  for (const View& v : sc.views) list << "images/" << v.name << "\n";
  std::ofstream os(dir + "/bundle.out");
  os.precision(17);
  os << "# Bundle file v0.3\n"
     << sc.views.size() << " " << sc.points.size() << "\n";
  const Eigen::Matrix3d flip = Eigen::Vector3d(1, -1, -1).asDiagonal();
  for (const View& v : sc.views) {
    const Camera& c = v.camera;
    os << c.fx << " " << v.distortion.k1 << " " << v.distortion.k2 << "\n";
    const Eigen::Matrix3d R = flip * c.R;
    const Eigen::Vector3d t = flip * c.t;
    for (int r = 0; r < 3; ++r)
      os << R(r, 0) << " " << R(r, 1) << " " << R(r, 2) << "\n";
    os << t.x() << " " << t.y() << " " << t.z() << "\n";
  }
  for (const SparsePoint& p : sc.points) {
    os << p.xyz.x() << " " << p.xyz.y() << " " << p.xyz.z() << "\n"
       << "128 128 128\n"
       << p.track.size();
    for (const Observation& o : p.track) {
      const View& v = sc.views[o.view];
      const Eigen::Vector2d d = Distort(v.camera, v.distortion, o.xy);
      os << " " << o.view << " 0 " << d.x() - 0.5 * v.camera.width << " "
         << 0.5 * v.camera.height - d.y();
    }
    os << "\n";
  }
}

struct Score {
  int gt_valid = 0, estimated = 0, within = 0;
  double completeness = 0, inliers = 0;
};

// Depth map (the ground truth's resolution) against the ground truth,
// relative error < 1 %.
Score Compare(const cv::Mat& gt, const DepthMap& dm) {
  Score r;
  EXPECT_EQ(dm.depth.size(), gt.size());
  if (dm.depth.size() != gt.size()) return r;
  for (int y = 0; y < gt.rows; ++y) {
    for (int x = 0; x < gt.cols; ++x) {
      const float g = gt.at<float>(y, x);
      if (!(g > 0)) continue;
      ++r.gt_valid;
      const float d = dm.depth.at<float>(y, x);
      if (!(d > 0)) continue;
      ++r.estimated;
      if (std::abs(d - g) < 0.01 * g) ++r.within;
    }
  }
  r.completeness = r.gt_valid ? double(r.within) / r.gt_valid : 0;
  r.inliers = r.estimated ? double(r.within) / r.estimated : 0;
  return r;
}

DepthMap Reconstruct(const Scene& scene) {
  ImageCache cache(MakeSceneLoader(scene, ImageOptions()), 64);
  ThreadPool pool(2);
  ViewReport rep;
  return ReconstructView(scene, kRef, cache, MvsOptions(), &pool, &rep);
}

// Loads `dir`, checks the cameras, distortion and undistorted observations
// against the rendered scene, reconstructs view kRef and scores it.
Score LoadAndReconstruct(const SyntheticScene& s, const std::string& dir,
                         DatasetFormat format, const char* what,
                         Scene* loaded = nullptr) {
  DatasetOptions o;
  o.path = dir;
  o.format = format;
  const Scene scene = LoadDataset(o);
  EXPECT_EQ(scene.views.size(), s.scene.views.size()) << what;
  if (scene.views.size() != s.scene.views.size()) return Score();
  for (size_t i = 0; i < scene.views.size(); ++i) {
    const Camera& a = scene.views[i].camera;
    const Camera& b = s.scene.views[i].camera;
    EXPECT_NEAR(a.fx, b.fx, 1e-6) << what << " view " << i;
    EXPECT_NEAR(a.fy, b.fy, 1e-6) << what << " view " << i;
    EXPECT_NEAR(a.cx, b.cx, 1e-6) << what << " view " << i;
    EXPECT_NEAR(a.cy, b.cy, 1e-6) << what << " view " << i;
    EXPECT_NEAR((a.Center() - b.Center()).norm(), 0, 1e-6) << what;
    EXPECT_FALSE(scene.views[i].distortion.IsNone()) << what;
    EXPECT_NEAR(scene.views[i].distortion.k1, s.scene.views[i].distortion.k1,
                1e-9)
        << what;
  }
  // Observations undistorted back onto the pinhole projections.
  EXPECT_EQ(scene.points.size(), s.scene.points.size()) << what;
  double worst = 0;
  for (size_t p = 0; p < std::min(scene.points.size(), s.scene.points.size());
       ++p)
    for (size_t k = 0;
         k < scene.points[p].track.size() && k < s.scene.points[p].track.size();
         ++k)
      worst = std::max(
          worst,
          (scene.points[p].track[k].xy - s.scene.points[p].track[k].xy).norm());
  EXPECT_LT(worst, 0.01) << what << ": undistorted observations";
  const Score r = Compare(s.depth[kRef], Reconstruct(scene));
  std::printf(
      "%-28s gt %5d est %5d within1%% %5d completeness %.3f inliers %.3f "
      "(observations within %.1e px)\n",
      what, r.gt_valid, r.estimated, r.within, r.completeness, r.inliers,
      worst);
  if (loaded) *loaded = scene;
  return r;
}

class MvsDistortedCameras : public ::testing::Test {
 protected:
  void SetUp() override { dir_ = testing::MakeTempDir("distorted"); }
  void TearDown() override { fs::remove_all(dir_); }
  std::string dir_;
};

// fx != fy, off-centre principal point, OpenCV k1 k2 p1 p2: COLMAP text
// (OPENCV) and binary; the control ignores the distortion.
TEST_F(MvsDistortedCameras, OpencvTextAndBinary) {
  const SyntheticSpec spec = BaseSpec();
  SyntheticLens lens;
  lens.focal_y_ratio = 1.08;
  lens.principal_offset = Eigen::Vector2d(6.5, -4.25);
  lens.distortion.model = Distortion::Model::kOpenCV;
  lens.distortion.k1 = -0.2;
  lens.distortion.k2 = 0.05;
  lens.distortion.p1 = 0.003;
  lens.distortion.p2 = -0.002;
  const SyntheticScene s = testing::Render(spec, lens);
  const Camera& c = s.scene.views[kRef].camera;
  ASSERT_NE(c.fx, c.fy);
  ASSERT_NE(c.cx, 0.5 * c.width);
  // The lens moves pixels by up to this much at the image corners.
  const double shift =
      (Distort(c, lens.distortion, {0.0, 0.0}) - Eigen::Vector2d(0, 0)).norm();
  std::printf("distortion at the corner: %.1f px\n", shift);
  ASSERT_GT(shift, 4.0);

  testing::WriteDataset(s, dir_ + "/text");
  Scene text;
  const Score t = LoadAndReconstruct(s, dir_ + "/text", DatasetFormat::kColmap,
                                     "COLMAP text OPENCV", &text);
  WriteBinaryModel(s, dir_ + "/text", dir_ + "/binary");
  const Score b = LoadAndReconstruct(
      s, dir_ + "/binary", DatasetFormat::kColmap, "COLMAP binary OPENCV");
  // Measured (text and binary alike): completeness 0.856, inliers 0.942.
  for (const Score& r : {t, b}) {
    EXPECT_GT(r.completeness, 0.76);
    EXPECT_GT(r.inliers, 0.88);
  }
  // Control: the same images used as if they had no distortion.
  for (View& v : text.views) v.distortion = Distortion();
  const Score n = Compare(s.depth[kRef], Reconstruct(text));
  std::printf(
      "%-28s gt %5d est %5d within1%% %5d completeness %.3f "
      "inliers %.3f\n",
      "control: distortion ignored", n.gt_valid, n.estimated, n.within,
      n.completeness, n.inliers);
  // Measured: completeness 0.739, inliers 0.824 (0.117 / 0.118 worse).
  EXPECT_LT(n.completeness, t.completeness - 0.05);
  EXPECT_LT(n.inliers, t.inliers - 0.05);
}

// fx = fy, off-centre principal point, one radial coefficient: COLMAP text
// SIMPLE_RADIAL.
TEST_F(MvsDistortedCameras, SimpleRadialText) {
  const SyntheticSpec spec = BaseSpec();
  SyntheticLens lens;
  lens.principal_offset = Eigen::Vector2d(-5.0, 3.5);
  lens.distortion.model = Distortion::Model::kRadial;
  lens.distortion.k1 = -0.18;
  const SyntheticScene s = testing::Render(spec, lens);
  testing::WriteDataset(s, dir_);
  ToSimpleRadial(s, dir_);
  const Score r = LoadAndReconstruct(s, dir_, DatasetFormat::kColmap,
                                     "COLMAP text SIMPLE_RADIAL");
  // Measured: completeness 0.863, inliers 0.938.
  EXPECT_GT(r.completeness, 0.76);
  EXPECT_GT(r.inliers, 0.88);
}

// Bundler: f k1 k2, principal point at the centre (the format has no other).
TEST_F(MvsDistortedCameras, Bundler) {
  const SyntheticSpec spec = BaseSpec();
  SyntheticLens lens;
  lens.distortion.model = Distortion::Model::kRadial;
  lens.distortion.k1 = -0.15;
  lens.distortion.k2 = 0.03;
  const SyntheticScene s = testing::Render(spec, lens);
  testing::WriteDataset(s, dir_);
  WriteBundler(s, dir_);
  const Score r =
      LoadAndReconstruct(s, dir_, DatasetFormat::kBundler, "Bundler f k1 k2");
  // Measured: completeness 0.859, inliers 0.941.
  EXPECT_GT(r.completeness, 0.76);
  EXPECT_GT(r.inliers, 0.88);
}

}  // namespace
}  // namespace wild_mvs
