// Copyright wild_mvs authors. Analytic depth maps (sphere on a ground
// square, ring cameras) with exact ground truth for the fusion and meshing
// tests: depth and normals are ray-cast in closed form, so the surface
// distance of any fused point is exact.
#pragma once

#include <Eigen/Geometry>
#include <cmath>
#include <limits>
#include <memory>
#include <random>
#include <vector>

#include "wild_mvs/core/depth_map.h"

namespace wild_mvs {
namespace fusion_test {

struct AnalyticScene {
  Eigen::Vector3d sphere_center{0, 0, 0};
  double sphere_radius = 0.5;
  double ground_z = -0.5;    // ground square z = ground_z
  double ground_half = 1.2;  // |x|, |y| <= ground_half
  bool with_ground = true;
  int width = 240, height = 180;
  double focal = 220;
  double ring_radius = 3.0, ring_height = 1.5;

  double SceneSize() const {  // diameter of the bounding sphere
    return with_ground ? 2.0 * std::sqrt(2.0 * ground_half * ground_half + 0.25)
                       : 2.0 * sphere_radius;
  }

  Camera MakeCamera(int i, int n) const {
    const double a = 2.0 * M_PI * i / n;
    const Eigen::Vector3d C(ring_radius * std::cos(a),
                            ring_radius * std::sin(a), ring_height);
    const Eigen::Vector3d z = (sphere_center - C).normalized();
    const Eigen::Vector3d x = z.cross(Eigen::Vector3d::UnitZ()).normalized();
    const Eigen::Vector3d y = z.cross(x);
    Camera cam;
    cam.fx = cam.fy = focal;
    cam.cx = width / 2.0;
    cam.cy = height / 2.0;
    cam.width = width;
    cam.height = height;
    cam.R.row(0) = x.transpose();
    cam.R.row(1) = y.transpose();
    cam.R.row(2) = z.transpose();
    cam.t = -cam.R * C;
    return cam;
  }

  // Ray cast: returns the ray parameter (inf when missed) and world normal.
  double Cast(const Eigen::Vector3d& o, const Eigen::Vector3d& d,
              Eigen::Vector3d* n) const {
    double best = std::numeric_limits<double>::infinity();
    const Eigen::Vector3d oc = o - sphere_center;
    const double b = oc.dot(d),
                 c = oc.squaredNorm() - sphere_radius * sphere_radius;
    const double disc = b * b - c;
    if (disc >= 0) {
      const double t = -b - std::sqrt(disc);
      if (t > 0) {
        best = t;
        *n = (o + t * d - sphere_center).normalized();
      }
    }
    if (with_ground && std::abs(d.z()) > 1e-12) {
      const double t = (ground_z - o.z()) / d.z();
      const Eigen::Vector3d p = o + t * d;
      if (t > 0 && t < best && std::abs(p.x()) <= ground_half &&
          std::abs(p.y()) <= ground_half) {
        best = t;
        *n = Eigen::Vector3d(0, 0, o.z() > ground_z ? 1 : -1);
      }
    }
    return best;
  }

  // Exact distance of a point to the surface (sphere + ground square).
  double Distance(const Eigen::Vector3d& p) const {
    double d = std::abs((p - sphere_center).norm() - sphere_radius);
    if (with_ground) {
      const double dx = std::max(0.0, std::abs(p.x()) - ground_half);
      const double dy = std::max(0.0, std::abs(p.y()) - ground_half);
      const double dz = p.z() - ground_z;
      d = std::min(d, std::sqrt(dx * dx + dy * dy + dz * dz));
    }
    return d;
  }

  // Exact depth map of view i of n; `neighbors` = the 4 nearest ring views.
  DepthMap Render(int i, int n) const {
    DepthMap m;
    m.view = i;
    m.camera = MakeCamera(i, n);
    m.depth = cv::Mat(height, width, CV_32F, cv::Scalar(0));
    m.normal = cv::Mat(height, width, CV_32FC3, cv::Scalar(0, 0, 0));
    m.confidence = cv::Mat(height, width, CV_32F, cv::Scalar(0));
    const Eigen::Vector3d C = m.camera.Center();
    for (int r = 0; r < height; ++r)
      for (int c = 0; c < width; ++c) {
        const Eigen::Vector3d d = m.camera.RayWorld({c + 0.5, r + 0.5});
        Eigen::Vector3d nw = Eigen::Vector3d::UnitZ();
        const double t = Cast(C, d, &nw);
        if (!std::isfinite(t)) continue;
        const Eigen::Vector3d nc = m.camera.R * nw;
        m.depth.at<float>(r, c) = static_cast<float>(m.camera.Depth(C + t * d));
        m.normal.at<cv::Vec3f>(r, c) = cv::Vec3f(nc.x(), nc.y(), nc.z());
        m.confidence.at<float>(r, c) = 0.8f;
      }
    for (int k = 1; k <= 2; ++k) {
      m.neighbors.push_back((i + k) % n);
      m.neighbors.push_back((i - k + n) % n);
    }
    return m;
  }

  // Ground-truth samples: union over views of the exact depth maps, one per
  // `stride` pixels.
  std::vector<Eigen::Vector3d> GroundTruth(int n, int stride) const {
    std::vector<Eigen::Vector3d> pts;
    for (int i = 0; i < n; ++i) {
      const DepthMap m = Render(i, n);
      for (int r = 0; r < height; r += stride)
        for (int c = 0; c < width; c += stride) {
          const float z = m.depth.at<float>(r, c);
          if (z > 0) pts.push_back(m.camera.Backproject({c + 0.5, r + 0.5}, z));
        }
    }
    return pts;
  }
};

// Corrupts a map: relative Gaussian depth noise, normal noise (radians),
// and a fraction of outlier pixels with depth scaled by U(0.6, 1.4) and a
// random normal.
inline void Corrupt(DepthMap* m, double depth_noise, double normal_noise,
                    double outlier_fraction, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> g(0, 1);
  std::uniform_real_distribution<double> u(0, 1);
  for (int r = 0; r < m->depth.rows; ++r)
    for (int c = 0; c < m->depth.cols; ++c) {
      float& z = m->depth.at<float>(r, c);
      if (z <= 0) continue;
      cv::Vec3f& nv = m->normal.at<cv::Vec3f>(r, c);
      Eigen::Vector3d n(nv[0], nv[1], nv[2]);
      if (u(rng) < outlier_fraction) {
        z = static_cast<float>(z * (0.6 + 0.8 * u(rng)));
        n = Eigen::Vector3d(g(rng), g(rng), -std::abs(g(rng)) - 0.5);
      } else {
        z = static_cast<float>(z * (1.0 + depth_noise * g(rng)));
        n += normal_noise * Eigen::Vector3d(g(rng), g(rng), g(rng));
      }
      n.normalize();
      nv = cv::Vec3f(n.x(), n.y(), n.z());
    }
}

}  // namespace fusion_test
}  // namespace wild_mvs
