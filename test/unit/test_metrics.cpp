// Copyright wild_mvs authors. Depth-map and cloud metrics on analytic cases.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <opencv2/imgcodecs.hpp>
#include <random>

#include "synthetic_scene.h"
#include "test_paths.h"
#include "wild_mvs/core/error.h"
#include "wild_mvs/core/metrics.h"
#include "wild_mvs/io/metrics_json.h"
#include "wild_mvs/io/strecha.h"

namespace wild_mvs {
namespace {

// ------------------------------------------------------------ depth maps

TEST(DepthMetrics, IdenticalMapsArePerfect) {
  cv::Mat gt(40, 50, CV_32F);
  cv::randu(gt, 1.0, 5.0);
  gt(cv::Rect(0, 0, 10, 40)) = 0;  // 400 unknown GT pixels
  const DepthMetrics m = EvaluateDepth(gt, gt);
  EXPECT_EQ(m.gt_valid, 40 * 40);
  EXPECT_EQ(m.estimated, 40 * 40);
  EXPECT_EQ(m.evaluated, 40 * 40);
  EXPECT_EQ(m.outside_gt, 0);
  EXPECT_DOUBLE_EQ(m.completeness, 1.0);
  EXPECT_DOUBLE_EQ(m.median_abs_error, 0.0);
  EXPECT_DOUBLE_EQ(m.rmse, 0.0);
  for (double f : m.relative_accuracy) EXPECT_DOUBLE_EQ(f, 1.0);
  for (double f : m.absolute_completeness) EXPECT_DOUBLE_EQ(f, 1.0);
}

TEST(DepthMetrics, KnownErrorsGiveKnownFractions) {
  // GT depth 2 everywhere on 100 x 10 pixels. Estimate:
  //   columns  0..19: unknown (0)
  //   columns 20..49: exact
  //   columns 50..79: +3 % (0.06 absolute)
  //   columns 80..99: -1.5 % (0.03 absolute)
  // Plus 5 pixels estimated where the GT is unknown.
  cv::Mat gt(10, 100, CV_32F, cv::Scalar(2.0f));
  cv::Mat est = gt.clone();
  est.colRange(0, 20) = 0;
  est.colRange(50, 80) = 2.06f;
  est.colRange(80, 100) = 1.97f;
  cv::Mat gt2 = cv::Mat::zeros(10, 105, CV_32F), est2 = gt2.clone();
  gt.copyTo(gt2.colRange(0, 100));
  est.copyTo(est2.colRange(0, 100));
  est2.colRange(100, 105).rowRange(0, 1) = 3.0f;
  DepthMetricsOptions opt;
  opt.relative_thresholds = {0.01, 0.02, 0.05};
  opt.absolute_thresholds = {0.01, 0.04, 0.1};
  const DepthMetrics m = EvaluateDepth(est2, gt2, opt);
  EXPECT_EQ(m.gt_valid, 1000);
  EXPECT_EQ(m.estimated, 805);
  EXPECT_EQ(m.evaluated, 800);
  EXPECT_EQ(m.outside_gt, 5);
  EXPECT_DOUBLE_EQ(m.completeness, 0.8);
  // 300 exact, 300 at 0.06 / 3 %, 200 at 0.03 / 1.5 %.
  EXPECT_NEAR(m.relative_accuracy[0], 300.0 / 800, 1e-12);
  EXPECT_NEAR(m.relative_accuracy[1], 500.0 / 800, 1e-12);
  EXPECT_NEAR(m.relative_accuracy[2], 1.0, 1e-12);
  EXPECT_NEAR(m.relative_completeness[1], 500.0 / 1000, 1e-12);
  EXPECT_NEAR(m.absolute_accuracy[0], 300.0 / 800, 1e-12);
  EXPECT_NEAR(m.absolute_accuracy[1], 500.0 / 800, 1e-12);
  EXPECT_NEAR(m.absolute_completeness[2], 800.0 / 1000, 1e-12);
  // Sorted errors: 300 x 0, 200 x 0.03, 300 x 0.06 -> median = 0.03.
  EXPECT_NEAR(m.median_abs_error, 0.03, 1e-6);
  EXPECT_NEAR(m.median_rel_error, 0.015, 1e-6);
  EXPECT_NEAR(m.mean_abs_error, (200 * 0.03 + 300 * 0.06) / 800, 1e-6);
  EXPECT_NEAR(m.rmse,
              std::sqrt((200 * 0.03 * 0.03 + 300 * 0.06 * 0.06) / 800.0), 1e-6);
  // Reports.
  const std::string js = DepthMetricsJson(m);
  EXPECT_EQ(js.front(), '{');
  EXPECT_EQ(js.back(), '}');
  EXPECT_NE(js.find("\"completeness\": 0.8"), std::string::npos) << js;
  EXPECT_NE(js.find("\"evaluated\": 800"), std::string::npos) << js;
  EXPECT_NE(m.ToString().find("completeness: 80.00 %"), std::string::npos)
      << m.ToString();
}

TEST(DepthMetrics, NanAndNegativeAreUnknown) {
  cv::Mat gt(4, 4, CV_32F, cv::Scalar(1.0f));
  cv::Mat est = gt.clone();
  est.at<float>(0, 0) = std::nanf("");
  est.at<float>(0, 1) = -1.f;
  gt.at<float>(3, 3) = std::numeric_limits<float>::infinity();
  const DepthMetrics m = EvaluateDepth(est, gt);
  EXPECT_EQ(m.gt_valid, 15);
  EXPECT_EQ(m.estimated, 14);
  EXPECT_EQ(m.evaluated, 13);
}

TEST(DepthMetrics, BadInputsAreRejected) {
  cv::Mat a(4, 4, CV_32F, cv::Scalar(1.0f)), b(5, 4, CV_32F, cv::Scalar(1.f));
  EXPECT_THROW(EvaluateDepth(a, b), Error);
  cv::Mat d(4, 4, CV_64F, cv::Scalar(1.0));
  EXPECT_THROW(EvaluateDepth(d, d), Error);
  DepthMetricsOptions opt;
  opt.relative_thresholds = {0.01, -1};
  try {
    EvaluateDepth(a, a, opt);
    FAIL() << "no throw";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("relative_thresholds[1]"),
              std::string::npos)
        << e.what();
  }
}

TEST(DepthMetrics, GroundTruthIsResampledToTheEstimateCamera) {
  // The same slanted plane rendered at full and at half resolution: the
  // full-resolution ground truth resampled to the half-resolution camera
  // equals the half-resolution ground truth.
  testing::SyntheticSpec full = testing::SlantedPlaneSpec(40, 2);
  full.num_sparse_points = 0;
  full.supersample = 1;
  testing::SyntheticSpec half = full;
  half.width = 160;
  half.height = 120;
  half.focal = 150;
  const testing::SyntheticScene a = testing::Render(full);
  const testing::SyntheticScene b = testing::Render(half);
  const Camera& ca = a.scene.views[1].camera;
  const Camera& cb = b.scene.views[1].camera;
  const Camera resized = ca.Resized(160, 120);
  EXPECT_NEAR((resized.K() - cb.K()).norm(), 0, 1e-12);
  const cv::Mat res = ResampleDepth(a.depth[1], ca, cb);
  ASSERT_EQ(res.size(), cv::Size(160, 120));
  double max_rel = 0;
  for (int r = 0; r < 120; ++r)
    for (int c = 0; c < 160; ++c) {
      const double g = b.depth[1].at<float>(r, c);
      ASSERT_GT(res.at<float>(r, c), 0.f);
      max_rel = std::max(max_rel, std::abs(res.at<float>(r, c) - g) / g);
    }
  EXPECT_LT(max_rel, 1e-5);
  // Half-resolution estimate = the exact half-resolution depth: perfect.
  const DepthMetrics m = EvaluateDepth(b.depth[1], cb, a.depth[1], ca);
  EXPECT_EQ(m.gt_valid, 160 * 120);
  EXPECT_DOUBLE_EQ(m.completeness, 1.0);
  EXPECT_LT(m.median_rel_error, 1e-5);
  EXPECT_DOUBLE_EQ(m.relative_accuracy[0], 1.0);
  // And the other way round (estimate larger than the ground truth).
  const DepthMetrics up = EvaluateDepth(a.depth[1], ca, b.depth[1], cb);
  EXPECT_EQ(up.evaluated, 320 * 240);
  EXPECT_LT(up.median_rel_error, 1e-4);
  // A different view is not the same pose.
  EXPECT_THROW(ResampleDepth(a.depth[0], ca, a.scene.views[0].camera), Error);
}

// Exact depth map of the plane n . X = d seen by `cam` (0 where the plane
// is behind the camera).
cv::Mat PlaneDepth(const Camera& cam, const Eigen::Vector3d& n, double d) {
  cv::Mat out(cam.height, cam.width, CV_32F, cv::Scalar(0));
  for (int r = 0; r < cam.height; ++r)
    for (int c = 0; c < cam.width; ++c) {
      const Eigen::Vector3d ray =
          cam.R.transpose() * cam.BackprojectCam({c + 0.5, r + 0.5}, 1.0);
      const double z = (d - n.dot(cam.Center())) / n.dot(ray);
      if (z > 0) out.at<float>(r, c) = static_cast<float>(z);
    }
  return out;
}

TEST(DepthMetrics, PrincipalPointMappingLikeFountainP11) {
  // fountain-P11's ground truth was rendered with a centred principal point
  // and square pixels while the real camera has cx, cy off-centre and
  // fx != fy (STAGING_NOTES.txt), at 1/16 of the resolution here.
  Camera real;
  real.width = 192;
  real.height = 128;
  real.fx = 2759.48 / 16;
  real.fy = 2764.16 / 16;
  real.cx = 1520.69 / 16 + 0.5;
  real.cy = 1006.81 / 16 + 0.5;
  real.R = Eigen::AngleAxisd(0.2, Eigen::Vector3d(0.3, 1, 0.1).normalized())
               .toRotationMatrix();
  real.t = Eigen::Vector3d(0.3, -0.1, 1.0);
  Camera render = real;
  render.fx = render.fy = 2759.48 / 16;
  render.cx = 1536.0 / 16 + 0.5;
  render.cy = 1024.0 / 16 + 0.5;
  const Eigen::Vector3d n = Eigen::Vector3d(0.2, -0.3, 1).normalized();
  const double d = n.dot(real.CameraToWorld({0, 0, 8.0}));
  const cv::Mat gt_render = PlaneDepth(render, n, d);
  const cv::Mat gt_real = PlaneDepth(real, n, d);
  // Mapped: agrees with the real camera's depth wherever it is defined.
  const cv::Mat mapped = ResampleDepth(gt_render, render, real);
  const DepthMetrics ok = EvaluateDepth(mapped, gt_real);
  EXPECT_GT(ok.completeness, 0.95);  // a border strip maps outside
  EXPECT_LT(ok.median_rel_error, 1e-5);
  EXPECT_DOUBLE_EQ(ok.relative_accuracy[0], 1.0);
  // Through the camera overload as well: same numbers.
  const DepthMetrics ok2 = EvaluateDepth(gt_real, real, gt_render, render);
  EXPECT_EQ(ok2.evaluated, ok.evaluated);
  EXPECT_LT(ok2.median_rel_error, 1e-5);
  // Unmapped (taking the rendered GT pixel for pixel) is measurably wrong.
  const DepthMetrics bad = EvaluateDepth(gt_render, gt_real);
  EXPECT_GT(bad.median_rel_error, 100 * ok.median_rel_error + 1e-4);
}

// fountain-P11 ground-truth depth (EXR rendered with a centred principal
// point) as a depth map of the real camera scaled to `scale`, via
// ResampleDepth; or, when !map, naively taken as if it were the real
// camera's (the mistake the principal-point mapping avoids).
cv::Mat FountainDepth(const std::string& dir, const std::string& stem,
                      const Camera& real, const Camera& work, bool map) {
  setenv("OPENCV_IO_ENABLE_OPENEXR", "1", 1);
  const std::string path = dir + "/gt_depth_blender_exr/" + stem + ".exr";
  const cv::Mat exr = cv::imread(path, cv::IMREAD_UNCHANGED);
  if (exr.empty()) return cv::Mat();
  cv::Mat z;
  cv::extractChannel(exr, z, 0);
  z.setTo(0, z > 1e4);
  Camera render = real;
  render.fx = render.fy = 2759.48;
  render.cx = 1536.0 + 0.5;  // integer-centre convention -> camera.h
  render.cy = 1024.0 + 0.5;
  return ResampleDepth(z, map ? render : real, work);
}

// GT depth of view i transferred into view j's pixels (backward lookup).
cv::Mat Transfer(const cv::Mat& di, const Camera& ci, const cv::Mat& dj,
                 const Camera& cj) {
  cv::Mat out(dj.size(), CV_32F, cv::Scalar(0));
  for (int r = 0; r < dj.rows; ++r)
    for (int c = 0; c < dj.cols; ++c) {
      const float z = dj.at<float>(r, c);
      if (!(z > 0)) continue;
      Eigen::Vector2d q;
      if (!ci.Project(cj.Backproject({c + 0.5, r + 0.5}, z), &q) ||
          !ci.InImage(q, 1))
        continue;
      const float zi =
          di.at<float>(static_cast<int>(q.y()), static_cast<int>(q.x()));
      if (!(zi > 0)) continue;
      out.at<float>(r, c) = static_cast<float>(cj.Depth(ci.Backproject(q, zi)));
    }
  return out;
}

TEST(DepthMetricsReal, FountainGroundTruthNeedsThePrincipalPointMapping) {
  WILD_MVS_REQUIRE_SHARED(dir, "datasets/strecha_fountain-P11");
  const Camera c0 = ReadStrechaCamera(dir + "/cameras/0004.jpg.camera");
  const Camera c1 = ReadStrechaCamera(dir + "/cameras/0005.jpg.camera");
  const Camera w0 = c0.Scaled(0.25), w1 = c1.Scaled(0.25);
  DepthMetricsOptions opt;
  opt.absolute_thresholds = {0.01};
  double median[2], within_1cm[2];
  for (int map = 1; map >= 0; --map) {
    const cv::Mat d0 = FountainDepth(dir, "0004", c0, w0, map);
    const cv::Mat d1 = FountainDepth(dir, "0005", c1, w1, map);
    if (d0.empty() || d1.empty()) GTEST_SKIP() << "OpenCV cannot read EXR";
    const DepthMetrics m = EvaluateDepth(Transfer(d0, w0, d1, w1), d1, opt);
    std::printf("fountain 0004 -> 0005 at 1/4 resolution, %s:\n%s",
                map ? "mapped" : "NOT mapped", m.ToString().c_str());
    median[map] = m.median_abs_error;
    within_1cm[map] = m.absolute_accuracy[0];
    EXPECT_GT(m.evaluated, 0.6 * w1.width * w1.height);
    if (map) {
      EXPECT_LT(m.median_abs_error, 0.006);
      EXPECT_GT(m.absolute_accuracy[0], 0.85);
    }
  }
  // Measured: median 2.5 mm vs 8.8 mm, 90 % vs 61 % within 1 cm.
  EXPECT_GT(median[0], 2.5 * median[1]);
  EXPECT_GT(within_1cm[1], within_1cm[0] + 0.15);
}

// ------------------------------------------------------------ clouds

// Points on the plane z = 0, a regular grid of n x n with spacing h.
PointCloud Grid(int n, double h, double z = 0) {
  PointCloud c;
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j)
      c.xyz.emplace_back(static_cast<float>(i * h), static_cast<float>(j * h),
                         static_cast<float>(z));
  return c;
}

