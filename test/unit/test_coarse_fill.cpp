// Copyright wild_mvs authors. The coarse fill (coarse_fill.h) on maps of
// exact planes: holes of a plane filled at its depth, nothing across a
// depth edge or in the band a coarse window fattens, only the pixels and
// from the samples the caller allows; the test of windows that noise leaves
// unmatchable, edge-aware beside an edge; and the default pipeline on
// rendered weak walls, with and without a sky.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "synthetic_scene.h"
#include "wild_mvs/core/coarse_fill.h"
#include "wild_mvs/core/error.h"
#include "wild_mvs/core/patch.h"
#include "wild_mvs/pipeline/depth_controller.h"

namespace wild_mvs {
namespace {

// fx != fy and an off-centre principal point, as real cameras have.
Camera MakeCamera(int width, int height) {
  Camera c;
  c.width = width;
  c.height = height;
  c.fx = 1.1 * width;
  c.fy = 1.0 * width;
  c.cx = 0.47 * width;
  c.cy = 0.53 * height;
  return c;
}

// A plane n . X = offset in the camera frame (n facing the camera).
struct Plane {
  Eigen::Vector3d n;
  double offset;
  double DepthAt(const Camera& c, double u, double v) const {
    const Eigen::Vector3d ray = c.BackprojectCam({u, v}, 1.0);
    return offset / n.dot(ray);
  }
};

const Plane kSlanted{Eigen::Vector3d(0.3, -0.2, -1).normalized(), -2.0};
const Plane kNear{Eigen::Vector3d(0, 0, -1), -1.5};

// The map of `camera` where `which(u, v)` names the plane of each pixel
// (nullptr = empty).
template <typename Which>
DepthMap PlaneMap(const Camera& camera, Which which) {
  DepthMap m;
  m.camera = camera;
  m.depth = cv::Mat(camera.height, camera.width, CV_32F, cv::Scalar(0));
  m.normal = cv::Mat(camera.height, camera.width, CV_32FC3, cv::Scalar(0));
  m.confidence = cv::Mat(camera.height, camera.width, CV_32F, cv::Scalar(0));
  for (int y = 0; y < camera.height; ++y)
    for (int x = 0; x < camera.width; ++x) {
      const Plane* p = which(x + 0.5, y + 0.5);
      if (!p) continue;
      m.depth.at<float>(y, x) = p->DepthAt(camera, x + 0.5, y + 0.5);
      m.normal.at<cv::Vec3f>(y, x) = cv::Vec3f(p->n.x(), p->n.y(), p->n.z());
      m.confidence.at<float>(y, x) = 0.5f;
    }
  return m;
}

constexpr int kW = 160, kH = 120;
constexpr double kSpread = 0.01;

TEST(CoarseFill, FillsAPlanesHolesAtItsDepth) {
  const Camera fine_cam = MakeCamera(kW, kH);
  const Camera coarse_cam = fine_cam.Resized(kW / 2, kH / 2);
  const DepthMap coarse =
      PlaneMap(coarse_cam, [](double, double) { return &kSlanted; });
  // The fine map lost a rectangle in the middle.
  DepthMap fine = PlaneMap(fine_cam, [](double u, double v) {
    const bool hole = u > 50 && u < 110 && v > 30 && v < 90;
    return hole ? nullptr : &kSlanted;
  });
  const DepthMap before = PlaneMap(fine_cam, [](double u, double v) {
    const bool hole = u > 50 && u < 110 && v > 30 && v < 90;
    return hole ? nullptr : &kSlanted;
  });
  const int filled =
      FillFromCoarse(coarse, cv::Mat(), kSpread, 2, cv::Mat(), &fine);
  EXPECT_EQ(filled, 60 * 60);
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW; ++x) {
      const double truth = kSlanted.DepthAt(fine_cam, x + 0.5, y + 0.5);
      const float d = fine.depth.at<float>(y, x);
      ASSERT_GT(d, 0) << x << "," << y;
      // A plane's samples predict the plane exactly along any ray.
      EXPECT_NEAR(d, truth, 1e-4 * truth) << x << "," << y;
      if (before.depth.at<float>(y, x) > 0) {
        ASSERT_EQ(d, before.depth.at<float>(y, x)) << "known samples stay";
      } else {
        const cv::Vec3f n = fine.normal.at<cv::Vec3f>(y, x);
        EXPECT_NEAR(n[2], kSlanted.n.z(), 1e-6);
        EXPECT_EQ(fine.confidence.at<float>(y, x), 0.5f);
      }
    }
}

TEST(CoarseFill, FillsNothingAcrossADepthEdge) {
  const Camera fine_cam = MakeCamera(kW, kH);
  const Camera coarse_cam = fine_cam.Resized(kW / 2, kH / 2);
  // Left of the edge (fine u = 80) the near plane, right of it the slanted
  // one, 0.5 m behind: every coarse sample exists.
  auto which = [](double u_fine) { return u_fine < 80 ? &kNear : &kSlanted; };
  const DepthMap coarse =
      PlaneMap(coarse_cam, [&](double u, double) { return which(2 * u); });
  DepthMap fine = PlaneMap(
      fine_cam, [](double, double) -> const Plane* { return nullptr; });
  FillFromCoarse(coarse, cv::Mat(), kSpread, 0, cv::Mat(), &fine);
  int filled = 0;
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW; ++x) {
      const float d = fine.depth.at<float>(y, x);
      if (d <= 0) {
        // Only the pixels whose four coarse samples straddle the edge, and
        // the border, stay empty.
        const bool near_edge = std::abs(x + 0.5 - 80) < 3;
        const bool border = x < 1 || y < 1 || x >= kW - 1 || y >= kH - 1;
        EXPECT_TRUE(near_edge || border) << x << "," << y;
        continue;
      }
      ++filled;
      const double truth = which(x + 0.5)->DepthAt(fine_cam, x + 0.5, y + 0.5);
      EXPECT_NEAR(d, truth, 1e-4 * truth) << x << "," << y;
    }
  EXPECT_GT(filled, kW * kH * 9 / 10);
}

