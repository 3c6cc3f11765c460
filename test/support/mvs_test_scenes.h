// Copyright wild_mvs authors. Constructed scenes shared by the MVS unit
// tests: a rendered slanted plane under changing exposure and white
// balance, and pinhole cameras looking at a point.
#pragma once

#include <Eigen/Geometry>
#include <cmath>

#include "synthetic_scene.h"
#include "wild_mvs/core/camera.h"

namespace wild_mvs {
namespace testing {

// Slanted plane seen by 5 cameras with different exposure and white balance
// (linear: gamma 1), so the colour scale of view V w.r.t. R is exactly
// (e_R wb_R[c]) / (e_V wb_V[c]).
inline SyntheticSpec LitPlaneSpec() {
  SyntheticSpec spec = SlantedPlaneSpec(30, 5);
  spec.width = 240;
  spec.height = 180;
  spec.focal = 240;
  spec.num_sparse_points = 50;
  const double e[5] = {1.0, 0.6, 1.4, 0.8, 1.2};
  const double wb[5][3] = {{1.0, 1.0, 1.0},
                           {1.25, 1.0, 0.8},
                           {0.8, 1.05, 1.2},
                           {1.1, 0.9, 1.0},
                           {0.9, 1.0, 1.15}};
  for (int k = 0; k < 5; ++k) {
    ViewLighting l;
    l.exposure = e[k];
    l.white_balance = Eigen::Vector3d(wb[k][0], wb[k][1], wb[k][2]);
    spec.lighting.push_back(l);
  }
  return spec;
}

// A camera at c looking at target (world z up), focal `focal`, w x h.
inline Camera LookAtCamera(const Eigen::Vector3d& c,
                           const Eigen::Vector3d& target, double focal, int w,
                           int h) {
  Camera cam;
  cam.fx = cam.fy = focal;
  cam.cx = w / 2.0;
  cam.cy = h / 2.0;
  cam.width = w;
  cam.height = h;
  const Eigen::Vector3d f = (target - c).normalized();
  const Eigen::Vector3d r = f.cross(Eigen::Vector3d::UnitZ()).normalized();
  const Eigen::Vector3d d = f.cross(r);
  cam.R.row(0) = r.transpose();
  cam.R.row(1) = d.transpose();
  cam.R.row(2) = f.transpose();
  cam.t = -cam.R * c;
  return cam;
}

// A point on the circle of `radius` about the origin in the plane z = 0, at
// `deg` degrees from -y.
inline Eigen::Vector3d OnCircle(double deg, double radius) {
  const double a = deg * M_PI / 180.0;
  return Eigen::Vector3d(radius * std::sin(a), -radius * std::cos(a), 0);
}

}  // namespace testing
}  // namespace wild_mvs