TEST(CloudMetrics, IdenticalCloudsArePerfect) {
  const PointCloud g = Grid(50, 0.01);
  const CloudMetrics m = EvaluateCloud(g, g);
  EXPECT_EQ(m.reconstruction_points, 2500);
  EXPECT_EQ(m.gt_points, 2500);
  EXPECT_DOUBLE_EQ(m.accuracy, 0.0);
  for (size_t k = 0; k < m.taus.size(); ++k) {
    EXPECT_DOUBLE_EQ(m.precision[k], 1.0);
    EXPECT_DOUBLE_EQ(m.recall[k], 1.0);
    EXPECT_DOUBLE_EQ(m.fscore[k], 1.0);
  }
}

TEST(CloudMetrics, ShiftedCloudHasTheShiftAsAccuracy) {
  const PointCloud g = Grid(40, 0.02);
  const PointCloud r = Grid(40, 0.02, 0.015);  // 1.5 cm above
  CloudMetricsOptions opt;
  opt.taus = {0.01, 0.02};
  const CloudMetrics m = EvaluateCloud(r, g, opt);
  EXPECT_NEAR(m.accuracy, 0.015, 1e-6);
  EXPECT_NEAR(m.median_accuracy, 0.015, 1e-6);
  EXPECT_NEAR(m.mean_completeness, 0.015, 1e-6);
  EXPECT_NEAR(m.completeness_distance, 0.015, 1e-6);
  EXPECT_DOUBLE_EQ(m.precision[0], 0.0);
  EXPECT_DOUBLE_EQ(m.recall[0], 0.0);
  EXPECT_DOUBLE_EQ(m.fscore[0], 0.0);
  EXPECT_DOUBLE_EQ(m.precision[1], 1.0);
  EXPECT_DOUBLE_EQ(m.recall[1], 1.0);
  EXPECT_DOUBLE_EQ(m.fscore[1], 1.0);
}

