// Copyright wild_mvs authors. Ground-truth depth: EXR/PFM readers, the
// resampling adapter, and fountain-P11 reprojection consistency.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>

#include "synthetic_scene.h"
#include "test_paths.h"
#include "wild_mvs/core/error.h"
#include "wild_mvs/io/dataset.h"
#include "wild_mvs/io/ground_truth.h"
#include "wild_mvs/io/pfm.h"
#include "wild_mvs/io/strecha.h"

namespace wild_mvs {
namespace {

namespace fs = std::filesystem;

TEST(GroundTruth, ExrAndPfmReadersMarkInvalid) {
  const std::string d = testing::MakeTempDir("gt_exr");
  cv::Mat depth(4, 6, CV_32F);
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 6; ++c)
      depth.at<float>(r, c) = 1.0f + 0.25f * (r * 6 + c);
  depth.at<float>(0, 0) = 65504.f;  // half-float "no mesh"
  depth.at<float>(1, 1) = std::numeric_limits<float>::infinity();
  depth.at<float>(2, 2) = std::numeric_limits<float>::quiet_NaN();
  depth.at<float>(3, 3) = -2.f;
  WriteExrDepth(d + "/a.exr", depth);
  WritePfm(d + "/a.pfm", depth);
  for (const std::string f : {"/a.exr", "/a.pfm"}) {
    const cv::Mat r = ReadGroundTruthDepth(d + f);
    ASSERT_EQ(r.type(), CV_32F);
    ASSERT_EQ(r.size(), depth.size());
    EXPECT_EQ(r.at<float>(0, 0), 0) << f;
    EXPECT_EQ(r.at<float>(1, 1), 0) << f;
    EXPECT_EQ(r.at<float>(2, 2), 0) << f;
    EXPECT_EQ(r.at<float>(3, 3), 0) << f;
    EXPECT_EQ(r.at<float>(3, 5), depth.at<float>(3, 5)) << f;
    EXPECT_EQ(r.at<float>(0, 1), 1.25f) << f;
  }
  std::ofstream(d + "/bad.exr") << "not an exr file at all";
  EXPECT_THROW(ReadGroundTruthDepth(d + "/bad.exr"), Error);
  EXPECT_THROW(ReadGroundTruthDepth(d + "/none.exr"), Error);
  EXPECT_THROW(ReadGroundTruthDepth(d + "/a.png"), Error);
  fs::remove_all(d);
}

Camera Cam(int w, int h, double f, double cx, double cy) {
  Camera c;
  c.width = w;
  c.height = h;
  c.fx = c.fy = f;
  c.cx = cx;
  c.cy = cy;
  return c;
}

// Depth of the plane n . X = dist seen by camera c (pose identity).
cv::Mat PlaneDepth(const Camera& c, const Eigen::Vector3d& n, double dist) {
  cv::Mat d(c.height, c.width, CV_32F);
  for (int r = 0; r < c.height; ++r)
    for (int k = 0; k < c.width; ++k) {
      const Eigen::Vector3d ray((k + 0.5 - c.cx) / c.fx,
                                (r + 0.5 - c.cy) / c.fy, 1);
      d.at<float>(r, k) = static_cast<float>(dist / n.dot(ray));
    }
  return d;
}

TEST(GroundTruth, ResampleDepthIsExactOnSmoothSurfacesAndKeepsEdges) {
  const Camera src = Cam(300, 200, 280, 150, 100);
  const Camera dst = Cam(140, 90, 127, 71.3, 43.9);  // other K, smaller
  const Eigen::Vector3d n = Eigen::Vector3d(0.3, -0.2, 1).normalized();
  const cv::Mat gt_src = PlaneDepth(src, n, 2.0);
  const cv::Mat gt_dst = PlaneDepth(dst, n, 2.0);
  const cv::Mat r = ResampleDepth(gt_src, src, dst);
  double max_rel = 0;
  int valid = 0;
  for (int y = 0; y < dst.height; ++y)
    for (int x = 0; x < dst.width; ++x) {
      if (r.at<float>(y, x) == 0) continue;
      ++valid;
      const double e = std::abs(r.at<float>(y, x) - gt_dst.at<float>(y, x)) /
                       gt_dst.at<float>(y, x);
      max_rel = std::max(max_rel, e);
    }
  EXPECT_GT(valid, dst.width * dst.height * 0.95);
  EXPECT_LT(max_rel, 2e-5);
  // Identity.
  EXPECT_EQ(cv::norm(ResampleDepth(gt_src, src, src), gt_src, cv::NORM_INF), 0);
  // A depth edge: values are never mixed.
  cv::Mat edge(200, 300, CV_32F, cv::Scalar(1.0f));
  edge.colRange(150, 300).setTo(2.0f);
  const cv::Mat re = ResampleDepth(edge, src, dst);
  for (int y = 0; y < dst.height; ++y)
    for (int x = 0; x < dst.width; ++x) {
      const float v = re.at<float>(y, x);
      EXPECT_TRUE(v == 0 || v == 1.0f || v == 2.0f) << v;
    }
  Camera moved = dst;
  moved.t.x() = 0.1;
  EXPECT_THROW(ResampleDepth(gt_src, src, moved), Error);
}

// Synthetic dataset: GT depth PFM in DIR/gt_depth/ comes back in the view's
// grid at any working resolution.
TEST(GroundTruth, SyntheticDatasetGroundTruthForView) {
  testing::SyntheticSpec spec = testing::SlantedPlaneSpec(30, 3);
  spec.width = 160;
  spec.height = 120;
  spec.focal = 150;
  spec.num_sparse_points = 50;
  const testing::SyntheticScene syn = testing::Render(spec);
  const std::string d = testing::MakeTempDir("gt_syn");
  testing::WriteDataset(syn, d);
  DatasetOptions o;
  o.path = d;
  const Scene s = LoadDataset(o);
  ASSERT_EQ(s.views.size(), 3u);
  const cv::Mat full =
      LoadGroundTruthDepthForView(d, s.views[1], s.views[1].camera);
  ASSERT_FALSE(full.empty());
  EXPECT_EQ(cv::norm(full, syn.depth[1], cv::NORM_INF), 0);
  const Camera half = s.views[1].camera.Scaled(0.5);
  const cv::Mat h = LoadGroundTruthDepthForView(d, s.views[1], half);
  ASSERT_EQ(h.cols, 80);
  // Each half-res pixel centre lies between 4 full-res centres: compare with
  // the mean of the 2x2 block where all four are valid (a plane: ~linear).
  int n = 0;
  for (int y = 0; y < 60; ++y)
    for (int x = 0; x < 80; ++x) {
      const cv::Mat blk = syn.depth[1](cv::Rect(2 * x, 2 * y, 2, 2));
      double lo, hi;
      cv::minMaxLoc(blk, &lo, &hi);
      if (lo <= 0 || hi - lo > 0.01 * lo) continue;
      EXPECT_NEAR(h.at<float>(y, x), cv::mean(blk)[0], 1e-3 * lo);
      ++n;
    }
  EXPECT_GT(n, 1000);
  View none = s.views[0];
  none.name = "nothing.png";
  EXPECT_TRUE(LoadGroundTruthDepthForView(d, none, none.camera).empty());
  fs::remove_all(d);
}

// fountain-P11: GT depth of view i, mapped into the real camera grid and
// reprojected into view i+1, agrees with view i+1's mapped GT.
TEST(GroundTruthShared, FountainReprojectionConsistency) {
  WILD_MVS_REQUIRE_SHARED(root, "datasets/strecha_fountain-P11");
  const Scene s = ReadStrechaCameras(root + "/cameras", root + "/images");
  ASSERT_EQ(s.views.size(), 11u);
  const double scale = 0.5;
  std::vector<cv::Mat> gt(s.views.size());
  std::vector<Camera> cams(s.views.size());
  for (size_t i = 0; i < s.views.size(); ++i) {
    cams[i] = s.views[i].camera.Scaled(scale);
    gt[i] = LoadGroundTruthDepthForView(root, s.views[i], cams[i]);
    ASSERT_EQ(gt[i].cols, cams[i].width);
    const double coverage = double(cv::countNonZero(gt[i] > 0)) / gt[i].total();
    EXPECT_GT(coverage, 0.6) << s.views[i].name;
    double lo, hi;
    cv::minMaxLoc(gt[i], &lo, &hi, nullptr, nullptr, gt[i] > 0);
    EXPECT_GT(lo, 3.5);
    EXPECT_LT(hi, 16);
  }
  // Without the adapter (render depth taken as if seen by the real camera)
  // the same check fails: it is sensitive to the principal-point mapping.
  std::vector<cv::Mat> naive(2);
  for (int i = 0; i < 2; ++i) {
    const cv::Mat render = ReadExrDepth(root + "/gt_depth_blender_exr/" +
                                        s.views[i].Stem() + ".exr");
    naive[i] = ResampleDepth(render, s.views[i].camera, cams[i]);
  }
  auto median_dz = [&](const std::vector<cv::Mat>& d, size_t i,
                       double* within) {
    const Camera& a = cams[i];
    const Camera& b = cams[i + 1];
    std::vector<double> dz;
    for (int y = 0; y < a.height; y += 2)
      for (int x = 0; x < a.width; x += 2) {
        const float z = d[i].at<float>(y, x);
        if (z <= 0) continue;
        const Eigen::Vector3d X = a.Backproject({x + 0.5, y + 0.5}, z);
        Eigen::Vector2d px;
        if (!b.Project(X, &px)) continue;
        const int bx = static_cast<int>(std::floor(px.x()));
        const int by = static_cast<int>(std::floor(px.y()));
        if (bx < 0 || by < 0 || bx >= b.width || by >= b.height) continue;
        const float zb = d[i + 1].at<float>(by, bx);
        if (zb <= 0) continue;
        dz.push_back(std::abs(b.Depth(X) - zb));
      }
    if (dz.size() < 10000) return 1e9;
    *within = double(std::count_if(dz.begin(), dz.end(),
                                   [](double v) { return v < 0.01; })) /
              dz.size();
    std::nth_element(dz.begin(), dz.begin() + dz.size() / 2, dz.end());
    return dz[dz.size() / 2];
  };
  double naive_within = 0;
  const double naive_median = median_dz(naive, 0, &naive_within);
  EXPECT_GT(naive_median, 0.005);  // fails the threshold used below
  std::printf("fountain without the adapter: median |dz| %.1f mm\n",
              naive_median * 1000);
  for (size_t i = 0; i + 1 < s.views.size(); ++i) {
    double within = 0;
    const double median = median_dz(gt, i, &within);
    EXPECT_LT(median, 0.005) << s.views[i].name;
    EXPECT_GT(within, 0.9) << s.views[i].name;
    std::printf("fountain %s -> %s: median |dz| %.2f mm, %.1f %% within 1 cm\n",
                s.views[i].name.c_str(), s.views[i + 1].name.c_str(),
                median * 1000, within * 100);
  }
}

}  // namespace
}  // namespace wild_mvs
