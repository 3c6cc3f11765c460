// Copyright wild_mvs authors. The `relief` family: curved and relief
// geometry under light that changes per view, the conditions that cost
// coverage on photos taken at different times.
//
// Layout (world z up, metres; all positions, sizes and textures jittered by
// the seed): a ground 9 x 9 m; a displaced facade 5.2 x 2.4 m at y ~ 2.2
// (relief amplitude ~3 % of its half width) and a displaced side wall at an
// angle; three capped columns (cylinders), an open round basin (an uncapped
// cylinder: its inside shows), two spheres and three boxes between them.
// Cameras: 14 views on a 120-degree arc in front of the facade at distances
// 1.6 .. 6.0 m from their targets (a 3.75x range of image scales), heights
// 0.5 .. 2.2 m, each looking at its own point of the scene; two views are
// near-duplicates of others (a few cm apart, other light). Per view: a sun
// at elevation 12 .. 75 degrees and any azimuth (cast shadows), except 20 %
// overcast views (sky light only); ambient level 0.15 .. 0.45; exposure
// normalised by the view's mean light then e^(+-0.4); white balance
// e^(+-0.35) per channel; gamma e^(+-0.3); vignetting 0 .. 0.35. A
// one-view occluder (a box, a sphere or a post) in three views.
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <numeric>
#include <random>
#include <vector>

#include "families.h"
#include "wild_mvs/core/error.h"