TEST(CloudMetrics, SubsetIsPreciseButIncomplete) {
  // Reconstruction = the GT points with x < 0.2 (20 of 50 columns).
  const PointCloud g = Grid(50, 0.01);
  PointCloud r;
  for (const auto& p : g.xyz)
    if (p.x() < 0.195f) r.xyz.push_back(p);
  ASSERT_EQ(r.size(), 20u * 50);
  CloudMetricsOptions opt;
  opt.taus = {0.005, 0.0505};  // below the spacing; 5 columns beyond
  const CloudMetrics m = EvaluateCloud(r, g, opt);
  EXPECT_DOUBLE_EQ(m.accuracy, 0.0);
  EXPECT_DOUBLE_EQ(m.precision[0], 1.0);
  EXPECT_NEAR(m.recall[0], 0.4, 1e-12);
  EXPECT_NEAR(m.fscore[0], 2 * 0.4 / 1.4, 1e-12);
  EXPECT_NEAR(m.recall[1], 0.5, 1e-12);  // columns 20..24 within 5 cm
  EXPECT_EQ(&m.completeness(), &m.recall);
  // The farthest GT column is 30 spacings away; 90 % of GT lie within 25.
  EXPECT_NEAR(m.completeness_distance, 0.25, 1e-6);
}