TEST(CoarseFill, KeepsTheCoarseWindowsHalfWidthOffTheSilhouette) {
  const Camera fine_cam = MakeCamera(kW, kH);
  const Camera coarse_cam = fine_cam.Resized(kW / 2, kH / 2);
  // The coarse map ends at coarse column 40 (fine u = 80): its samples next
  // to the empty side may be fattened, so none within the radius fills.
  const DepthMap coarse = PlaneMap(coarse_cam, [](double u, double) {
    return u < 40 ? &kSlanted : nullptr;
  });
  const int radius = 2;
  DepthMap fine = PlaneMap(
      fine_cam, [](double, double) -> const Plane* { return nullptr; });
  FillFromCoarse(coarse, cv::Mat(), kSpread, radius, cv::Mat(), &fine);
  int rightmost = -1;
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW; ++x)
      if (fine.depth.at<float>(y, x) > 0) rightmost = std::max(rightmost, x);
  // Usable coarse columns end at 40 - 1 - radius = 37 (centre u 37.5, fine
  // 75); a fine pixel needs both coarse columns around it.
  EXPECT_GT(rightmost, 60);
  EXPECT_LT(rightmost + 0.5, 2 * (40 - radius - 0.5));
  // Without the radius the fill reaches the coarse map's last column.
  DepthMap plain = PlaneMap(
      fine_cam, [](double, double) -> const Plane* { return nullptr; });
  FillFromCoarse(coarse, cv::Mat(), kSpread, 0, cv::Mat(), &plain);
  int plain_rightmost = -1;
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW; ++x)
      if (plain.depth.at<float>(y, x) > 0)
        plain_rightmost = std::max(plain_rightmost, x);
  EXPECT_GE(plain_rightmost, rightmost + 2 * radius);
}

TEST(CoarseFill, FillsOnlyThePixelsAllowed) {
  const Camera fine_cam = MakeCamera(kW, kH);
  const DepthMap coarse = PlaneMap(fine_cam.Resized(kW / 2, kH / 2),
                                   [](double, double) { return &kSlanted; });
  DepthMap fine = PlaneMap(
      fine_cam, [](double, double) -> const Plane* { return nullptr; });
  cv::Mat fillable(kH, kW, CV_8U, cv::Scalar(0));
  fillable.rowRange(0, kH / 2).setTo(255);
  FillFromCoarse(coarse, cv::Mat(), kSpread, 0, fillable, &fine);
  EXPECT_EQ(cv::countNonZero(fine.depth.rowRange(kH / 2, kH)), 0);
  EXPECT_GE(cv::countNonZero(fine.depth.rowRange(0, kH / 2)),
            (kH / 2 - 1) * (kW - 2));
}

TEST(CoarseFill, RefusesABadSpread) {
  DepthMap fine;
  EXPECT_THROW(FillFromCoarse(DepthMap(), cv::Mat(), 0.0, 0, cv::Mat(), &fine),
               Error);
  EXPECT_THROW(FillFromCoarse(DepthMap(), cv::Mat(), 1.0, 0, cv::Mat(), &fine),
               Error);
}

