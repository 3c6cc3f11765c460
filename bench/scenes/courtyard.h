// Copyright wild_mvs authors. The rendered courtyard of the benchmark scenes
// (make_scene, make_collection): a textured ground, a back wall, boxes,
// spheres and a pillar under a sky; cameras look at kCourtyardLookAt from
// the side of negative y (in front of the wall).
#pragma once

#include <Eigen/Geometry>
#include <cmath>
#include <vector>

#include "synthetic_scene.h"

namespace wild_mvs {
namespace courtyard {

using testing::SyntheticObject;
using T = SyntheticObject::Type;

inline SyntheticObject Plane(Eigen::Vector3d c, Eigen::Vector3d u,
                             Eigen::Vector3d v, double hu, double hv, int seed,
                             double tex) {
  SyntheticObject o;
  o.type = T::kPlane;
  o.center = c;
  o.axis_u = u;
  o.axis_v = v;
  o.size = Eigen::Vector3d(hu, hv, 1);
  o.texture_seed = seed;
  o.texture_scale = tex;
  return o;
}

inline SyntheticObject Box(Eigen::Vector3d c, Eigen::Vector3d half,
                           double yaw_deg, int seed, double tex) {
  SyntheticObject o;
  o.type = T::kBox;
  o.center = c;
  o.size = half;
  o.rotation = Eigen::AngleAxisd(yaw_deg * M_PI / 180, Eigen::Vector3d::UnitZ())
                   .toRotationMatrix();
  o.texture_seed = seed;
  o.texture_scale = tex;
  return o;
}

inline SyntheticObject Sphere(Eigen::Vector3d c, double r, int seed,
                              double tex) {
  SyntheticObject o;
  o.type = T::kSphere;
  o.center = c;
  o.size = Eigen::Vector3d(r, r, r);
  o.texture_seed = seed;
  o.texture_scale = tex;
  return o;
}

// The persistent objects (seen in every view).
inline std::vector<SyntheticObject> Objects() {
  const Eigen::Vector3d X(1, 0, 0), Y(0, 1, 0), Z(0, 0, 1);
  std::vector<SyntheticObject> o;
  o.push_back(Plane({0, 0, 0}, X, Y, 3.0, 3.0, 11, 0.06));      // ground
  o.push_back(Plane({0, 1.6, 0.9}, X, Z, 2.4, 0.9, 12, 0.08));  // wall
  o.push_back(Box({0.55, 0.35, 0.25}, {0.28, 0.22, 0.25}, 30, 21, 0.05));
  o.push_back(Box({-0.6, -0.2, 0.2}, {0.2, 0.3, 0.2}, -20, 31, 0.05));
  o.push_back(Box({-0.2, 0.9, 0.5}, {0.12, 0.12, 0.5}, 10, 32, 0.04));
  o.push_back(Sphere({-0.1, 0.5, 0.3}, 0.3, 41, 0.05));
  o.push_back(Sphere({0.9, -0.4, 0.15}, 0.15, 42, 0.04));
  return o;
}

inline Eigen::Vector3d LookAt() { return Eigen::Vector3d(0, 0.3, 0.35); }

}  // namespace courtyard
}  // namespace wild_mvs