TEST(CloudMetrics, AccuracyIsTheNinetyPercentDistance) {
  // 80 points on the GT and 20 outliers at heights 0.1, 0.2, ..., 2.0 above
  // GT points: the 90th smallest of the 100 distances is 1.0.
  const PointCloud g = Grid(30, 0.05);
  PointCloud r;
  for (int k = 0; k < 80; ++k) r.xyz.push_back(g.xyz[k * 7]);
  for (int k = 1; k <= 20; ++k) {
    Eigen::Vector3f p = g.xyz[450 + k];
    p.z() = static_cast<float>(0.1 * k);
    r.xyz.push_back(p);
  }
  CloudMetricsOptions opt;
  opt.taus = {0.15, 0.55};
  const CloudMetrics m = EvaluateCloud(r, g, opt);
  EXPECT_NEAR(m.accuracy, 1.0, 1e-6);
  EXPECT_NEAR(m.precision[0], 0.81, 1e-12);
  EXPECT_NEAR(m.precision[1], 0.85, 1e-12);
  opt.accuracy_fraction = 0.8;
  EXPECT_NEAR(EvaluateCloud(r, g, opt).accuracy, 0.0, 1e-9);
  opt.accuracy_fraction = 1.0;
  EXPECT_NEAR(EvaluateCloud(r, g, opt).accuracy, 2.0, 1e-6);
}