// An image: grey `level` with texture of amplitude `texture` (a pattern a
// few pixels wide, as surfaces have; the noise estimate tells it from
// pixel noise) plus noise of deviation `noise`, all channels alike.
cv::Mat Image(double level, double texture, double noise, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> n(0, 1);
  cv::Mat im(120, 160, CV_32FC3);
  for (int y = 0; y < im.rows; ++y)
    for (int x = 0; x < im.cols; ++x) {
      const double pattern = std::sin(0.7 * x) * std::cos(0.5 * y);
      const float v = static_cast<float>(level + texture * pattern);
      for (int c = 0; c < 3; ++c)
        im.at<cv::Vec3f>(y, x)[c] = static_cast<float>(v + noise * n(rng));
    }
  return im;
}

double BelowNoiseFraction(const cv::Mat& im) {
  MatchImage view;
  view.data = im.ptr<float>();
  view.width = im.cols;
  view.height = im.rows;
  const cv::Mat below =
      WindowsBelowNoise(im, NoiseProfile::Estimate(view), 5, 0.4);
  return cv::countNonZero(below) / double(im.total());
}

TEST(CoarseFill, WindowsOfNoiseAloneCannotMatchTexturedOnesCan) {
  // Noise only (a blank wall): no window reaches NCC 0.4 against itself.
  EXPECT_GT(BelowNoiseFraction(Image(0.5, 0.0, 0.01, 1)), 0.95);
  // Texture of ten times the noise: every window can.
  EXPECT_LT(BelowNoiseFraction(Image(0.5, 0.1, 0.01, 2)), 0.01);
}

// A textured half (left) beside a flat, darker half (a sky), with noise.
cv::Mat EdgeImage(unsigned seed) {
  cv::Mat im = Image(0.5, 0.05, 0.005, seed);
  std::mt19937 rng(seed + 100);
  std::normal_distribution<double> n(0, 0.005);
  for (int y = 0; y < im.rows; ++y)
    for (int x = im.cols / 2; x < im.cols; ++x)
      for (int c = 0; c < 3; ++c)
        im.at<cv::Vec3f>(y, x)[c] = static_cast<float>(0.15 + n(rng));
  return im;
}

// Beside an edge the plain window sees the other side's texture; the
// edge-aware one judges the flat side by itself (no texture: it cannot
// match) and keeps the textured side's weak texture (it can).
TEST(CoarseFill, EdgeAwareWindowsJudgeEachSideOfAnEdgeByItself) {
  const cv::Mat im = EdgeImage(3);
  MatchImage view;
  view.data = im.ptr<float>();
  view.width = im.cols;
  view.height = im.rows;
  view.channels = 3;
  const NoiseProfile noise = NoiseProfile::Estimate(view);
  const cv::Mat plain = WindowsBelowNoise(im, noise, 5, 0.4);
  const cv::Mat aware = WindowsBelowNoise(im, noise, 5, 0.4, kEdgeAwareSigma);
  const int edge = im.cols / 2;
  int plain_textured = 0, aware_textured = 0, aware_left_below = 0, rows = 0;
  for (int y = 4; y < im.rows - 4; ++y, ++rows) {
    // Flat side, one and two pixels from the edge (inside the window).
    for (int x : {edge, edge + 1}) {
      plain_textured += plain.at<uchar>(y, x) == 0;
      aware_textured += aware.at<uchar>(y, x) == 0;
    }
    for (int x = 4; x < edge - 4; ++x)
      aware_left_below += aware.at<uchar>(y, x) != 0;
  }
  EXPECT_GT(plain_textured, rows);       // the edge lends its texture
  EXPECT_LT(aware_textured, rows / 10);  // not to the edge-aware window
  EXPECT_LT(aware_left_below, rows * (edge - 8) / 20);  // weak texture kept
}

// A coarse sample outside `coarse_usable` fills nothing.
TEST(CoarseFill, FillsOnlyFromUsableSamples) {
  const Camera fine_cam = MakeCamera(kW, kH);
  const DepthMap coarse = PlaneMap(fine_cam.Resized(kW / 2, kH / 2),
                                   [](double, double) { return &kSlanted; });
  cv::Mat usable(kH / 2, kW / 2, CV_8U, cv::Scalar(255));
  usable.colRange(0, kW / 4).setTo(0);
  DepthMap fine = PlaneMap(
      fine_cam, [](double, double) -> const Plane* { return nullptr; });
  FillFromCoarse(coarse, usable, kSpread, 0, cv::Mat(), &fine);
  EXPECT_EQ(cv::countNonZero(fine.depth.colRange(0, kW / 2 - 1)), 0);
  EXPECT_GE(cv::countNonZero(fine.depth.colRange(kW / 2 + 1, kW)),
            (kH - 2) * (kW / 2 - 2));
}

