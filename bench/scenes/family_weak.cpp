// Copyright wild_mvs authors. The `weak` family: an indoor-like room whose
// walls, floor and ceiling carry 10 .. 20 % of the usual albedo variation,
// beside fully textured furniture, under mild lighting changes.
//
// Layout (world z up, metres; sizes, positions, textures jittered by the
// seed): a room ~6.4 x 5.4 x 2.7 m (floor, ceiling, four walls; weakly
// textured, each its own contrast in 0.10 .. 0.20 and its own feature
// size); a cabinet against the back wall, a table, a low chest (boxes), a
// round bin (a cylinder), a ball (a sphere) and a picture on a side wall
// (a textured rectangle just off the wall). Cameras: 14 views walking along
// the front of the room at eye height 1.2 .. 1.7 m, each looking at its own
// point that sweeps from the left wall over the back wall to the right one.
// Light: diffuse from above (the overcast model: ceiling lights) with
// ambient 0.4 .. 0.6; exposure e^(+-0.2), white balance e^(+-0.1) per
// channel, gamma e^(+-0.1), vignetting 0 .. 0.15. No sky (a closed room).
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include "families.h"
#include "wild_mvs/core/error.h"

namespace wild_mvs {
namespace families {

using testing::SyntheticObject;
using testing::SyntheticSpec;
using testing::ViewLighting;
using T = SyntheticObject::Type;

SyntheticSpec WeakTextureScene(const FamilyOptions& opt) {
  Require(opt.views >= 4, "weak scene: needs >= 4 views");
  std::mt19937 rng(opt.seed * 104723u + 29u);
  std::uniform_real_distribution<double> U01(0, 1);
  auto U = [&](double a, double b) { return a + (b - a) * U01(rng); };
  const int tex0 = 5000 + 50 * static_cast<int>(opt.seed % 1000);

  SyntheticSpec s;
  s.width = opt.width;
  s.height = opt.height;
  s.focal = 0.75 * opt.width;
  s.sky = false;
  s.seed = opt.seed;
  s.num_sparse_points = opt.points;
  s.sparse_pixel_noise = 0.3;
  s.noise_sigma = opt.noise;
  s.supersample = 2;

  const Eigen::Vector3d X(1, 0, 0), Y(0, 1, 0), Z(0, 0, 1);
  const double hx = U(3.0, 3.4), hy = U(2.5, 2.9), hz = U(1.3, 1.4);
  int tex = tex0;
  auto wall = [&](Eigen::Vector3d c, Eigen::Vector3d u, Eigen::Vector3d v,
                  double su, double sv) {
    SyntheticObject o;
    o.type = T::kPlane;
    o.center = c;
    o.axis_u = u;
    o.axis_v = v;
    o.size = Eigen::Vector3d(su, sv, 1);
    o.texture_seed = tex++;
    o.texture_scale = U(0.05, 0.12);
    o.texture_contrast = U(0.10, 0.20);
    s.objects.push_back(o);
  };
  wall({0, 0, 0}, X, Y, hx, hy);       // floor
  wall({0, 0, 2 * hz}, X, Y, hx, hy);  // ceiling
  wall({0, hy, hz}, X, Z, hx, hz);     // back wall
  wall({0, -hy, hz}, X, Z, hx, hz);    // front wall
  wall({-hx, 0, hz}, Y, Z, hy, hz);    // left wall
  wall({hx, 0, hz}, Y, Z, hy, hz);     // right wall

  auto box = [&](Eigen::Vector3d c, Eigen::Vector3d half, double yaw) {
    SyntheticObject o;
    o.type = T::kBox;
    o.center = c;
    o.size = half;
    o.rotation = Eigen::AngleAxisd(yaw, Z).toRotationMatrix();
    o.texture_seed = tex++;
    o.texture_scale = U(0.03, 0.06);
    s.objects.push_back(o);
  };
  // A cabinet against the back wall.
  const Eigen::Vector3d cab(U(0.4, 0.6), U(0.25, 0.3), U(0.6, 0.9));
  box({U(-1.5, 1.5), hy - cab.y() - 0.01, cab.z()}, cab, 0);
  // A table (a slab on a block) and a low chest in the room.
  const double table_x = U(-1.4, -0.4), table_y = U(0.2, 1.0);
  const double table_yaw = U(-0.4, 0.4);
  box({table_x, table_y, 0.72}, {0.6, 0.4, 0.03}, table_yaw);
  box({table_x, table_y, 0.345}, {0.2, 0.2, 0.345}, table_yaw);
  const Eigen::Vector3d chest(U(0.3, 0.45), U(0.2, 0.3), U(0.2, 0.3));
  box({U(0.6, 1.6), U(0.0, 0.9), chest.z()}, chest, U(0, M_PI));
  {  // a round bin
    SyntheticObject o;
    o.type = T::kCylinder;
    const double r = U(0.15, 0.25), h = U(0.25, 0.4);
    o.center = Eigen::Vector3d(U(1.8, 2.4), U(1.2, 2.0), h);
    o.size = Eigen::Vector3d(r, r, h);
    o.texture_seed = tex++;
    o.texture_scale = U(0.03, 0.05);
    s.objects.push_back(o);
  }
  {  // a ball on the floor
    SyntheticObject o;
    o.type = T::kSphere;
    const double r = U(0.15, 0.3);
    o.center = Eigen::Vector3d(U(-2.4, -1.8), U(0.8, 1.8), r);
    o.size = Eigen::Vector3d(r, r, r);
    o.texture_seed = tex++;
    o.texture_scale = U(0.03, 0.05);
    s.objects.push_back(o);
  }
  {  // a picture on the left or right wall, 1 cm off it
    const bool left = U01(rng) < 0.5;
    SyntheticObject o;
    o.type = T::kPlane;
    o.center = Eigen::Vector3d(left ? -hx + 0.01 : hx - 0.01, U(-0.5, 1.0),
                               U(1.3, 1.6));
    o.axis_u = Y;
    o.axis_v = Z;
    o.size = Eigen::Vector3d(U(0.3, 0.5), U(0.25, 0.35), 1);
    o.texture_seed = tex++;
    o.texture_scale = U(0.02, 0.04);
    s.objects.push_back(o);
  }

  // Cameras walk along the front of the room; targets sweep left to right.
  const int n = opt.views;
  for (int i = 0; i < n; ++i) {
    const double t = (i + U(-0.25, 0.25)) / (n - 1);
    const Eigen::Vector3d c(-1.8 + 3.6 * t + U(-0.15, 0.15), -hy + U(0.6, 1.3),
                            U(1.2, 1.7));
    const double sweep = (-80 + 160 * t + U(-8, 8)) * M_PI / 180;
    // A target 2.5 .. 4 m away in the sweep direction, at 0.4 .. 1.2 m.
    Eigen::Vector3d target =
        c + U(2.5, 4.0) * Eigen::Vector3d(std::sin(sweep), std::cos(sweep), 0);
    target.x() = std::clamp(target.x(), -hx + 0.2, hx - 0.2);
    target.y() = std::clamp(target.y(), -hy + 0.5, hy - 0.2);
    target.z() = U(0.4, 1.2);
    s.camera_centers.push_back(c);
    s.look_ats.push_back(target);
  }
  for (int i = 0; i < n; ++i) {
    ViewLighting l;
    l.overcast = true;
    l.ambient = U(0.4, 0.6);
    l.exposure = 1.8 * std::exp(U(-0.2, 0.2));
    for (int c = 0; c < 3; ++c) l.white_balance[c] = std::exp(U(-0.1, 0.1));
    l.gamma = std::exp(U(-0.1, 0.1));
    l.vignetting = U(0, 0.15);
    s.lighting.push_back(l);
  }
  return s;
}

}  // namespace families
}  // namespace wild_mvs
