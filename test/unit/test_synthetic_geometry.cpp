// Copyright wild_mvs authors. Tests of the renderer's curved and relief
// objects (cylinders, displaced rectangles) and of its per-object texture
// contrast and overcast / ambient lighting: the ground truth must be that of
// the analytic surface the images show.
#include <gtest/gtest.h>

#include <cmath>
#include <opencv2/core.hpp>
#include <vector>

#include "synthetic_scene.h"
#include "wild_mvs/core/error.h"

namespace wild_mvs {
namespace testing {
namespace {

// Pixel-centre ray of view `i` (camera-frame z = 1) and the hit point at the
// ground-truth depth, in world coordinates.
Eigen::Vector3d RayDirection(const Camera& cam, int r, int c) {
  return cam.R.transpose() * Eigen::Vector3d((c + 0.5 - cam.cx) / cam.fx,
                                             (r + 0.5 - cam.cy) / cam.fy, 1);
}

Eigen::Vector3d WorldNormal(const SyntheticScene& s, int i, int r, int c) {
  const cv::Vec3f n = s.normals[i].at<cv::Vec3f>(r, c);
  return s.scene.views[i].camera.R.transpose() *
         Eigen::Vector3d(n[0], n[1], n[2]);
}

SyntheticSpec SmallSpec() {
  SyntheticSpec s;
  s.width = 160;
  s.height = 120;
  s.focal = 150;
  s.num_sparse_points = 0;
  return s;
}

TEST(SyntheticGeometry, CylinderDepthAndNormalsAreTheAnalyticSurface) {
  SyntheticSpec spec = SmallSpec();
  SyntheticObject cyl;
  cyl.type = SyntheticObject::Type::kCylinder;
  cyl.center = Eigen::Vector3d(0.1, -0.05, 0.2);
  cyl.size = Eigen::Vector3d(0.35, 0.35, 0.5);  // radius, -, half height
  spec.objects.push_back(cyl);
  // From the side, from above (sees the top cap) and from below.
  spec.camera_centers = {{0, -2.5, 0.3}, {1.2, -1.5, 1.8}, {-1.5, -1.2, -1.2}};
  spec.look_at = cyl.center;
  const SyntheticScene s = Render(spec);
  int side = 0, cap = 0;
  for (int i = 0; i < 3; ++i) {
    const Camera& cam = s.scene.views[i].camera;
    for (int r = 0; r < spec.height; ++r) {
      for (int c = 0; c < spec.width; ++c) {
        if (s.object_id[i].at<int>(r, c) != 0) continue;
        const double z = s.depth[i].at<float>(r, c);
        ASSERT_GT(z, 0);
        const Eigen::Vector3d d = RayDirection(cam, r, c);
        const Eigen::Vector3d q = cam.Center() + z * d - cyl.center;
        const double radial = std::hypot(q.x(), q.y());
        const Eigen::Vector3d n = WorldNormal(s, i, r, c);
        EXPECT_NEAR(n.norm(), 1.0, 1e-5);
        EXPECT_LT(n.dot(d), 0) << "normal must face the camera";
        // Depth is stored as float: ~1e-7 relative.
        const double tol = 3e-7 * z + 1e-9;
        if (std::abs(std::abs(q.z()) - 0.5) < tol) {  // a cap
          ++cap;
          EXPECT_LE(radial, 0.35 + tol);
          EXPECT_NEAR(std::abs(n.z()), 1.0, 1e-5);
          EXPECT_GT(n.z() * q.z(), 0);  // outward: the caps are seen outside
        } else {
          ++side;
          EXPECT_NEAR(radial, 0.35, tol);
          EXPECT_LE(std::abs(q.z()), 0.5 + tol);
          const Eigen::Vector3d radial_n =
              Eigen::Vector3d(q.x(), q.y(), 0).normalized();
          EXPECT_NEAR(n.dot(radial_n), 1.0, 1e-5);
        }
      }
    }
  }
  EXPECT_GT(side, 3000);
  EXPECT_GT(cap, 500);
  // An uncapped tube seen from above shows its inside: the normals there
  // face the camera, i.e. point to the axis.
  spec.objects[0].capped = false;
  spec.camera_centers = {{0.0, -1.0, 2.5}};
  const SyntheticScene open = Render(spec);
  const Camera& cam = open.scene.views[0].camera;
  int inside = 0;
  for (int r = 0; r < spec.height; ++r) {
    for (int c = 0; c < spec.width; ++c) {
      if (open.object_id[0].at<int>(r, c) != 0) continue;
      const double z = open.depth[0].at<float>(r, c);
      const Eigen::Vector3d q =
          cam.Center() + z * RayDirection(cam, r, c) - cyl.center;
      EXPECT_NEAR(std::hypot(q.x(), q.y()), 0.35, 3e-7 * z + 1e-9);
      const Eigen::Vector3d n = WorldNormal(open, 0, r, c);
      inside += n.dot(Eigen::Vector3d(q.x(), q.y(), 0)) < 0;
    }
  }
  EXPECT_GT(inside, 300);
}

TEST(SyntheticGeometry, ReliefDepthAndNormalsAreTheAnalyticSurface) {
  SyntheticSpec spec = SmallSpec();
  SyntheticObject relief;
  relief.type = SyntheticObject::Type::kRelief;
  relief.center = Eigen::Vector3d(0, 0, 0);
  relief.axis_u = Eigen::Vector3d(1, 0, 0);
  relief.axis_v = Eigen::Vector3d(0, 0, 1);  // a facade facing -y
  relief.size = Eigen::Vector3d(1.0, 0.7, 1);
  relief.relief_amplitude = 0.05;  // 2.5 % of its width
  relief.relief_scale = 0.3;
  relief.relief_seed = 4;
  spec.objects.push_back(relief);
  // Head-on and grazing (20 degrees from the facade's plane).
  spec.camera_centers = {{0.1, -2.2, 0.2},
                         {-2.0 * std::cos(0.35), -2.0 * std::sin(0.35), 0.1}};
  const SyntheticScene s = Render(spec);
  const Eigen::Vector3d U = relief.axis_u, V = relief.axis_v,
                        N = U.cross(V);  // -y
  double w_min = 1, w_max = -1;
  int pixels = 0;
  for (int i = 0; i < 2; ++i) {
    const Camera& cam = s.scene.views[i].camera;
    for (int r = 0; r < spec.height; ++r) {
      for (int c = 0; c < spec.width; ++c) {
        if (s.object_id[i].at<int>(r, c) != 0) continue;
        ++pixels;
        const double z = s.depth[i].at<float>(r, c);
        const Eigen::Vector3d d = RayDirection(cam, r, c);
        const Eigen::Vector3d q = cam.Center() + z * d - relief.center;
        const double u = q.dot(U), v = q.dot(V), w = q.dot(N);
        Eigen::Vector2d g;
        const double h = ReliefHeight(relief, u, v, &g);
        // On the surface (depth stored as float: 3e-7 z along the ray).
        EXPECT_NEAR(w, h, 3e-7 * z * (1 + g.norm()) + 1e-9);
        EXPECT_LE(std::abs(u), 1.0 + 1e-6);
        EXPECT_LE(std::abs(v), 0.7 + 1e-6);
        w_min = std::min(w_min, w);
        w_max = std::max(w_max, w);
        // The normal is that of the analytic gradient, unit, facing the
        // camera.
        const Eigen::Vector3d n = WorldNormal(s, i, r, c);
        const Eigen::Vector3d expected =
            (N - g.x() * U - g.y() * V).normalized();
        EXPECT_NEAR(n.norm(), 1.0, 1e-5);
        EXPECT_LT(n.dot(d), 0);
        EXPECT_NEAR(std::abs(n.dot(expected)), 1.0, 1e-5);
        // The nearest crossing: the ray stays on the camera's side of the
        // surface before the hit (sampled densely from the camera).
        if ((r * spec.width + c) % 7 == 0) {
          const Eigen::Vector3d o = cam.Center() - relief.center;
          double prev_sign = 0;
          for (int k = 1; k < 400; ++k) {
            const Eigen::Vector3d p = o + (z * k / 400.0) * d;
            const double f =
                p.dot(N) - ReliefHeight(relief, p.dot(U), p.dot(V));
            if (std::abs(p.dot(U)) > 1 || std::abs(p.dot(V)) > 0.7) continue;
            const double sign = f > 0 ? 1 : -1;
            if (prev_sign != 0) ASSERT_EQ(sign, prev_sign) << r << " " << c;
            prev_sign = sign;
          }
        }
      }
    }
  }
  EXPECT_GT(pixels, 10000);
  // The relief is not flat: it spans most of +-amplitude.
  EXPECT_GT(w_max - w_min, 0.06);
  EXPECT_LE(w_max, 0.05 + 1e-6);
  EXPECT_GE(w_min, -0.05 - 1e-6);
}

TEST(SyntheticGeometry, ReliefHeightGradientMatchesFiniteDifferences) {
  SyntheticObject relief;
  relief.type = SyntheticObject::Type::kRelief;
  relief.relief_amplitude = 0.1;
  relief.relief_scale = 0.5;
  relief.relief_seed = 9;
  for (const auto& uv : {Eigen::Vector2d(0.1, 0.2), Eigen::Vector2d(-0.7, 0.4),
                         Eigen::Vector2d(1.3, -0.9)}) {
    Eigen::Vector2d g;
    ReliefHeight(relief, uv.x(), uv.y(), &g);
    const double e = 1e-6;
    const double gu = (ReliefHeight(relief, uv.x() + e, uv.y()) -
                       ReliefHeight(relief, uv.x() - e, uv.y())) /
                      (2 * e);
    const double gv = (ReliefHeight(relief, uv.x(), uv.y() + e) -
                       ReliefHeight(relief, uv.x(), uv.y() - e)) /
                      (2 * e);
    EXPECT_NEAR(g.x(), gu, 1e-7);
    EXPECT_NEAR(g.y(), gv, 1e-7);
  }
  SyntheticObject plane;
  EXPECT_THROW(ReliefHeight(plane, 0, 0), Error);
}

// A ground plane and a wall seen by one camera, for the photometric tests.
SyntheticSpec GroundAndWall(double contrast) {
  SyntheticSpec spec = SmallSpec();
  SyntheticObject ground;
  ground.size = Eigen::Vector3d(2, 2, 1);
  ground.texture_contrast = contrast;
  SyntheticObject wall;
  wall.center = Eigen::Vector3d(0, 1, 0.5);
  wall.axis_u = Eigen::Vector3d(1, 0, 0);
  wall.axis_v = Eigen::Vector3d(0, 0, 1);
  wall.size = Eigen::Vector3d(2, 0.5, 1);
  wall.texture_seed = 5;
  wall.texture_contrast = contrast;
  spec.objects = {ground, wall};
  spec.camera_centers = {{0, -1.5, 1.2}};
  spec.look_at = Eigen::Vector3d(0, 0.4, 0.3);
  spec.quantize = false;
  spec.supersample = 1;
  return spec;
}

// Mean and standard deviation of the luminance of object `id`'s pixels.
void Stats(const SyntheticScene& s, int id, double* mean, double* sd) {
  double sum = 0, sum2 = 0;
  int n = 0;
  for (int r = 0; r < s.images[0].rows; ++r) {
    for (int c = 0; c < s.images[0].cols; ++c) {
      if (s.object_id[0].at<int>(r, c) != id) continue;
      const cv::Vec3f p = s.images[0].at<cv::Vec3f>(r, c);
      const double l = (p[0] + p[1] + p[2]) / 3;
      sum += l;
      sum2 += l * l;
      ++n;
    }
  }
  ASSERT_GT(n, 100);
  *mean = sum / n;
  *sd = std::sqrt(std::max(0.0, sum2 / n - *mean * *mean));
}

TEST(SyntheticGeometry, TextureContrastScalesTheAlbedoVariation) {
  const SyntheticScene full = Render(GroundAndWall(1.0));
  const SyntheticScene weak = Render(GroundAndWall(0.15));
  for (int id = 0; id < 2; ++id) {
    double m1, s1, m2, s2;
    Stats(full, id, &m1, &s1);
    Stats(weak, id, &m2, &s2);
    // The luminance deviation scales with the contrast (the clamp of the
    // full texture makes it not exactly linear).
    EXPECT_GT(s2, 0.08 * s1) << id;
    EXPECT_LT(s2, 0.22 * s1) << id;
    EXPECT_NEAR(m2, m1, 0.25 * m1) << id;
  }
}

TEST(SyntheticGeometry, OvercastLightsFromTheSkyAndIgnoresTheSun) {
  SyntheticSpec spec = GroundAndWall(1.0);
  ViewLighting l;
  l.overcast = true;
  l.ambient = 0.2;
  spec.lighting = {l};
  const SyntheticScene a = Render(spec);
  spec.lighting[0].sun = Eigen::Vector3d(0.3, -1, 0.5);
  const SyntheticScene b = Render(spec);
  EXPECT_EQ(cv::norm(a.images[0], b.images[0], cv::NORM_INF), 0.0);
  // Albedo without light: overcast with ambient 1 (factor 1 everywhere).
  spec.lighting[0].ambient = 1.0;
  const SyntheticScene albedo = Render(spec);
  for (int r = 0; r < spec.height; ++r) {
    for (int c = 0; c < spec.width; ++c) {
      const int id = a.object_id[0].at<int>(r, c);
      if (id < 0) continue;
      // Ground (up): 0.2 + 0.8 * 1; wall (horizontal normal): 0.2 + 0.8 / 2.
      const double factor = id == 0 ? 1.0 : 0.6;
      const cv::Vec3f pa = a.images[0].at<cv::Vec3f>(r, c);
      const cv::Vec3f p1 = albedo.images[0].at<cv::Vec3f>(r, c);
      for (int k = 0; k < 3; ++k) {
        if (p1[k] >= 1.f) continue;  // clamped
        ASSERT_NEAR(pa[k], factor * p1[k], 1e-5) << r << " " << c;
      }
    }
  }
  // With a sun, the shadowed ground keeps `ambient` of the albedo.
  spec.lighting[0] = ViewLighting();
  spec.lighting[0].ambient = 0.1;
  spec.lighting[0].sun = Eigen::Vector3d(0, 1, 0.2);  // behind the wall
  const SyntheticScene sun = Render(spec);
  int shadowed = 0;
  for (int r = 0; r < spec.height; ++r) {
    for (int c = 0; c < spec.width; ++c) {
      if (sun.object_id[0].at<int>(r, c) != 0) continue;
      const cv::Vec3f ps = sun.images[0].at<cv::Vec3f>(r, c);
      const cv::Vec3f p1 = albedo.images[0].at<cv::Vec3f>(r, c);
      if (std::abs(ps[0] - 0.1f * p1[0]) < 1e-5) ++shadowed;
    }
  }
  EXPECT_GT(shadowed, 500);
}

TEST(SyntheticGeometry, BadObjectsAndLightingAreRejected) {
  SyntheticSpec spec = GroundAndWall(1.0);
  spec.objects[0].texture_contrast = -0.1;
  EXPECT_THROW(Render(spec), Error);
  spec = GroundAndWall(1.0);
  spec.objects[0].type = SyntheticObject::Type::kRelief;
  spec.objects[0].relief_scale = 0;
  EXPECT_THROW(Render(spec), Error);
  spec = GroundAndWall(1.0);
  spec.lighting = {ViewLighting()};
  spec.lighting[0].ambient = 1.5;
  EXPECT_THROW(Render(spec), Error);
  spec = GroundAndWall(1.0);
  spec.look_ats = {Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero()};
  EXPECT_THROW(Render(spec), Error);
}

}  // namespace
}  // namespace testing
}  // namespace wild_mvs