// What the coarse fill added to view 0's raw map (before the consistency
// filter; half-size depths are half as precise), against the ground truth.
struct FillOutcome {
  int surface = 0;      // pixels with a surface
  int kept = 0;         // estimates found at full size (unchanged)
  int added = 0;        // estimates added by the fill
  int added_right = 0;  // of them, on the surface within 1 %
  int added_sky = 0;    // of them, where there is no surface
  int reported = 0;     // ViewReport::coarse_samples
};

FillOutcome MatchWithAndWithoutFill(const testing::SyntheticScene& s) {
  ImageCache images(s.Loader(), 256);
  ViewProblem problem;
  problem.scene = &s.scene;
  problem.ref = 0;
  problem.images = &images;
  const ViewResult with = DepthController(MvsOptions(), nullptr).Match(problem);
  MvsOptions one_size;
  one_size.ablation.coarse_fill = false;
  const ViewResult without = DepthController(one_size, nullptr).Match(problem);
  EXPECT_EQ(with.map.width(), s.spec.width);
  EXPECT_EQ(without.map.width(), s.spec.width);
  FillOutcome o;
  o.reported = with.report.coarse_samples;
  for (int y = 0; y < with.map.height(); ++y)
    for (int x = 0; x < with.map.width(); ++x) {
      const float g = s.depth[0].at<float>(y, x);
      o.surface += g > 0;
      const float d0 = without.map.depth.at<float>(y, x);
      const float d1 = with.map.depth.at<float>(y, x);
      if (d0 > 0) {
        EXPECT_EQ(d1, d0) << x << "," << y;
        ++o.kept;
      } else if (d1 > 0) {
        ++o.added;
        o.added_right += g > 0 && std::abs(d1 - g) <= 0.01f * g;
        o.added_sky += g <= 0;
      }
    }
  std::printf(
      "%d of %d surface pixels at full size, %d added (%d within 1 %%, %d on "
      "the sky)\n",
      o.kept, o.surface, o.added, o.added_right, o.added_sky);
  return o;
}

// Five cameras 2 m in front of a weakly textured wall (20 % of the usual
// albedo variation, camera noise 0.01), at 320x240, where the half-size
// pass runs (160 px). `width` x `height` metres of wall, rotated 30 degrees.
testing::SyntheticSpec WeakWall(double width, double height, bool sky) {
  testing::SyntheticSpec spec;
  spec.camera_centers = {{0, -2, 0},
                         {0.3, -2, 0.05},
                         {-0.3, -2, -0.05},
                         {0.6, -2, -0.1},
                         {-0.6, -2, 0.1}};
  for (const Eigen::Vector3d& c : spec.camera_centers)
    spec.look_ats.push_back(c + Eigen::Vector3d(0, 2, 0));
  testing::SyntheticObject wall;
  const double a = 30 * M_PI / 180;
  wall.center = Eigen::Vector3d(0, 0, 0);
  wall.axis_u = Eigen::Vector3d(std::cos(a), std::sin(a), 0);
  wall.axis_v = Eigen::Vector3d(0, 0, 1);
  wall.size = Eigen::Vector3d(width, height, 0.02);
  wall.texture_seed = 7;
  wall.texture_scale = 0.06;
  wall.texture_contrast = 0.2;
  spec.objects = {wall};
  spec.noise_sigma = 0.01;
  spec.sky = sky;
  return spec;
}

// The default pipeline on a wall that fills the view: the fill adds
// samples where the full-size window found none, the samples found at full
// size stay as they were, and the added ones lie on the wall. (Most of
// this wall's empty pixels stay empty: their half-size windows have too
// little texture for the edge-aware test.)
TEST(CoarseFill, DefaultMatchFillsAWeakWallFromHalfSize) {
  const FillOutcome o =
      MatchWithAndWithoutFill(testing::Render(WeakWall(4, 3, false)));
  EXPECT_EQ(o.reported, o.added);
  EXPECT_GT(o.added, o.surface / 100);
  EXPECT_GT(o.added_right, 0.95 * o.added);
  EXPECT_EQ(o.added_sky, 0);
}

// The same wall, smaller, in front of a sky: the sky has no texture at half
// size either, so nothing is filled there (a coarse window on the sky beside
// the wall matches the wall's edge at the wall's depth).
TEST(CoarseFill, DefaultMatchFillsNothingOnTheSky) {
  const FillOutcome o =
      MatchWithAndWithoutFill(testing::Render(WeakWall(0.7, 0.5, true)));
  EXPECT_GT(o.surface, 10000);
  EXPECT_LT(o.surface, 320 * 240 * 3 / 4);
  EXPECT_GT(o.added, 0);
  EXPECT_EQ(o.added_sky, 0);
}

}  // namespace
}  // namespace wild_mvs
