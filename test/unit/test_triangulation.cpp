// Copyright wild_mvs authors. Tests of multi-view triangulation with exact
// synthetic cameras and points.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <random>
#include <vector>

#include "wild_mvs/core/triangulation.h"

namespace wild_mvs {
namespace {

// A camera at `center` looking at `target` (image x horizontal, world z up).
Camera LookAt(const Eigen::Vector3d& center, const Eigen::Vector3d& target) {
  Camera c;
  c.fx = 800;
  c.fy = 780;
  c.cx = 320.5;
  c.cy = 240.5;
  c.width = 640;
  c.height = 480;
  const Eigen::Vector3d z = (target - center).normalized();
  Eigen::Vector3d x = z.cross(Eigen::Vector3d::UnitZ());
  if (x.norm() < 1e-6) x = Eigen::Vector3d::UnitX();
  x.normalize();
  const Eigen::Vector3d y = z.cross(x);
  c.R.row(0) = x;
  c.R.row(1) = y;
  c.R.row(2) = z;
  c.t = -c.R * center;
  return c;
}

std::vector<Camera> RingCameras(int n, double radius, double arc_deg) {
  std::vector<Camera> cams;
  for (int i = 0; i < n; ++i) {
    const double a = (arc_deg * M_PI / 180.0) * i / std::max(1, n - 1);
    cams.push_back(
        LookAt(Eigen::Vector3d(radius * std::cos(a), radius * std::sin(a), 0.5),
               Eigen::Vector3d::Zero()));
  }
  return cams;
}

std::vector<TriangulationInput> Observe(const std::vector<Camera>& cams,
                                        const Eigen::Vector3d& X, double noise,
                                        std::mt19937* rng) {
  std::normal_distribution<double> n(0.0, noise);
  std::vector<TriangulationInput> obs;
  for (const Camera& c : cams) {
    Eigen::Vector2d px;
    EXPECT_TRUE(c.Project(X, &px));
    if (noise > 0) px += Eigen::Vector2d(n(*rng), n(*rng));
    obs.push_back({&c, px});
  }
  return obs;
}

TEST(Triangulation, ExactObservationsGiveExactPoint) {
  const std::vector<Camera> cams = RingCameras(5, 3.0, 60);
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-0.5, 0.5);
  for (int k = 0; k < 200; ++k) {
    const Eigen::Vector3d X(u(rng), u(rng), u(rng));
    const auto obs = Observe(cams, X, 0, &rng);
    Eigen::Vector3d lin, ref;
    ASSERT_TRUE(TriangulateLinear(obs, &lin));
    EXPECT_LT((lin - X).norm(), 1e-9);
    ASSERT_TRUE(Triangulate(obs, &ref));
    EXPECT_LT((ref - X).norm(), 1e-9);
    for (const auto& o : obs) {
      EXPECT_LT(ReprojectionError(*o.camera, ref, o.xy), 1e-6);
    }
  }
}

TEST(Triangulation, TwoViewsExact) {
  const std::vector<Camera> cams = RingCameras(2, 2.0, 20);
  const Eigen::Vector3d X(0.1, -0.2, 0.3);
  std::mt19937 rng(1);
  const auto obs = Observe(cams, X, 0, &rng);
  Eigen::Vector3d P;
  ASSERT_TRUE(Triangulate(obs, &P));
  EXPECT_LT((P - X).norm(), 1e-9);
}

// With pixel noise, the refinement lowers the reprojection error below the
// linear solution's and the 3-D error stays within the bound expected from
// the geometry (noise * depth / focal / sin(angle) scale).
TEST(Triangulation, NoisyObservationsRefinementHelps) {
  const std::vector<Camera> cams = RingCameras(6, 3.0, 90);
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-0.4, 0.4);
  const double noise = 1.0;  // px
  double sum_lin = 0, sum_ref = 0, max_err3d = 0;
  const int n = 300;
  for (int k = 0; k < n; ++k) {
    const Eigen::Vector3d X(u(rng), u(rng), u(rng));
    const auto obs = Observe(cams, X, noise, &rng);
    Eigen::Vector3d lin;
    ASSERT_TRUE(TriangulateLinear(obs, &lin));
    Eigen::Vector3d ref = lin;
    ASSERT_TRUE(RefineTriangulation(obs, &ref));
    double e_lin = 0, e_ref = 0;
    for (const auto& o : obs) {
      e_lin += std::pow(ReprojectionError(*o.camera, lin, o.xy), 2);
      e_ref += std::pow(ReprojectionError(*o.camera, ref, o.xy), 2);
    }
    EXPECT_LE(e_ref, e_lin * (1 + 1e-9));
    sum_lin += e_lin;
    sum_ref += e_ref;
    max_err3d = std::max(max_err3d, (ref - X).norm());
    // RMS residual of a least-squares fit with 2n equations and 3 unknowns:
    // about noise * sqrt((2n - 3) / (2n)); allow a generous factor.
    EXPECT_LT(std::sqrt(e_ref / obs.size()), 4 * noise);
  }
  EXPECT_LT(sum_ref, sum_lin);
  // Depth ~3, focal ~800: one pixel ~ 3.8 mm; wide baseline over 6 views.
  EXPECT_LT(max_err3d, 0.02);
}