namespace wild_mvs {
namespace families {
namespace {

using testing::SyntheticObject;
using testing::SyntheticSpec;
using testing::ViewLighting;
using T = SyntheticObject::Type;

// Non-overlapping footprints (discs) on the ground.
struct Footprints {
  std::vector<Eigen::Vector3d> discs;  // x, y, radius
  bool Free(double x, double y, double r) const {
    for (const Eigen::Vector3d& d : discs)
      if (std::hypot(x - d.x(), y - d.y()) < r + d.z() + 0.15) return false;
    return true;
  }
};

}  // namespace

SyntheticSpec ReliefScene(const FamilyOptions& opt) {
  Require(opt.views >= 4, "relief scene: needs >= 4 views");
  Require(opt.texture_contrast > 0 && opt.texture_contrast <= 1,
          "relief scene: texture contrast ", opt.texture_contrast,
          " must be in (0, 1]");
  std::mt19937 rng(opt.seed * 7919u + 17u);
  std::uniform_real_distribution<double> U01(0, 1);
  auto U = [&](double a, double b) { return a + (b - a) * U01(rng); };
  const int tex0 = 200 + 50 * static_cast<int>(opt.seed % 1000);

  SyntheticSpec s;
  s.width = opt.width;
  s.height = opt.height;
  s.focal = 0.8 * opt.width;
  s.sky = true;
  s.seed = opt.seed;
  s.num_sparse_points = opt.points;
  s.sparse_pixel_noise = 0.3;
  s.noise_sigma = opt.noise;
  s.supersample = 2;

  const Eigen::Vector3d X(1, 0, 0), Y(0, 1, 0), Z(0, 0, 1);
  SyntheticObject ground;
  ground.type = T::kPlane;
  ground.center = Eigen::Vector3d(0, 0.5, 0);
  ground.axis_u = X;
  ground.axis_v = Y;
  ground.size = Eigen::Vector3d(4.5, 4.5, 1);
  ground.texture_seed = tex0;
  ground.texture_scale = U(0.05, 0.08);
  s.objects.push_back(ground);

  // The facade: facing -y (towards the cameras), its foot on the ground.
  const double facade_y = U(2.0, 2.4);
  SyntheticObject facade;
  facade.type = T::kRelief;
  facade.center = Eigen::Vector3d(U(-0.2, 0.2), facade_y, 1.2);
  facade.axis_u = X;
  facade.axis_v = Z;
  facade.size = Eigen::Vector3d(2.6, 1.2, 1);
  facade.relief_amplitude = U(0.025, 0.035) * facade.size.x();
  facade.relief_scale = U(0.45, 0.8);
  facade.relief_seed = tex0 + 1;
  facade.texture_seed = tex0 + 1;
  facade.texture_scale = U(0.05, 0.08);
  // Lift it by its amplitude so the relief does not cut the ground.
  facade.center.y() -= facade.relief_amplitude;
  s.objects.push_back(facade);

  // A side wall at an angle on the left, with a shallower relief.
  const double side_angle = U(55, 75) * M_PI / 180;  // from the facade
  SyntheticObject side;
  side.type = T::kRelief;
  side.axis_u = Eigen::Vector3d(std::cos(side_angle), std::sin(side_angle), 0);
  side.axis_v = Z;
  side.size = Eigen::Vector3d(1.5, 0.9, 1);
  side.center = Eigen::Vector3d(-2.6, facade_y, 0.9) - 1.55 * side.axis_u;
  side.relief_amplitude = U(0.015, 0.025) * side.size.x() * 2;
  side.relief_scale = U(0.3, 0.5);
  side.relief_seed = tex0 + 2;
  side.texture_seed = tex0 + 2;
  side.texture_scale = U(0.04, 0.07);
  s.objects.push_back(side);

  Footprints taken;
  auto place = [&](double r, double ylo, double yhi, Eigen::Vector2d* xy) {
    for (int attempt = 0; attempt < 500; ++attempt) {
      const double x = U(-2.1, 2.1), y = U(ylo, yhi);
      if (taken.Free(x, y, r)) {
        taken.discs.emplace_back(x, y, r);
        *xy = Eigen::Vector2d(x, y);
        return;
      }
    }
    throw Error("relief scene: no room for an object");
  };
  int tex = tex0 + 10;
  for (int k = 0; k < 3; ++k) {  // columns
    SyntheticObject c;
    c.type = T::kCylinder;
    const double r = U(0.14, 0.3), h = U(0.6, 1.1);
    Eigen::Vector2d xy;
    place(r, 0.9, facade_y - 0.5, &xy);
    c.center = Eigen::Vector3d(xy.x(), xy.y(), h);
    c.size = Eigen::Vector3d(r, r, h);
    c.texture_seed = tex++;
    c.texture_scale = U(0.03, 0.06);
    s.objects.push_back(c);
  }
  {  // an open basin: its inner wall shows over the rim
    SyntheticObject b;
    b.type = T::kCylinder;
    b.capped = false;
    const double r = U(0.4, 0.6), h = U(0.18, 0.3);
    Eigen::Vector2d xy;
    place(r, 0.4, facade_y - 0.8, &xy);
    b.center = Eigen::Vector3d(xy.x(), xy.y(), h);
    b.size = Eigen::Vector3d(r, r, h);
    b.texture_seed = tex++;
    b.texture_scale = U(0.03, 0.05);
    s.objects.push_back(b);
  }
  for (int k = 0; k < 2; ++k) {  // spheres resting on the ground
    SyntheticObject o;
    o.type = T::kSphere;
    const double r = U(0.2, 0.45);
    Eigen::Vector2d xy;
    place(r, 0.4, facade_y - 0.5, &xy);
    o.center = Eigen::Vector3d(xy.x(), xy.y(), r);
    o.size = Eigen::Vector3d(r, r, r);
    o.texture_seed = tex++;
    o.texture_scale = U(0.03, 0.05);
    s.objects.push_back(o);
  }
  for (int k = 0; k < 3; ++k) {  // boxes
    SyntheticObject o;
    o.type = T::kBox;
    const Eigen::Vector3d half(U(0.12, 0.3), U(0.12, 0.3), U(0.1, 0.35));
    Eigen::Vector2d xy;
    place(std::hypot(half.x(), half.y()), 0.3, facade_y - 0.4, &xy);
    o.center = Eigen::Vector3d(xy.x(), xy.y(), half.z());
    o.size = half;
    o.rotation = Eigen::AngleAxisd(U(0, M_PI), Z).toRotationMatrix();
    o.texture_seed = tex++;
    o.texture_scale = U(0.03, 0.06);
    s.objects.push_back(o);
  }

  // Cameras: distances 1.6 .. 6.0 spread log-uniformly over the views in a
  // shuffled order, azimuths over a 120-degree arc in order.
  const int n = opt.views;
  std::vector<double> dist(n);
  for (int i = 0; i < n; ++i)
    dist[i] = 1.6 * std::pow(6.0 / 1.6, i / double(n - 1));
  std::shuffle(dist.begin(), dist.end(), rng);
  const Eigen::Vector3d centre(0, 0.5 * (0.4 + facade_y), 0.6);
  for (int i = 0; i < n; ++i) {
    const double a = (-150 + 120.0 * (i + U(-0.3, 0.3)) / (n - 1)) * M_PI / 180;
    const Eigen::Vector3d target =
        centre + Eigen::Vector3d(U(-0.6, 0.6), U(-0.3, 0.4), U(-0.2, 0.4));
    const double d = dist[i];
    const double height = std::clamp(0.3 * d + U(-0.2, 0.4), 0.5, 2.2);
    Eigen::Vector3d c =
        target + Eigen::Vector3d(d * std::cos(a), d * std::sin(a), 0);
    c.z() = height;
    // Keep cameras in front of the objects (y < 0.1).
    c.y() = std::min(c.y(), 0.1);
    s.camera_centers.push_back(c);
    s.look_ats.push_back(target);
  }
  // Two near-duplicates: a view replaced by another's pose moved a few cm.
  std::vector<int> order(n);
  std::iota(order.begin(), order.end(), 0);
  std::shuffle(order.begin(), order.end(), rng);
  for (int k = 0; k < 2; ++k) {
    const int dst = order[k], src = order[k + 2];
    s.camera_centers[dst] =
        s.camera_centers[src] +
        Eigen::Vector3d(U(-0.04, 0.04), U(-0.04, 0.04), U(-0.03, 0.03));
    s.look_ats[dst] =
        s.look_ats[src] +
        Eigen::Vector3d(U(-0.03, 0.03), U(-0.03, 0.03), U(-0.03, 0.03));
    dist[dst] = dist[src];
  }

  // Lighting.
  std::shuffle(order.begin(), order.end(), rng);
  const int overcast_views = static_cast<int>(std::lround(0.2 * n));
  for (int i = 0; i < n; ++i) {
    const bool overcast =
        std::find(order.begin(), order.begin() + overcast_views, i) !=
        order.begin() + overcast_views;
    ViewLighting l;
    l.overcast = overcast;
    l.ambient = U(0.15, 0.45);
    const double el = U(12, 75) * M_PI / 180, az = U(0, 2 * M_PI);
    l.sun = Eigen::Vector3d(std::cos(az) * std::cos(el),
                            std::sin(az) * std::cos(el), std::sin(el));
    // A camera's auto exposure evens out the mean light level (overcast:
    // the sky light of a wall is 1/2, of the ground 1; sun: about half of
    // the surfaces lit at ~0.6), then errs by e^(+-0.4).
    const double mean_light =
        l.ambient + (1 - l.ambient) * (overcast ? 0.75 : 0.35);
    l.exposure = 0.75 / mean_light * std::exp(U(-0.4, 0.4));
    for (int c = 0; c < 3; ++c) l.white_balance[c] = std::exp(U(-0.35, 0.35));
    l.gamma = std::exp(U(-0.3, 0.3));
    l.vignetting = U(0, 0.35);
    s.lighting.push_back(l);
  }

  // One-view occluders in three views (not the near-duplicates' sources).
  std::shuffle(order.begin(), order.end(), rng);
  for (int k = 0; k < 3; ++k) {
    const int i = order[k];
    const Eigen::Vector3d c = s.camera_centers[i];
    const Eigen::Vector3d f = (s.look_ats[i] - c).normalized();
    const Eigen::Vector3d right = f.cross(Z).normalized();
    const double t = U(0.3, 0.55) * dist[i];
    const Eigen::Vector3d p = c + t * f + U(-0.25, 0.25) * t * right;
    SyntheticObject o;
    const int kind = k % 3;
    const double size = 0.12 * t;
    if (kind == 0) {
      o.type = T::kBox;
      o.size = Eigen::Vector3d(size, size, 1.5 * size);
      o.rotation = Eigen::AngleAxisd(U(0, M_PI), Z).toRotationMatrix();
    } else if (kind == 1) {
      o.type = T::kSphere;
      o.size = Eigen::Vector3d::Constant(size);
    } else {
      o.type = T::kCylinder;
      o.size = Eigen::Vector3d(0.5 * size, 0.5 * size, 3 * size);
    }
    o.center = p;
    o.texture_seed = tex++;
    o.texture_scale = 0.03;
    o.only_in_view = i;
    s.objects.push_back(o);
  }
  for (SyntheticObject& o : s.objects)
    o.texture_contrast *= opt.texture_contrast;
  return s;
}

}  // namespace families
}  // namespace wild_mvs
