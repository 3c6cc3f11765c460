// Copyright wild_mvs authors. Local view selection (paper 5.2) on
// constructed cameras: epipolar directions, the pick order by global score
// and epipolar spread, the epipolar weight.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>

#include "mvs_test_scenes.h"
#include "wild_mvs/core/local_view_selection.h"

namespace wild_mvs {
namespace {

using testing::LookAtCamera;

constexpr double kDeg = M_PI / 180.0;

TEST(MvsLocalViewSelection, SpreadsEpipolarDirections) {
  // R at the origin looking along +y (world z up); candidates to its right
  // on a horizontal line, and one above it.
  const Camera r = LookAtCamera(Eigen::Vector3d(0, 0, 0),
                                Eigen::Vector3d(0, 5, 0), 300, 320, 240);
  const Eigen::Vector3d centers[3] = {
      Eigen::Vector3d(0.5, 0, 0),   // right
      Eigen::Vector3d(1.0, 0, 0),   // further right: collinear
      Eigen::Vector3d(0, 0, 0.5)};  // above
  Eigen::Vector2d dirs[3];
  const double x = 170.5, y = 100.5;
  for (int i = 0; i < 3; ++i) {
    const Eigen::Vector3d e = r.K() * (r.R * centers[i] + r.t);
    dirs[i] = EpipolarDirection(e, x, y);
  }
  EXPECT_NEAR(std::abs(dirs[0].x()), 1.0, 1e-6);
  EXPECT_NEAR(std::abs(dirs[2].y()), 1.0, 1e-6);
  // The collinear views have the better global scores.
  const double scores[3] = {1.0, 0.9, 0.5};
  uint8_t state[3] = {0, 0, 0};
  int active[3];
  int na = 0;
  const double gmax = 10 * kDeg;
  EpipolarWeights weights(gmax);
  weights.Reset(dirs, 3);
  int v = PickNextView(3, scores, weights, state, active, na);
  EXPECT_EQ(v, 0);
  state[v] = 1;
  active[na++] = v;
  v = PickNextView(3, scores, weights, state, active, na);
  EXPECT_EQ(v, 2);  // the vertical one before the collinear one
  state[v] = 1;
  active[na++] = v;
  v = PickNextView(3, scores, weights, state, active, na);
  EXPECT_EQ(v, 1);
  state[v] = 1;
  active[na++] = v;
  EXPECT_EQ(PickNextView(3, scores, weights, state, active, na), -1);
  // Rejected views are never picked again.
  uint8_t rejected[3] = {2, 0, 0};
  EXPECT_EQ(PickNextView(3, scores, weights, rejected, active, 0), 1);

  EXPECT_NEAR(EpipolarWeight(dirs[0], dirs[1], gmax), 0.0, 1e-6);
  // The cached weights are EpipolarWeight's, either way round, before and
  // after a new pixel's directions.
  for (int a = 0; a < 3; ++a)
    for (int b = 0; b < 3; ++b) {
      EXPECT_EQ(weights(a, b), EpipolarWeight(dirs[a], dirs[b], gmax));
      EXPECT_EQ(weights(b, a), weights(a, b));
    }
  const double angles[3] = {0.3, 0.3 + 4 * kDeg, 0.3 + 30 * kDeg};
  Eigen::Vector2d turned[3];
  for (int i = 0; i < 3; ++i)
    turned[i] = Eigen::Vector2d(std::cos(angles[i]), std::sin(angles[i]));
  weights.Reset(turned, 3);
  for (int a = 0; a < 3; ++a)
    for (int b = 0; b < 3; ++b)
      EXPECT_EQ(weights(a, b), EpipolarWeight(turned[a], turned[b], gmax));
  EXPECT_NEAR(weights(0, 1), 0.4, 1e-6);
  EXPECT_NEAR(EpipolarWeight(dirs[0], dirs[2], gmax), 1.0, 1e-9);
  const Eigen::Vector2d d5(std::cos(5 * kDeg), std::sin(5 * kDeg));
  EXPECT_NEAR(EpipolarWeight(Eigen::Vector2d(1, 0), d5, gmax), 0.5, 1e-6);
  // Acute angle: opposite directions are the same line.
  EXPECT_NEAR(EpipolarWeight(Eigen::Vector2d(1, 0), -d5, gmax), 0.5, 1e-6);
}

}  // namespace
}  // namespace wild_mvs