TEST(Triangulation, RejectsDegenerateInput) {
  const std::vector<Camera> cams = RingCameras(2, 2.0, 30);
  Eigen::Vector3d X;
  // One observation.
  std::vector<TriangulationInput> one = {{&cams[0], {100, 100}}};
  EXPECT_FALSE(TriangulateLinear(one, &X));
  // The same camera twice with the same pixel: the ray, not a point.
  std::vector<TriangulationInput> same = {{&cams[0], {100, 100}},
                                          {&cams[0], {100, 100}}};
  EXPECT_FALSE(TriangulateLinear(same, &X));
}

TEST(Triangulation, PointBehindCameraHasInfiniteError) {
  const Camera c = LookAt({0, -2, 0}, {0, 0, 0});
  EXPECT_TRUE(std::isinf(ReprojectionError(c, {0, -3, 0}, {320, 240})));
  EXPECT_LT(ReprojectionError(c, {0, 0, 0}, {320.5, 240.5}), 1e-9);
}

TEST(Triangulation, Angles) {
  const Eigen::Vector3d X(0, 0, 0);
  EXPECT_NEAR(TriangulationAngle({1, 0, 0}, {0, 1, 0}, X), M_PI / 2, 1e-12);
  EXPECT_NEAR(TriangulationAngle({1, 0, 0}, {2, 0, 0}, X), 0, 1e-12);
  EXPECT_NEAR(TriangulationAngle({1, 0, 0}, {-1, 0, 0}, X), M_PI, 1e-12);
  const std::vector<Camera> cams = RingCameras(3, 3.0, 60);
  std::vector<TriangulationInput> obs;
  for (const Camera& c : cams) obs.push_back({&c, {0, 0}});
  // Centres at 0, 30, 60 degrees around the z axis, all at height 0.5.
  const Eigen::Vector3d a = cams[0].Center(), b = cams[2].Center();
  EXPECT_NEAR(MaxTriangulationAngle(obs, X),
              std::acos(a.normalized().dot(b.normalized())), 1e-9);
}

TEST(Triangulation, FundamentalMatrixMapsPointsToEpipolarLines) {
  const std::vector<Camera> cams = RingCameras(2, 2.5, 40);
  const Eigen::Matrix3d F = FundamentalMatrix(cams[0], cams[1]);
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-0.5, 0.5);
  for (int k = 0; k < 100; ++k) {
    const Eigen::Vector3d X(u(rng), u(rng), u(rng));
    Eigen::Vector2d p1, p2;
    ASSERT_TRUE(cams[0].Project(X, &p1));
    ASSERT_TRUE(cams[1].Project(X, &p2));
    const Eigen::Vector3d l = F * p1.homogeneous();
    // Distance of p2 from the epipolar line of p1, in pixels.
    EXPECT_LT(std::abs(l.dot(p2.homogeneous())) / l.head<2>().norm(), 1e-6);
    // A point moved 5 px off the line is 5 px away.
    const Eigen::Vector2d off = p2 + 5.0 * l.head<2>().normalized();
    EXPECT_NEAR(std::abs(l.dot(off.homogeneous())) / l.head<2>().norm(), 5.0,
                1e-6);
  }
}

}  // namespace
}  // namespace wild_mvs