TEST(CloudMetrics, NearestDistancesMatchBruteForce) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> u(-1, 1);
  PointCloud a, b;
  for (int i = 0; i < 3000; ++i) a.xyz.emplace_back(u(rng), u(rng), u(rng));
  for (int i = 0; i < 500; ++i) b.xyz.emplace_back(u(rng), u(rng), u(rng));
  const std::vector<double> d = NearestDistances(b, a, 2);
  ASSERT_EQ(d.size(), 500u);
  for (size_t i = 0; i < b.size(); ++i) {
    double best = 1e9;
    for (const auto& p : a.xyz)
      best = std::min(best, (p - b.xyz[i]).cast<double>().norm());
    ASSERT_NEAR(d[i], best, 1e-6);
  }
}

TEST(CloudMetrics, EmptyReconstructionAndBadInput) {
  const PointCloud g = Grid(10, 0.1);
  const CloudMetrics m = EvaluateCloud(PointCloud(), g);
  EXPECT_TRUE(std::isinf(m.accuracy));
  for (size_t k = 0; k < m.taus.size(); ++k) {
    EXPECT_EQ(m.precision[k], 0.0);
    EXPECT_EQ(m.recall[k], 0.0);
    EXPECT_EQ(m.fscore[k], 0.0);
  }
  EXPECT_NE(CloudMetricsJson(m).find("\"accuracy\": null"), std::string::npos)
      << CloudMetricsJson(m);
  EXPECT_NE(m.ToString().find("inf"), std::string::npos);
  EXPECT_THROW(EvaluateCloud(g, PointCloud()), Error);
  CloudMetricsOptions opt;
  opt.taus = {0};
  EXPECT_THROW(EvaluateCloud(g, g, opt), Error);
  opt = CloudMetricsOptions();
  opt.accuracy_fraction = 1.5;
  EXPECT_THROW(EvaluateCloud(g, g, opt), Error);
  PointCloud bad = g;
  bad.xyz[3].x() = std::nanf("");
  EXPECT_THROW(EvaluateCloud(bad, g), Error);
}

