// Copyright wild_mvs authors. Tests of the synthetic-scene renderer that all
// algorithm tests build on: its ground truth must be exact.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <opencv2/imgproc.hpp>
#include <vector>

#include "synthetic_scene.h"
#include "test_paths.h"
#include "wild_mvs/core/error.h"
#include "wild_mvs/core/image.h"
#include "wild_mvs/io/colmap.h"
#include "wild_mvs/io/image_files.h"
#include "wild_mvs/io/pfm.h"

namespace wild_mvs {
namespace testing {
namespace {

// Rendered once and shared by the tests (rendering is deterministic).
const SyntheticScene& Cluttered() {
  static const SyntheticScene s = Render(ClutteredSceneSpec(false, false));
  return s;
}

const SyntheticScene& Slanted() {
  static const SyntheticScene s = Render(SlantedPlaneSpec(30, 5));
  return s;
}

// Bilinear interpolation of inverse depth at pixel coordinates px (exact for
// planar surfaces) when all four neighbours belong to object `id`.
bool InterpDepth(const SyntheticScene& s, int view, const Eigen::Vector2d& px,
                 int id, double* z) {
  const double x = px.x() - 0.5, y = px.y() - 0.5;
  const int c0 = static_cast<int>(std::floor(x)),
            r0 = static_cast<int>(std::floor(y));
  const cv::Mat& d = s.depth[view];
  if (c0 < 0 || r0 < 0 || c0 + 1 >= d.cols || r0 + 1 >= d.rows) return false;
  const double fx = x - c0, fy = y - r0;
  double inv = 0;
  for (int k = 0; k < 4; ++k) {
    const int r = r0 + (k >> 1), c = c0 + (k & 1);
    if (s.object_id[view].at<int>(r, c) != id) return false;
    const double w = ((k & 1) ? fx : 1 - fx) * ((k >> 1) ? fy : 1 - fy);
    inv += w / d.at<float>(r, c);
  }
  *z = 1.0 / inv;
  return true;
}

TEST(Synthetic, CamerasFollowTheConventions) {
  const SyntheticScene& s = Cluttered();
  ASSERT_EQ(s.scene.views.size(), 8u);
  for (size_t i = 0; i < s.scene.views.size(); ++i) {
    const View& v = s.scene.views[i];
    char name[32];
    std::snprintf(name, sizeof(name), "view_%03zu.png", i);
    EXPECT_EQ(v.name, name);
    EXPECT_TRUE(v.image_path.empty());
    const Camera& c = v.camera;
    EXPECT_NO_THROW(c.Validate(v.name));
    EXPECT_EQ(c.cx, 160.0);
    EXPECT_EQ(c.cy, 120.0);
    EXPECT_EQ(c.fx, 300.0);
    // The look-at point projects to the image centre.
    Eigen::Vector2d px;
    ASSERT_TRUE(c.Project(s.spec.look_at, &px));
    EXPECT_NEAR(px.x(), 160.0, 1e-9);
    EXPECT_NEAR(px.y(), 120.0, 1e-9);
    // Image x is horizontal and world up is image up.
    EXPECT_NEAR(c.R.row(0).z(), 0.0, 1e-12);
    Eigen::Vector2d above;
    ASSERT_TRUE(c.Project(s.spec.look_at + Eigen::Vector3d(0, 0, 0.2), &above));
    EXPECT_LT(above.y(), px.y() - 5);
    EXPECT_NEAR(above.x(), px.x(), 1e-9);
    EXPECT_NEAR((c.Center() - s.spec.camera_centers[i]).norm(), 0, 1e-12);
  }
  EXPECT_GT(s.scene_size, 3.0);
  EXPECT_LT(s.scene_size, 7.0);
}

TEST(Synthetic, RingCameras) {
  const auto ring = MakeRingCameras(4, 2.0, 0.5);
  ASSERT_EQ(ring.size(), 4u);
  EXPECT_NEAR((ring[0] - Eigen::Vector3d(0, -2, 0.5)).norm(), 0, 1e-12);
  EXPECT_NEAR((ring[1] - Eigen::Vector3d(2, 0, 0.5)).norm(), 0, 1e-12);
  EXPECT_NEAR((ring[2] - Eigen::Vector3d(0, 2, 0.5)).norm(), 0, 1e-12);
  const auto arc = MakeRingCameras(3, 1.0, 0.0, 90);
  EXPECT_NEAR(
      (arc[0] - Eigen::Vector3d(-std::sqrt(0.5), -std::sqrt(0.5), 0)).norm(), 0,
      1e-12);
  EXPECT_NEAR((arc[1] - Eigen::Vector3d(0, -1, 0)).norm(), 0, 1e-12);
  EXPECT_THROW(MakeRingCameras(0, 1, 0), Error);
}

TEST(Synthetic, ImagesAreFloatRgbInRangeAndCovered) {
  const SyntheticScene& s = Cluttered();
  for (size_t i = 0; i < s.images.size(); ++i) {
    ASSERT_EQ(s.images[i].type(), CV_32FC3);
    ASSERT_EQ(s.depth[i].type(), CV_32F);
    ASSERT_EQ(s.normals[i].type(), CV_32FC3);
    ASSERT_EQ(s.images[i].size(), cv::Size(320, 240));
    double lo, hi;
    cv::minMaxLoc(s.images[i].reshape(1), &lo, &hi);
    EXPECT_GE(lo, 0.0);
    EXPECT_LE(hi, 1.0);
    // Most of the image sees the scene.
    EXPECT_GT(cv::countNonZero(s.depth[i]), 320 * 240 * 6 / 10);
    // Background: depth 0, black, id -1.
    for (int r = 0; r < 240; ++r)
      for (int c = 0; c < 320; ++c)
        if (s.depth[i].at<float>(r, c) == 0.f) {
          ASSERT_EQ(s.object_id[i].at<int>(r, c), -1);
        }
  }
  // Slanted plane fills every view completely.
  for (const cv::Mat& d : Slanted().depth)
    EXPECT_EQ(cv::countNonZero(d), 320 * 240);
}

TEST(Synthetic, TextureIsRichEnoughForStereoWindows) {
  // Standard deviation of the grey value in 5x5 windows, relative to the
  // window mean, over surface pixels: strong contrast at a few pixels.
  for (const SyntheticScene* s : {&Cluttered(), &Slanted()}) {
    for (size_t i = 0; i < s->images.size(); ++i) {
      cv::Mat g;
      cv::cvtColor(s->images[i], g, cv::COLOR_RGB2GRAY);
      cv::Mat mean, sq;
      cv::blur(g, mean, cv::Size(5, 5));
      cv::blur(g.mul(g), sq, cv::Size(5, 5));
      int total = 0, textured = 0;
      for (int r = 2; r < g.rows - 2; ++r)
        for (int c = 2; c < g.cols - 2; ++c) {
          if (s->depth[i].at<float>(r, c) == 0.f) continue;
          const double m = mean.at<float>(r, c);
          const double var = sq.at<float>(r, c) - m * m;
          ++total;
          if (std::sqrt(std::max(0.0, var)) > 0.08 * m) ++textured;
        }
      EXPECT_GT(textured, 0.9 * total) << "view " << i;
    }
  }
}

// Grey value at continuous pixel coordinates (bilinear).
double GreyAt(const cv::Mat& img, double x, double y) {
  const double gx = x - 0.5, gy = y - 0.5;
  const int c0 = static_cast<int>(std::floor(gx)),
            r0 = static_cast<int>(std::floor(gy));
  const double fx = gx - c0, fy = gy - r0;
  auto g = [&](int r, int c) {
    r = std::clamp(r, 0, img.rows - 1);
    c = std::clamp(c, 0, img.cols - 1);
    const cv::Vec3f v = img.at<cv::Vec3f>(r, c);
    return (v[0] + v[1] + v[2]) / 3.0;
  };
  return (1 - fy) * ((1 - fx) * g(r0, c0) + fx * g(r0, c0 + 1)) +
         fy * ((1 - fx) * g(r0 + 1, c0) + fx * g(r0 + 1, c0 + 1));
}

// NCC of a 5x5 window at pi in view i against its image in view j through
// the tangent plane (X, n) shifted by `shift` pixels in view j.
double NccWarped(const SyntheticScene& s, int i, int j,
                 const Eigen::Vector2d& pi, const Eigen::Vector3d& X,
                 const Eigen::Vector3d& n, const Eigen::Vector2d& shift) {
  const Camera& ci = s.scene.views[i].camera;
  const Camera& cj = s.scene.views[j].camera;
  double sa = 0, sb = 0, saa = 0, sbb = 0, sab = 0;
  for (int dy = -2; dy <= 2; ++dy)
    for (int dx = -2; dx <= 2; ++dx) {
      const Eigen::Vector2d q = pi + Eigen::Vector2d(dx, dy);
      const Eigen::Vector3d ray = ci.RayWorld(q);
      const double t = n.dot(X - ci.Center()) / n.dot(ray);
      Eigen::Vector2d qj;
      cj.Project(ci.Center() + t * ray, &qj);
      qj += shift;
      const double va = GreyAt(s.images[i], q.x(), q.y());
      const double vb = GreyAt(s.images[j], qj.x(), qj.y());
      sa += va;
      sb += vb;
      saa += va * va;
      sbb += vb * vb;
      sab += va * vb;
    }
  const double cnt = 25;
  const double cov = sab - sa * sb / cnt;
  const double var = (saa - sa * sa / cnt) * (sbb - sb * sb / cnt);
  return var > 0 ? cov / std::sqrt(var) : 0;
}

void CheckUniqueMatches(const SyntheticScene& s, int step) {
  int tried = 0, unique = 0, high = 0;
  const int n = static_cast<int>(s.images.size());
  for (int i = 0; i + 1 < n; i += step) {
    const int j = i + 1;
    const Camera& ci = s.scene.views[i].camera;
    const Camera& cj = s.scene.views[j].camera;
    for (int r = 20; r < ci.height - 20; r += 14)
      for (int c = 20; c < ci.width - 20; c += 14) {
        const float z = s.depth[i].at<float>(r, c);
        if (z == 0.f) continue;
        const Eigen::Vector2d pi(c + 0.5, r + 0.5);
        const Eigen::Vector3d X = ci.Backproject(pi, z);
        Eigen::Vector2d pj, pf;
        if (!cj.Project(X, &pj) || !cj.InImage(pj, 50)) continue;
        double zj;
        if (!InterpDepth(s, j, pj, s.object_id[i].at<int>(r, c), &zj) ||
            std::abs(zj - cj.Depth(X)) > 1e-3 * zj)
          continue;  // occluded in j
        cj.Project(ci.Backproject(pi, z * 1.05), &pf);
        const Eigen::Vector2d dir = (pf - pj).normalized();
        const cv::Vec3f nc = s.normals[i].at<cv::Vec3f>(r, c);
        const Eigen::Vector3d nw =
            ci.R.transpose() * Eigen::Vector3d(nc[0], nc[1], nc[2]);
        const double best =
            NccWarped(s, i, j, pi, X, nw, Eigen::Vector2d::Zero());
        double other = -1;
        for (int k = 3; k <= 40; ++k)
          for (int sign : {-1, 1})
            other =
                std::max(other, NccWarped(s, i, j, pi, X, nw, sign * k * dir));
        ++tried;
        unique += best > other;
        high += best > 0.8;
      }
  }
  ASSERT_GT(tried, 250);
  std::printf("unique best match %d / %d, NCC > 0.8 %d / %d\n", unique, tried,
              high, tried);
  EXPECT_GT(unique, 0.9 * tried);
  EXPECT_GT(high, 0.8 * tried);
}

TEST(Synthetic, TextureMatchesUniquelyAlongEpipolarLines) {
  // For stereo: a 5x5 window at the true correspondence correlates better
  // than anywhere else 3..40 px away along the epipolar line, despite the
  // lighting changes between views (NCC is invariant to gain and offset).
  SyntheticSpec plane = SlantedPlaneSpec(30, 5);
  plane.lighting = ClutteredSceneSpec(true, false).lighting;
  plane.lighting.resize(5);
  plane.num_sparse_points = 0;
  CheckUniqueMatches(Render(plane), 1);
  SyntheticSpec clutter = ClutteredSceneSpec(true, false, 105);
  clutter.num_sparse_points = 0;
  CheckUniqueMatches(Render(clutter), 2);
}

void CheckReprojection(const SyntheticScene& s, int i, int j,
                       double min_agree) {
  const Camera& ci = s.scene.views[i].camera;
  const Camera& cj = s.scene.views[j].camera;
  int visible = 0, agree = 0, occluded = 0;
  for (int r = 0; r < ci.height; r += 2) {
    for (int c = 0; c < ci.width; c += 2) {
      const float z = s.depth[i].at<float>(r, c);
      if (z == 0.f) continue;
      const int id = s.object_id[i].at<int>(r, c);
      const Eigen::Vector3d X = ci.Backproject({c + 0.5, r + 0.5}, z);
      const cv::Vec3f nc = s.normals[i].at<cv::Vec3f>(r, c);
      const Eigen::Vector3d nw =
          ci.R.transpose() * Eigen::Vector3d(nc[0], nc[1], nc[2]);
      Eigen::Vector2d px;
      if (!cj.Project(X, &px) || !cj.InImage(px, 1)) continue;
      // Self-occlusion of convex objects: the surface must face view j.
      if (nw.dot(cj.Center() - X) <= 0) continue;
      double zj;
      if (!InterpDepth(s, j, px, id, &zj)) {
        // Another object in front (or the background / an edge).
        const int idj = s.object_id[j].at<int>(static_cast<int>(px.y()),
                                               static_cast<int>(px.x()));
        if (idj >= 0 && idj != id &&
            s.depth[j].at<float>(static_cast<int>(px.y()),
                                 static_cast<int>(px.x())) < cj.Depth(X) * 0.98)
          ++occluded;
        continue;
      }
      ++visible;
      if (std::abs(zj - cj.Depth(X)) < 1e-4 * zj) ++agree;
    }
  }
  EXPECT_GT(visible, 2000) << i << "->" << j;
  EXPECT_GE(agree, min_agree * visible) << i << "->" << j;
  if (&s == &Cluttered()) {
    EXPECT_GT(occluded, 50) << i << "->" << j;
  }
}

TEST(Synthetic, GroundTruthDepthReprojectsBetweenViews) {
  for (int i = 0; i < 8; ++i)
    CheckReprojection(Cluttered(), i, (i + 1) % 8, 0.97);
  for (int j = 1; j < 5; ++j) CheckReprojection(Slanted(), 0, j, 0.999);
}

TEST(Synthetic, NormalsAreUnitFacingAndMatchDepthGradients) {
  for (const SyntheticScene* s : {&Cluttered(), &Slanted()}) {
    for (size_t i = 0; i < s->images.size(); ++i) {
      const Camera& cam = s->scene.views[i].camera;
      std::vector<double> angles;
      for (int r = 1; r + 1 < cam.height; ++r) {
        for (int c = 1; c + 1 < cam.width; ++c) {
          const float z = s->depth[i].at<float>(r, c);
          if (z == 0.f) continue;
          const cv::Vec3f nv = s->normals[i].at<cv::Vec3f>(r, c);
          const Eigen::Vector3d n(nv[0], nv[1], nv[2]);
          ASSERT_NEAR(n.norm(), 1.0, 1e-5);
          const Eigen::Vector3d X = cam.BackprojectCam({c + 0.5, r + 0.5}, z);
          ASSERT_LT(n.dot(X), 0.0) << "normal faces away at " << c << "," << r;
          // Normal from the depth gradient (central differences) where the
          // 3x3 neighbourhood is one object.
          const int id = s->object_id[i].at<int>(r, c);
          bool same = true;
          for (int dr = -1; dr <= 1; ++dr)
            for (int dc = -1; dc <= 1; ++dc)
              same &= s->object_id[i].at<int>(r + dr, c + dc) == id;
          if (!same) continue;
          auto P = [&](int cc, int rr) {
            return cam.BackprojectCam({cc + 0.5, rr + 0.5},
                                      s->depth[i].at<float>(rr, cc));
          };
          Eigen::Vector3d g =
              (P(c + 1, r) - P(c - 1, r)).cross(P(c, r + 1) - P(c, r - 1));
          if (g.norm() == 0) continue;
          g.normalize();
          if (g.dot(X) > 0) g = -g;
          angles.push_back(std::acos(std::clamp(g.dot(n), -1.0, 1.0)) * 180 /
                           M_PI);
        }
      }
      ASSERT_GT(angles.size(), 1000u);
      std::sort(angles.begin(), angles.end());
      EXPECT_LT(angles[angles.size() / 2], 0.5) << "view " << i;
      EXPECT_LT(angles[angles.size() * 9 / 10], 3.0) << "view " << i;
    }
  }
}

TEST(Synthetic, SparsePointsProjectToTheirObservations) {
  const SyntheticScene& s = Cluttered();
  ASSERT_EQ(s.scene.points.size(), 300u);
  EXPECT_NO_THROW(s.scene.Validate());
  int checked = 0, on_surface = 0;
  for (const SparsePoint& p : s.scene.points) {
    ASSERT_GE(p.track.size(), 2u);
    for (const Observation& o : p.track) {
      const Camera& cam = s.scene.views[o.view].camera;
      Eigen::Vector2d px;
      ASSERT_TRUE(cam.Project(p.xyz, &px));
      EXPECT_LT((px - o.xy).norm(), 1e-9);
      EXPECT_TRUE(cam.InImage(o.xy));
      EXPECT_EQ(o.scale, 2.0);
      // Visible: its depth matches the ground-truth depth at that pixel.
      const float zg = s.depth[o.view].at<float>(static_cast<int>(o.xy.y()),
                                                 static_cast<int>(o.xy.x()));
      ++checked;
      if (std::abs(zg - cam.Depth(p.xyz)) < 0.01 * zg) ++on_surface;
    }
  }
  EXPECT_GT(on_surface, 0.95 * checked);

  // With observation noise, the reprojection error has the requested sigma.
  SyntheticSpec spec = ClutteredSceneSpec(false, false);
  spec.width = 160;
  spec.height = 120;
  spec.focal = 150;
  spec.supersample = 1;
  spec.sparse_pixel_noise = 0.5;
  spec.num_sparse_points = 400;
  const SyntheticScene noisy = Render(spec);
  double sq = 0;
  int n = 0;
  for (const SparsePoint& p : noisy.scene.points)
    for (const Observation& o : p.track) {
      Eigen::Vector2d px;
      noisy.scene.views[o.view].camera.Project(p.xyz, &px);
      sq += (px - o.xy).squaredNorm();
      n += 2;
    }
  ASSERT_GT(n, 1000);
  EXPECT_NEAR(std::sqrt(sq / n), 0.5, 0.05);
}

TEST(Synthetic, LightingChangesImagesExactlyAsSpecified) {
  SyntheticSpec base = ClutteredSceneSpec(false, false);
  base.width = 160;
  base.height = 120;
  base.focal = 150;
  base.quantize = false;
  base.num_sparse_points = 0;
  SyntheticSpec lit = ClutteredSceneSpec(true, false);
  lit.width = 160;
  lit.height = 120;
  lit.focal = 150;
  lit.quantize = false;
  lit.num_sparse_points = 0;
  ASSERT_EQ(lit.lighting.size(), 8u);
  const SyntheticScene a = Render(base), b = Render(lit);
  double min_exp = 1e9, max_exp = 0, max_gamma = 0;
  for (int i = 0; i < 8; ++i) {
    const ViewLighting& l = lit.lighting[i];
    min_exp = std::min(min_exp, l.exposure);
    max_exp = std::max(max_exp, l.exposure);
    max_gamma = std::max(max_gamma, l.gamma);
    double max_err = 0;
    for (int r = 0; r < a.images[i].rows; ++r)
      for (int c = 0; c < a.images[i].cols; ++c) {
        const cv::Vec3f L = a.images[i].at<cv::Vec3f>(r, c);
        const cv::Vec3f v = b.images[i].at<cv::Vec3f>(r, c);
        for (int k = 0; k < 3; ++k) {
          const double want = std::pow(
              std::clamp(l.exposure * l.white_balance[k] * L[k], 0.0, 1.0),
              1.0 / l.gamma);
          max_err = std::max(max_err, std::abs(want - v[k]));
        }
      }
    EXPECT_LT(max_err, 1e-5) << "view " << i;
    // Geometry does not change with lighting.
    EXPECT_EQ(cv::norm(a.depth[i], b.depth[i], cv::NORM_INF), 0.0);
  }
  EXPECT_LE(min_exp, 0.5);
  EXPECT_GE(max_exp, 2.0);
  EXPECT_GE(max_gamma, 2.0);

  // Quantisation: values are 8-bit sRGB levels; noise has the given sigma.
  SyntheticSpec q = base;
  q.quantize = true;
  q.camera_centers.resize(1);
  const SyntheticScene qs = Render(q);
  double max_level_err = 0, max_diff = 0;
  for (int r = 0; r < qs.images[0].rows; ++r)
    for (int c = 0; c < qs.images[0].cols; ++c)
      for (int k = 0; k < 3; ++k) {
        const double v = qs.images[0].at<cv::Vec3f>(r, c)[k];
        const double s = LinearToSrgb(static_cast<float>(v)) * 255.0;
        max_level_err = std::max(max_level_err, std::abs(s - std::round(s)));
        max_diff = std::max(max_diff,
                            std::abs(v - a.images[0].at<cv::Vec3f>(r, c)[k]));
      }
  EXPECT_LT(max_level_err, 1e-3);
  EXPECT_LT(max_diff, 0.01);
  EXPECT_GT(max_diff, 0.0);

  SyntheticSpec noisy = q;
  noisy.quantize = false;
  noisy.noise_sigma = 0.01;
  const SyntheticScene ns = Render(noisy);
  // Away from the clamping at 0 and 1 the noise is unbiased.
  double sum = 0, sum2 = 0;
  int count = 0;
  for (int r = 0; r < ns.images[0].rows; ++r)
    for (int c = 0; c < ns.images[0].cols; ++c)
      for (int k = 0; k < 3; ++k) {
        const double v0 = a.images[0].at<cv::Vec3f>(r, c)[k];
        if (v0 < 0.05 || v0 > 0.95) continue;
        const double d = ns.images[0].at<cv::Vec3f>(r, c)[k] - v0;
        sum += d;
        sum2 += d * d;
        ++count;
      }
  ASSERT_GT(count, 10000);
  const double mean = sum / count;
  EXPECT_NEAR(std::sqrt(sum2 / count - mean * mean), 0.01, 0.001);
  EXPECT_NEAR(mean, 0.0, 0.0005);
}

TEST(Synthetic, OneViewOccluderAppearsOnlyInItsView) {
  SyntheticSpec with = ClutteredSceneSpec(false, true);
  SyntheticSpec without = ClutteredSceneSpec(false, false);
  for (SyntheticSpec* s : {&with, &without}) {
    s->width = 160;
    s->height = 120;
    s->focal = 150;
  }
  const SyntheticScene a = Render(with), b = Render(without);
  const int occ = static_cast<int>(with.objects.size()) - 1;
  ASSERT_EQ(with.objects[occ].only_in_view, 0);
  const int occ_pixels = cv::countNonZero(a.object_id[0] == occ);
  EXPECT_GT(occ_pixels, 160 * 120 / 50);
  EXPECT_LT(occ_pixels, 160 * 120 / 3);
  // In view 0 the occluder is in front of the scene; elsewhere view 0 equals
  // the unoccluded render.
  for (int r = 0; r < 120; ++r)
    for (int c = 0; c < 160; ++c) {
      if (a.object_id[0].at<int>(r, c) == occ) {
        EXPECT_LT(a.depth[0].at<float>(r, c), b.depth[0].at<float>(r, c) == 0
                                                  ? 1e9f
                                                  : b.depth[0].at<float>(r, c));
      } else {
        ASSERT_EQ(a.depth[0].at<float>(r, c), b.depth[0].at<float>(r, c));
      }
    }
  for (int i = 1; i < 8; ++i) {
    EXPECT_EQ(cv::countNonZero(a.object_id[i] == occ), 0);
    EXPECT_EQ(cv::norm(a.depth[i], b.depth[i], cv::NORM_INF), 0.0);
    EXPECT_EQ(cv::norm(a.images[i], b.images[i], cv::NORM_INF), 0.0);
  }
  // Neither the sparse points nor the ground-truth cloud contain it.
  const SyntheticObject& o = with.objects[occ];
  auto inside = [&](const Eigen::Vector3d& X) {
    const Eigen::Vector3d l = o.rotation.transpose() * (X - o.center);
    return (l.cwiseAbs().array() <= o.size.array() + 1e-4).all();
  };
  for (const SparsePoint& p : a.scene.points) EXPECT_FALSE(inside(p.xyz));
  const PointCloud gt = a.GroundTruthCloud(1);
  for (const Eigen::Vector3f& X : gt.xyz)
    ASSERT_FALSE(inside(X.cast<double>()));
  EXPECT_LT(gt.size(), b.GroundTruthCloud(1).size());
}

TEST(Synthetic, GroundTruthCloudLiesOnTheSurface) {
  const SyntheticScene& s = Slanted();
  const PointCloud cloud = s.GroundTruthCloud(4);
  ASSERT_EQ(cloud.size(), 5u * 80 * 60);
  ASSERT_EQ(cloud.normal.size(), cloud.size());
  ASSERT_EQ(cloud.rgb.size(), cloud.size());
  const SyntheticObject& p = s.spec.objects[0];
  const Eigen::Vector3d n = p.axis_u.cross(p.axis_v).normalized();
  for (size_t k = 0; k < cloud.size(); ++k) {
    const Eigen::Vector3d X = cloud.xyz[k].cast<double>();
    ASSERT_NEAR((X - p.center).dot(n), 0.0, 1e-5);
    // Normal = plane normal, oriented towards the cameras (at -y).
    ASSERT_NEAR(std::abs(cloud.normal[k].cast<double>().dot(n)), 1.0, 1e-5);
    ASSERT_LT(cloud.normal[k].y(), 0.f);
  }
}

TEST(Synthetic, LoaderServesTheImages) {
  const SyntheticScene& s = Slanted();
  ImageCache cache(s.Loader(), 64);
  for (int i = 0; i < 5; ++i) {
    auto img = cache.Get(i);
    EXPECT_EQ(cv::norm(*img, s.images[i], cv::NORM_INF), 0.0);
  }
  EXPECT_THROW(cache.Get(5), Error);
}

TEST(Synthetic, WriteDatasetRoundTrips) {
  SyntheticSpec spec = SlantedPlaneSpec(25, 3);
  spec.width = 96;
  spec.height = 64;
  spec.focal = 90;
  spec.num_sparse_points = 50;
  const SyntheticScene s = Render(spec);
  const std::string dir = MakeTempDir("synthetic_dataset");
  WriteDataset(s, dir);
  const Scene back = ReadColmapModel(dir + "/sparse", dir + "/images");
  ASSERT_EQ(back.views.size(), 3u);
  ASSERT_EQ(back.points.size(), s.scene.points.size());
  for (int i = 0; i < 3; ++i) {
    const View& v = back.views[i];
    EXPECT_EQ(v.name, s.scene.views[i].name);
    const Camera& a = v.camera;
    const Camera& b = s.scene.views[i].camera;
    EXPECT_NEAR((a.K() - b.K()).norm(), 0, 1e-9);
    EXPECT_NEAR((a.R - b.R).norm(), 0, 1e-9);
    EXPECT_NEAR((a.t - b.t).norm(), 0, 1e-9);
    // Images: the 8-bit sRGB PNG loads back to exactly the rendered image.
    const cv::Mat img = LoadViewImage(v, ImageOptions());
    EXPECT_LT(cv::norm(img, s.images[i], cv::NORM_INF), 1e-6);
    const cv::Mat d = ReadPfm(dir + "/gt_depth/" + v.Stem() + ".pfm");
    EXPECT_EQ(cv::norm(d, s.depth[i], cv::NORM_INF), 0.0);
  }
  for (size_t k = 0; k < back.points.size(); ++k) {
    EXPECT_NEAR((back.points[k].xyz - s.scene.points[k].xyz).norm(), 0, 1e-9);
    ASSERT_EQ(back.points[k].track.size(), s.scene.points[k].track.size());
    EXPECT_NEAR(
        (back.points[k].track[0].xy - s.scene.points[k].track[0].xy).norm(), 0,
        1e-6);
  }
  std::filesystem::remove_all(dir);
}

TEST(Synthetic, BadSpecsAreRejected) {
  SyntheticSpec s = SlantedPlaneSpec();
  s.width = 0;
  EXPECT_THROW(Render(s), Error);
  s = SlantedPlaneSpec();
  s.lighting.resize(2);
  EXPECT_THROW(Render(s), Error);
  s = SlantedPlaneSpec();
  s.objects[0].texture_scale = 0;
  EXPECT_THROW(Render(s), Error);
  s = SlantedPlaneSpec();
  s.camera_centers.clear();
  EXPECT_THROW(Render(s), Error);
}

}  // namespace
}  // namespace testing
}  // namespace wild_mvs