TEST(CloudMetrics, VoxelThinningKeepsOnePointPerVoxel) {
  // A 40 x 40 grid at 1 cm thinned with 5 cm voxels: 8 x 8 voxels.
  PointCloud g = Grid(40, 0.01);
  for (auto& p : g.xyz) p += Eigen::Vector3f(0.001f, 0.001f, 0.001f);
  g.rgb.assign(g.size(), Eigen::Vector3f(1, 0, 0));
  const PointCloud t = VoxelThin(g, 0.05);
  EXPECT_EQ(t.size(), 64u);
  EXPECT_EQ(t.rgb.size(), 64u);
  CloudMetricsOptions opt;
  opt.voxel_size = 0.05;
  const CloudMetrics m = EvaluateCloud(g, g, opt);
  EXPECT_EQ(m.gt_points, 64);
  EXPECT_EQ(m.reconstruction_points, 64);
  EXPECT_EQ(VoxelThin(g, 0).size(), g.size());
}

TEST(CloudMetrics, SyntheticGroundTruthCloudScoresItself) {
  // The GT cloud of a rendered scene against a sparser GT cloud of the same
  // scene: every point lies on the surface, so precision is ~1 at a tau of
  // a few pixel footprints, and recall is high.
  testing::SyntheticSpec spec = testing::ClutteredSceneSpec(false, false);
  spec.width = 160;
  spec.height = 120;
  spec.focal = 150;
  spec.num_sparse_points = 0;
  const testing::SyntheticScene s = testing::Render(spec);
  const PointCloud dense = s.GroundTruthCloud(1);
  const PointCloud sparse = s.GroundTruthCloud(3);
  CloudMetricsOptions opt;
  opt.taus = {0.01 * s.scene_size};
  const CloudMetrics m = EvaluateCloud(sparse, dense, opt);
  EXPECT_GT(m.precision[0], 0.999);
  EXPECT_GT(m.recall[0], 0.95);  // grazing far ground is sampled sparsely
  EXPECT_LT(m.accuracy, 0.01 * s.scene_size);
}

}  // namespace
}  // namespace wild_mvs
