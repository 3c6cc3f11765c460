// Copyright wild_mvs authors. A small ray-casting renderer for tests.
//
// Rendering model (exact, documented in synthetic_scene.h):
//  - Every pixel is sampled with supersample^2 rays on a regular sub-grid;
//    the image value is the mean of the samples' radiance. Ground-truth
//    depth, normal and object id come from the single ray through the pixel
//    centre (col + 0.5, row + 0.5), so they are exact at that point.
//  - A ray is written x(z) = C + z * R^T (x_n, y_n, 1): its parameter is the
//    camera depth z directly. The nearest hit with z > 1e-6 wins.
//  - Radiance is view independent: albedo(p) * shade(n) where albedo is a
//    multi-octave 3-D value noise at the world hit point (colour, per object
//    seed, feature size texture_scale) and shade = 0.75 + 0.25 |n . l| for a
//    fixed light direction l (two-sided, so it does not depend on the
//    viewer). Radiance lies in about [0.02, 0.40] so that exposures up to
//    2.5 still mostly fit in [0, 1]. Background (no hit) radiance is 0.
//    Views with a sun or overcast shade as ViewLighting describes.
#include "synthetic_scene.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <limits>
#include <opencv2/imgcodecs.hpp>
#include <random>

#include "synthetic_lens.h"
#include "wild_mvs/core/error.h"
#include "wild_mvs/core/thread_pool.h"
#include "wild_mvs/io/atomic_file.h"
#include "wild_mvs/io/colmap.h"
#include "wild_mvs/io/pfm.h"

namespace wild_mvs {
namespace testing {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kMinDepth = 1e-6;

// ---------------------------------------------------------------- texture

inline uint32_t Hash(int32_t x, int32_t y, int32_t z, uint32_t seed) {
  uint32_t h = seed * 0x9E3779B1u;
  h ^= static_cast<uint32_t>(x) * 0x85EBCA77u;
  h = (h << 13) | (h >> 19);
  h ^= static_cast<uint32_t>(y) * 0xC2B2AE3Du;
  h = (h << 11) | (h >> 21);
  h ^= static_cast<uint32_t>(z) * 0x27D4EB2Fu;
  h ^= h >> 15;
  h *= 0x2C1B3C6Du;
  h ^= h >> 12;
  h *= 0x297A2D39u;
  h ^= h >> 15;
  return h;
}

inline double Lattice(int32_t x, int32_t y, int32_t z, uint32_t seed) {
  return (Hash(x, y, z, seed) & 0xFFFFFFu) / static_cast<double>(0xFFFFFFu);
}

inline double Smooth(double t) { return t * t * (3 - 2 * t); }

// Value noise in [0, 1] with unit feature size.
double ValueNoise(const Eigen::Vector3d& p, uint32_t seed) {
  const double fx = std::floor(p.x()), fy = std::floor(p.y()),
               fz = std::floor(p.z());
  const int32_t x = static_cast<int32_t>(fx), y = static_cast<int32_t>(fy),
                z = static_cast<int32_t>(fz);
  const double u = Smooth(p.x() - fx), v = Smooth(p.y() - fy),
               w = Smooth(p.z() - fz);
  double c[2][2];
  for (int dz = 0; dz < 2; ++dz) {
    for (int dy = 0; dy < 2; ++dy) {
      const double a = Lattice(x, y + dy, z + dz, seed);
      const double b = Lattice(x + 1, y + dy, z + dz, seed);
      c[dz][dy] = a + (b - a) * u;
    }
  }
  const double c0 = c[0][0] + (c[0][1] - c[0][0]) * v;
  const double c1 = c[1][0] + (c[1][1] - c[1][0]) * v;
  return c0 + (c1 - c0) * w;
}

// Sum of octaves at feature sizes 2s, s, s/2, s/4 (s = texture_scale),
// weighted towards the fine octaves so that the texture has strong contrast
// at a few pixels, then contrast-stretched. Returns a value in [0, 1].
double Fbm(const Eigen::Vector3d& p, double scale, uint32_t seed) {
  static const double kFreq[4] = {0.5, 1.0, 2.0, 4.0};
  static const double kWeight[4] = {0.9, 1.0, 0.8, 0.55};
  double sum = 0, wsum = 0;
  for (int o = 0; o < 4; ++o) {
    // A per-octave offset decorrelates the lattices of the octaves.
    const Eigen::Vector3d q =
        p * (kFreq[o] / scale) + Eigen::Vector3d(17.31 * o, 5.17 * o, 11.7 * o);
    sum += kWeight[o] * ValueNoise(q, seed + 1013u * o);
    wsum += kWeight[o];
  }
  const double f = sum / wsum;
  return std::clamp(0.5 + 2.6 * (f - 0.5), 0.0, 1.0);
}

Eigen::Vector3d BaseColor(int seed) {
  // A saturated-ish but not extreme colour per object.
  const double h = Lattice(seed, 3, 5, 99u);
  const double a = 2 * M_PI * h;
  Eigen::Vector3d c(0.6 + 0.35 * std::cos(a), 0.6 + 0.35 * std::cos(a - 2.094),
                    0.6 + 0.35 * std::cos(a + 2.094));
  return c;
}

// Value noise with two independent channels from one lattice hash (low
// and high 16 bits), for the colour variation.
Eigen::Vector2d ValueNoise2(const Eigen::Vector3d& p, uint32_t seed) {
  const double fx = std::floor(p.x()), fy = std::floor(p.y()),
               fz = std::floor(p.z());
  const int32_t x = static_cast<int32_t>(fx), y = static_cast<int32_t>(fy),
                z = static_cast<int32_t>(fz);
  const double u = Smooth(p.x() - fx), v = Smooth(p.y() - fy),
               w = Smooth(p.z() - fz);
  Eigen::Vector2d c[2][2];
  for (int dz = 0; dz < 2; ++dz) {
    for (int dy = 0; dy < 2; ++dy) {
      const uint32_t ha = Hash(x, y + dy, z + dz, seed);
      const uint32_t hb = Hash(x + 1, y + dy, z + dz, seed);
      const Eigen::Vector2d a((ha & 0xFFFFu) / 65535.0, (ha >> 16) / 65535.0);
      const Eigen::Vector2d b((hb & 0xFFFFu) / 65535.0, (hb >> 16) / 65535.0);
      c[dz][dy] = a + (b - a) * u;
    }
  }
  const Eigen::Vector2d c0 = c[0][0] + (c[0][1] - c[0][0]) * v;
  const Eigen::Vector2d c1 = c[1][0] + (c[1][1] - c[1][0]) * v;
  return c0 + (c1 - c0) * w;
}

// Linear albedo in [0.05, 1] per channel, fixed to the surface. `base` is
// BaseColor(o.texture_seed).
Eigen::Vector3d Albedo(const SyntheticObject& o, const Eigen::Vector3d& base,
                       const Eigen::Vector3d& p) {
  const uint32_t seed = static_cast<uint32_t>(o.texture_seed) * 7919u + 1u;
  double lum = Fbm(p, o.texture_scale, seed);
  const Eigen::Vector2d ch = ValueNoise2(
      p * (1.0 / o.texture_scale) + Eigen::Vector3d(3.3, 1.7, 9.1), seed + 77u);
  double c1 = ch.x(), c2 = ch.y();
  if (o.texture_contrast != 1.0) {
    const double k = o.texture_contrast;
    lum = 0.5 + k * (lum - 0.5);
    c1 = 0.5 + k * (c1 - 0.5);
    c2 = 0.5 + k * (c2 - 0.5);
  }
  Eigen::Vector3d tint(1.0 + 0.5 * (c1 - 0.5), 1.0 - 0.25 * (c1 + c2 - 1.0),
                       1.0 + 0.5 * (c2 - 0.5));
  Eigen::Vector3d a = (0.06 + 0.94 * lum) * base.cwiseProduct(tint);
  return a.cwiseMax(0.05).cwiseMin(1.0);
}

const Eigen::Vector3d& LightDir() {
  static const Eigen::Vector3d l = Eigen::Vector3d(0.3, -0.5, 0.8).normalized();
  return l;
}

// ------------------------------------------------------------ intersection

struct Hit {
  double z = kInf;  // ray parameter = camera depth
  int object = -1;
  Eigen::Vector3d normal{0, 0, 0};  // world frame, unit, not yet oriented
};

// One plane wave of a relief height field: h += amp * sin(k . (u, v) + phase).
struct ReliefWave {
  Eigen::Vector2d k{0, 0};
  double amp = 0, phase = 0;
};

// Prepared object (normalised axes, cached normal).
struct Prepared {
  SyntheticObject obj;
  Eigen::Vector3d n{0, 0, 1};
  Eigen::Vector3d base{1, 1, 1};  // BaseColor(obj.texture_seed)
  std::vector<ReliefWave> waves;  // kRelief
  double max_slope = 0;           // kRelief: bound on |grad h|
};

// kRelief: the height h(u, v) and, when `grad` is set, its gradient.
double ReliefHeight(const Prepared& pr, double u, double v,
                    Eigen::Vector2d* grad) {
  double h = 0;
  if (grad) grad->setZero();
  for (const ReliefWave& w : pr.waves) {
    const double a = w.k.x() * u + w.k.y() * v + w.phase;
    h += w.amp * std::sin(a);
    if (grad) *grad += w.amp * std::cos(a) * w.k;
  }
  return h;
}

// kRelief waves: six plane waves, wavelengths 0.6 .. 1.7 relief_scale,
// amplitudes ~ wavelength, scaled so that sum |amp| = relief_amplitude.
void PrepareRelief(Prepared* pr) {
  const SyntheticObject& o = pr->obj;
  const uint32_t seed = static_cast<uint32_t>(o.relief_seed) * 104729u + 5u;
  double sum = 0;
  for (int k = 0; k < 6; ++k) {
    const double wavelength =
        o.relief_scale * (0.6 + 1.1 * Lattice(k, 1, 0, seed));
    const double dir = M_PI * Lattice(k, 2, 0, seed);
    ReliefWave w;
    w.k =
        (2 * M_PI / wavelength) * Eigen::Vector2d(std::cos(dir), std::sin(dir));
    w.phase = 2 * M_PI * Lattice(k, 3, 0, seed);
    w.amp = wavelength;
    sum += w.amp;
    pr->waves.push_back(w);
  }
  pr->max_slope = 0;
  for (ReliefWave& w : pr->waves) {
    w.amp *= o.relief_amplitude / sum;
    pr->max_slope += w.amp * w.k.norm();
  }
}

// Clips [*t0, *t1] to the slab |(o + t d) . axis| <= half; false if empty.
bool ClipSlab(double q, double dq, double half, double* t0, double* t1) {
  if (std::abs(dq) < 1e-15) return std::abs(q) <= half;
  double a = (-half - q) / dq, b = (half - q) / dq;
  if (a > b) std::swap(a, b);
  *t0 = std::max(*t0, a);
  *t1 = std::min(*t1, b);
  return *t0 < *t1;
}

// Linear radiance of a surface point (view independent).
Eigen::Vector3d Radiance(const Prepared& o, const Eigen::Vector3d& p,
                         const Eigen::Vector3d& n) {
  const double shade = 0.75 + 0.25 * std::abs(n.dot(LightDir()));
  return 0.4 * shade * Albedo(o.obj, o.base, p);
}

void IntersectObject(const Prepared& pr, int index, const Eigen::Vector3d& o,
                     const Eigen::Vector3d& d, Hit* hit) {
  const SyntheticObject& ob = pr.obj;
  switch (ob.type) {
    case SyntheticObject::Type::kPlane: {
      const double dn = d.dot(pr.n);
      if (std::abs(dn) < 1e-14) return;
      const double z = (ob.center - o).dot(pr.n) / dn;
      if (!(z > kMinDepth) || z >= hit->z) return;
      const Eigen::Vector3d q = o + z * d - ob.center;
      if (std::abs(q.dot(ob.axis_u)) > ob.size.x() ||
          std::abs(q.dot(ob.axis_v)) > ob.size.y())
        return;
      hit->z = z;
      hit->object = index;
      hit->normal = pr.n;
      return;
    }
    case SyntheticObject::Type::kBox: {
      const Eigen::Vector3d lo = ob.rotation.transpose() * (o - ob.center);
      const Eigen::Vector3d ld = ob.rotation.transpose() * d;
      double tnear = -kInf, tfar = kInf;
      int near_axis = -1, far_axis = -1;
      for (int a = 0; a < 3; ++a) {
        if (std::abs(ld[a]) < 1e-15) {
          if (std::abs(lo[a]) > ob.size[a]) return;
          continue;
        }
        double t0 = (-ob.size[a] - lo[a]) / ld[a];
        double t1 = (ob.size[a] - lo[a]) / ld[a];
        if (t0 > t1) std::swap(t0, t1);
        if (t0 > tnear) {
          tnear = t0;
          near_axis = a;
        }
        if (t1 < tfar) {
          tfar = t1;
          far_axis = a;
        }
        if (tnear > tfar) return;
      }
      double z;
      int axis;
      if (tnear > kMinDepth) {
        z = tnear;
        axis = near_axis;
      } else if (tfar > kMinDepth) {
        z = tfar;
        axis = far_axis;
      } else {
        return;
      }
      if (z >= hit->z || axis < 0) return;
      Eigen::Vector3d nl = Eigen::Vector3d::Zero();
      nl[axis] = 1.0;
      hit->z = z;
      hit->object = index;
      hit->normal = ob.rotation * nl;
      return;
    }
    case SyntheticObject::Type::kSphere: {
      const Eigen::Vector3d oc = o - ob.center;
      const double a = d.squaredNorm();
      const double b = oc.dot(d);
      const double c = oc.squaredNorm() - ob.size.x() * ob.size.x();
      const double disc = b * b - a * c;
      if (disc < 0) return;
      const double s = std::sqrt(disc);
      double z = (-b - s) / a;
      if (!(z > kMinDepth)) z = (-b + s) / a;
      if (!(z > kMinDepth) || z >= hit->z) return;
      hit->z = z;
      hit->object = index;
      hit->normal = (o + z * d - ob.center).normalized();
      return;
    }
    case SyntheticObject::Type::kCylinder: {
      const Eigen::Vector3d q = o - ob.center;
      const double r = ob.size.x(), hz = ob.size.z();
      double best = hit->z;
      Eigen::Vector3d normal;
      const double a = d.x() * d.x() + d.y() * d.y();
      if (a > 1e-30) {  // the side
        const double b = q.x() * d.x() + q.y() * d.y();
        const double c = q.x() * q.x() + q.y() * q.y() - r * r;
        const double disc = b * b - a * c;
        if (disc >= 0) {
          const double s = std::sqrt(disc);
          for (const double z : {(-b - s) / a, (-b + s) / a}) {
            if (!(z > kMinDepth) || z >= best) continue;
            if (std::abs(q.z() + z * d.z()) > hz) continue;
            best = z;
            normal = Eigen::Vector3d(q.x() + z * d.x(), q.y() + z * d.y(), 0)
                         .normalized();
            break;
          }
        }
      }
      if (ob.capped && std::abs(d.z()) > 1e-15) {
        for (const double side : {-1.0, 1.0}) {
          const double z = (side * hz - q.z()) / d.z();
          if (!(z > kMinDepth) || z >= best) continue;
          const double x = q.x() + z * d.x(), y = q.y() + z * d.y();
          if (x * x + y * y > r * r) continue;
          best = z;
          normal = Eigen::Vector3d(0, 0, side);
        }
      }
      if (best >= hit->z) return;
      hit->z = best;
      hit->object = index;
      hit->normal = normal;
      return;
    }
    case SyntheticObject::Type::kRelief: {
      // f(t) = w(t) - h(u(t), v(t)) along the ray, in the slab |w| <= A.
      const Eigen::Vector3d q = o - ob.center;
      const double qu = q.dot(ob.axis_u), qv = q.dot(ob.axis_v),
                   qw = q.dot(pr.n);
      const double du = d.dot(ob.axis_u), dv = d.dot(ob.axis_v),
                   dw = d.dot(pr.n);
      double t0 = kMinDepth, t1 = hit->z;
      const double slab =
          std::max(ob.relief_amplitude, 1e-9 * (ob.size.x() + ob.size.y()));
      if (!ClipSlab(qw, dw, slab, &t0, &t1) ||
          !ClipSlab(qu, du, ob.size.x(), &t0, &t1) ||
          !ClipSlab(qv, dv, ob.size.y(), &t0, &t1))
        return;
      if (!std::isfinite(t1)) return;
      auto f = [&](double t) {
        return qw + t * dw -
               ReliefHeight(pr, qu + t * du, qv + t * dv, nullptr);
      };
      // |f'| <= lip, so f keeps its sign for |f| / lip; steps of at least
      // 1/512 of the interval bound the work (a sign change inside such a
      // step and back is thinner than the relief's features).
      const double lip =
          std::abs(dw) + pr.max_slope * std::sqrt(du * du + dv * dv) + 1e-300;
      const double min_step = (t1 - t0) / 512;
      double ta = t0, fa = f(ta);
      double root = -1;
      if (fa == 0) root = ta;
      while (root < 0 && ta < t1) {
        const double tb =
            std::min(t1, ta + std::max(std::abs(fa) / lip, min_step));
        const double fb = f(tb);
        if (fb == 0) {
          root = tb;
        } else if ((fa < 0) != (fb < 0)) {
          double lo = ta, hi = tb;
          for (int it = 0; it < 200 && hi - lo > 1e-12 * hi; ++it) {
            const double mid = 0.5 * (lo + hi);
            const double fm = f(mid);
            if ((fm < 0) == (fa < 0)) {
              lo = mid;
            } else {
              hi = mid;
            }
          }
          root = 0.5 * (lo + hi);
        }
        ta = tb;
        fa = fb;
      }
      if (root < 0 || !(root > kMinDepth) || root >= hit->z) return;
      Eigen::Vector2d g;
      ReliefHeight(pr, qu + root * du, qv + root * dv, &g);
      hit->z = root;
      hit->object = index;
      hit->normal = (pr.n - g.x() * ob.axis_u - g.y() * ob.axis_v).normalized();
      return;
    }
  }
}

std::vector<Prepared> Prepare(const std::vector<SyntheticObject>& objects) {
  std::vector<Prepared> out;
  for (size_t i = 0; i < objects.size(); ++i) {
    const SyntheticObject& o = objects[i];
    const std::string what = Msg("synthetic object ", i);
    Require(o.texture_scale > 0, what, ": texture_scale = ", o.texture_scale,
            " must be > 0");
    Require(o.texture_contrast >= 0, what,
            ": texture_contrast = ", o.texture_contrast, " must be >= 0");
    Require((o.size.array() > 0).all() ||
                (o.type == SyntheticObject::Type::kSphere && o.size.x() > 0),
            what, ": size must be positive");
    Prepared p;
    p.obj = o;
    p.base = BaseColor(o.texture_seed);
    if (o.type == SyntheticObject::Type::kPlane ||
        o.type == SyntheticObject::Type::kRelief) {
      Require(o.axis_u.norm() > 0 && o.axis_v.norm() > 0 &&
                  o.axis_u.cross(o.axis_v).norm() > 1e-9,
              what, ": plane axes must be non-zero and not parallel");
      p.obj.axis_u = o.axis_u.normalized();
      // Orthogonalise v against u so the rectangle is well defined.
      p.obj.axis_v =
          (o.axis_v - o.axis_v.dot(p.obj.axis_u) * p.obj.axis_u).normalized();
      p.n = p.obj.axis_u.cross(p.obj.axis_v).normalized();
    }
    if (o.type == SyntheticObject::Type::kRelief) {
      Require(o.relief_amplitude >= 0 && o.relief_scale > 0, what,
              ": relief_amplitude must be >= 0 and relief_scale > 0");
      PrepareRelief(&p);
    }
    out.push_back(p);
  }
  return out;
}

// Nearest hit of the ray x(z) = o + z d among the objects present in `view`.
Hit Cast(const std::vector<Prepared>& objs, int view, const Eigen::Vector3d& o,
         const Eigen::Vector3d& d) {
  Hit hit;
  for (size_t i = 0; i < objs.size(); ++i) {
    const int only = objs[i].obj.only_in_view;
    if (only >= 0 && only != view) continue;
    IntersectObject(objs[i], static_cast<int>(i), o, d, &hit);
  }
  return hit;
}

// World direction with camera-frame z = 1 through pixel px.
Eigen::Vector3d RayDir(const Camera& cam, double u, double v) {
  return cam.R.transpose() *
         Eigen::Vector3d((u - cam.cx) / cam.fx, (v - cam.cy) / cam.fy, 1.0);
}

// The undistorted (pinhole) pixel whose distortion by `d` is pixel px of
// the distorted image (fixed-point iteration on normalised coordinates).
Eigen::Vector2d UndistortedPixel(const Camera& cam, const Distortion& d,
                                 double u, double v) {
  const double xd = (u - cam.cx) / cam.fx, yd = (v - cam.cy) / cam.fy;
  double x = xd, y = yd;
  for (int it = 0; it < 50; ++it) {
    const double r2 = x * x + y * y;
    const double radial = 1 + d.k1 * r2 + d.k2 * r2 * r2 + d.k3 * r2 * r2 * r2;
    const double dx = 2 * d.p1 * x * y + d.p2 * (r2 + 2 * x * x);
    const double dy = d.p1 * (r2 + 2 * y * y) + 2 * d.p2 * x * y;
    const double nx = (xd - dx) / radial, ny = (yd - dy) / radial;
    const double change = std::abs(nx - x) + std::abs(ny - y);
    x = nx;
    y = ny;
    if (change < 1e-14) break;
  }
  return {cam.fx * x + cam.cx, cam.fy * y + cam.cy};
}

Camera LookAtCamera(const Eigen::Vector3d& center,
                    const Eigen::Vector3d& target, int width, int height,
                    double focal) {
  const Eigen::Vector3d f = (target - center).normalized();
  Eigen::Vector3d up(0, 0, 1);
  if (std::abs(f.dot(up)) > 0.999) up = Eigen::Vector3d(0, 1, 0);
  const Eigen::Vector3d x = f.cross(up).normalized();  // image right
  const Eigen::Vector3d y = f.cross(x).normalized();   // image down
  Camera c;
  c.fx = c.fy = focal;
  c.cx = width / 2.0;
  c.cy = height / 2.0;
  c.width = width;
  c.height = height;
  c.R.row(0) = x.transpose();
  c.R.row(1) = y.transpose();
  c.R.row(2) = f.transpose();
  c.t = -c.R * center;
  return c;
}

// Photometric response of one channel (see ViewLighting / header).
inline float Respond(double radiance, double gain, double inv_gamma) {
  double v = std::clamp(gain * radiance, 0.0, 1.0);
  if (inv_gamma != 1.0) v = std::pow(v, inv_gamma);
  return static_cast<float>(v);
}

// 8-bit quantisation in the sRGB encoding (what a PNG/JPEG stores), back to
// linear: exactly what LoadViewImage returns for the written 8-bit PNG.
inline float Quantize(float v) {
  const float s = LinearToSrgb(std::clamp(v, 0.f, 1.f));
  return SrgbToLinear(std::round(s * 255.f) / 255.f);
}

void ExtendBounds(const SyntheticObject& o, Eigen::Vector3d* lo,
                  Eigen::Vector3d* hi) {
  auto add = [&](const Eigen::Vector3d& p) {
    *lo = lo->cwiseMin(p);
    *hi = hi->cwiseMax(p);
  };
  switch (o.type) {
    case SyntheticObject::Type::kPlane:
    case SyntheticObject::Type::kRelief: {
      const Eigen::Vector3d u = o.axis_u.normalized() * o.size.x();
      const Eigen::Vector3d v = o.axis_v.normalized() * o.size.y();
      const bool relief = o.type == SyntheticObject::Type::kRelief;
      const Eigen::Vector3d n =
          relief ? Eigen::Vector3d(o.relief_amplitude * u.cross(v).normalized())
                 : Eigen::Vector3d::Zero();
      for (const double s : {1.0, -1.0}) {
        if (!relief && s < 0) break;
        add(o.center + u + v + s * n);
        add(o.center + u - v + s * n);
        add(o.center - u + v + s * n);
        add(o.center - u - v + s * n);
      }
      break;
    }
    case SyntheticObject::Type::kCylinder:
      add(o.center - Eigen::Vector3d(o.size.x(), o.size.x(), o.size.z()));
      add(o.center + Eigen::Vector3d(o.size.x(), o.size.x(), o.size.z()));
      break;
    case SyntheticObject::Type::kBox:
      for (int k = 0; k < 8; ++k) {
        const Eigen::Vector3d s((k & 1) ? 1 : -1, (k & 2) ? 1 : -1,
                                (k & 4) ? 1 : -1);
        add(o.center + o.rotation * s.cwiseProduct(o.size));
      }
      break;
    case SyntheticObject::Type::kSphere:
      add(o.center - Eigen::Vector3d::Constant(o.size.x()));
      add(o.center + Eigen::Vector3d::Constant(o.size.x()));
      break;
  }
}

}  // namespace

double ReliefHeight(const SyntheticObject& relief, double u, double v,
                    Eigen::Vector2d* grad) {
  Require(relief.type == SyntheticObject::Type::kRelief,
          "ReliefHeight: the object is not a relief");
  Prepared p;
  p.obj = relief;
  PrepareRelief(&p);
  return ReliefHeight(p, u, v, grad);
}

// ------------------------------------------------------------------ render

SyntheticScene Render(const SyntheticSpec& spec) {
  return Render(spec, SyntheticLens());
}

SyntheticScene Render(const SyntheticSpec& spec, const SyntheticLens& lens) {
  Require(spec.width > 0 && spec.height > 0, "synthetic spec: image size ",
          spec.width, "x", spec.height, " must be positive");
  Require(spec.focal > 0, "synthetic spec: focal = ", spec.focal,
          " must be > 0");
  Require(lens.focal_y_ratio > 0,
          "synthetic spec: focal_y_ratio = ", lens.focal_y_ratio,
          " must be > 0");
  Require(spec.supersample >= 1,
          "synthetic spec: supersample = ", spec.supersample, " must be >= 1");
  Require(!spec.camera_centers.empty(), "synthetic spec: no cameras");
  Require(spec.lighting.empty() ||
              spec.lighting.size() == spec.camera_centers.size(),
          "synthetic spec: lighting has ", spec.lighting.size(),
          " entries for ", spec.camera_centers.size(), " cameras");
  Require(
      spec.focals.empty() || spec.focals.size() == spec.camera_centers.size(),
      "synthetic spec: focals has ", spec.focals.size(), " entries for ",
      spec.camera_centers.size(), " cameras");
  Require(spec.noise_sigma >= 0 && spec.sparse_pixel_noise >= 0,
          "synthetic spec: noise must be >= 0");
  Require(spec.look_ats.empty() ||
              spec.look_ats.size() == spec.camera_centers.size(),
          "synthetic spec: look_ats has ", spec.look_ats.size(),
          " entries for ", spec.camera_centers.size(), " cameras");
  for (const ViewLighting& l : spec.lighting) {
    Require(
        l.exposure > 0 && l.gamma > 0 && (l.white_balance.array() > 0).all(),
        "synthetic spec: lighting needs exposure, gamma and white "
        "balance > 0");
    Require(l.ambient >= 0 && l.ambient <= 1,
            "synthetic spec: ambient = ", l.ambient, " must be in [0, 1]");
  }
  const std::vector<Prepared> objs = Prepare(spec.objects);
  const int n = static_cast<int>(spec.camera_centers.size());
  const int W = spec.width, H = spec.height, ss = spec.supersample;

  SyntheticScene out;
  out.spec = spec;
  out.scene.source = "synthetic scene";
  for (int i = 0; i < n; ++i) {
    View v;
    char name[32];
    std::snprintf(name, sizeof(name), "view_%03d.png", i);
    v.name = name;
    v.camera =
        LookAtCamera(spec.camera_centers[i],
                     spec.look_ats.empty() ? spec.look_at : spec.look_ats[i], W,
                     H, spec.focals.empty() ? spec.focal : spec.focals[i]);
    v.camera.fy = lens.focal_y_ratio * v.camera.fx;
    v.camera.cx += lens.principal_offset.x();
    v.camera.cy += lens.principal_offset.y();
    v.distortion = lens.distortion;
    out.scene.views.push_back(v);
  }
  out.images.resize(n);
  out.depth.resize(n);
  out.normals.resize(n);
  out.object_id.resize(n);

  ThreadPool pool(0);
  for (int i = 0; i < n; ++i) {
    const Camera& cam = out.scene.views[i].camera;
    const Eigen::Vector3d C = cam.Center();
    const ViewLighting light =
        spec.lighting.empty() ? ViewLighting() : spec.lighting[i];
    cv::Mat img(H, W, CV_32FC3), dep(H, W, CV_32F), nor(H, W, CV_32FC3),
        ids(H, W, CV_32S);
    const double inv_gamma = 1.0 / light.gamma;
    const bool distorted = !lens.distortion.IsNone();
    const Eigen::Vector3d sun = light.sun.squaredNorm() > 0
                                    ? Eigen::Vector3d(light.sun.normalized())
                                    : Eigen::Vector3d::Zero();
    pool.ParallelFor(H, [&](int r) {
      std::mt19937 rng(spec.seed * 2654435761u + i * 40503u + r * 7u + 1u);
      std::normal_distribution<double> gauss(0.0, 1.0);
      auto* ip = img.ptr<cv::Vec3f>(r);
      auto* dp = dep.ptr<float>(r);
      auto* np = nor.ptr<cv::Vec3f>(r);
      auto* op = ids.ptr<int>(r);
      for (int c = 0; c < W; ++c) {
        // Ground truth at the pixel centre.
        const Eigen::Vector3d dc = RayDir(cam, c + 0.5, r + 0.5);
        const Hit h = Cast(objs, i, C, dc);
        if (h.object >= 0) {
          Eigen::Vector3d nc = cam.R * h.normal;
          if (nc.dot(cam.R * dc) > 0) nc = -nc;
          dp[c] = static_cast<float>(h.z);
          np[c] = cv::Vec3f(nc.x(), nc.y(), nc.z());
          op[c] = h.object;
        } else {
          dp[c] = 0.f;
          np[c] = cv::Vec3f(0, 0, 0);
          op[c] = -1;
        }
        // Radiance: mean over the sub-samples.
        Eigen::Vector3d L = Eigen::Vector3d::Zero();
        for (int sy = 0; sy < ss; ++sy) {
          for (int sx = 0; sx < ss; ++sx) {
            const double u = c + (sx + 0.5) / ss, v = r + (sy + 0.5) / ss;
            Eigen::Vector2d p(u, v);
            if (distorted) p = UndistortedPixel(cam, lens.distortion, u, v);
            const Eigen::Vector3d d = RayDir(cam, p.x(), p.y());
            const Hit s = Cast(objs, i, C, d);
            Eigen::Vector3d Ls;
            if (s.object < 0) {
              if (!spec.sky) continue;
              const double elev = d.normalized().z();
              Ls = (0.25 + 0.1 * elev) *
                   (light.overcast ? Eigen::Vector3d(0.85, 0.85, 0.85)
                                   : Eigen::Vector3d(0.8, 0.9, 1.0));
            } else if (light.overcast) {
              const Eigen::Vector3d X = C + s.z * d;
              Eigen::Vector3d nw = s.normal;
              if (nw.dot(d) > 0) nw = -nw;  // the side facing the camera
              const double sky_light = 0.5 * (1.0 + nw.z());
              Ls = 0.4 * (light.ambient + (1.0 - light.ambient) * sky_light) *
                   Albedo(objs[s.object].obj, objs[s.object].base, X);
            } else if (sun.squaredNorm() > 0) {
              const Eigen::Vector3d X = C + s.z * d;
              Eigen::Vector3d nw = s.normal;
              if (nw.dot(d) > 0) nw = -nw;  // the side facing the camera
              const double ndl = nw.dot(sun);
              double lit = 0;
              if (ndl > 0) {
                const Hit sh = Cast(objs, i, X + 1e-6 * nw, sun);
                lit = sh.object < 0 ? ndl : 0.0;
              }
              Ls = 0.4 * (light.ambient + (1.0 - light.ambient) * lit) *
                   Albedo(objs[s.object].obj, objs[s.object].base, X);
            } else {
              Ls = Radiance(objs[s.object], C + s.z * d, s.normal);
            }
            if (light.vignetting > 0) {
              const double rx = (u - 0.5 * W) / (0.5 * W),
                           ry = (v - 0.5 * H) / (0.5 * H);
              Ls *= 1.0 - light.vignetting * 0.5 * (rx * rx + ry * ry);
            }
            L += Ls;
          }
        }
        L /= ss * ss;
        float rgb[3];
        for (int k = 0; k < 3; ++k) {
          float val =
              Respond(L[k], light.exposure * light.white_balance[k], inv_gamma);
          if (spec.noise_sigma > 0)
            val += static_cast<float>(spec.noise_sigma * gauss(rng));
          val = std::clamp(val, 0.f, 1.f);
          if (spec.quantize) val = Quantize(val);
          rgb[k] = val;
        }
        ip[c] = cv::Vec3f(rgb[0], rgb[1], rgb[2]);
      }
    });
    out.images[i] = img;
    out.depth[i] = dep;
    out.normals[i] = nor;
    out.object_id[i] = ids;
  }

  // Scene size: diagonal of the bounding box of the persistent objects.
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(kInf),
                  hi = Eigen::Vector3d::Constant(-kInf);
  for (const SyntheticObject& o : spec.objects)
    if (o.only_in_view < 0) ExtendBounds(o, &lo, &hi);
  out.scene_size = lo.allFinite() ? (hi - lo).norm() : 1.0;

  // Sparse points: random surface points seen by a random view, kept when
  // they are visible (same nearest hit) in at least two views.
  std::mt19937 rng(spec.seed);
  std::uniform_int_distribution<int> pick_view(0, n - 1);
  std::uniform_real_distribution<double> pu(0.0, W), pv(0.0, H);
  std::normal_distribution<double> obs_noise(0.0, 1.0);
  const int max_attempts = 200 * std::max(1, spec.num_sparse_points) + 1000;
  for (int attempt = 0;
       attempt < max_attempts &&
       static_cast<int>(out.scene.points.size()) < spec.num_sparse_points;
       ++attempt) {
    const int i = pick_view(rng);
    const Camera& cam = out.scene.views[i].camera;
    const double u = pu(rng), v = pv(rng);
    const Eigen::Vector3d d = RayDir(cam, u, v);
    const Hit h = Cast(objs, i, cam.Center(), d);
    if (h.object < 0 || objs[h.object].obj.only_in_view >= 0) continue;
    const Eigen::Vector3d X = cam.Center() + h.z * d;
    SparsePoint sp;
    sp.xyz = X;
    for (int j = 0; j < n; ++j) {
      const Camera& cj = out.scene.views[j].camera;
      Eigen::Vector2d px;
      if (!cj.Project(X, &px) || !cj.InImage(px, 1.0)) continue;
      const double zj = cj.Depth(X);
      const Hit hj = Cast(objs, j, cj.Center(), RayDir(cj, px.x(), px.y()));
      if (hj.object != h.object || std::abs(hj.z - zj) > 1e-6 * zj) continue;
      Observation ob;
      ob.view = j;
      ob.xy = px;
      if (spec.sparse_pixel_noise > 0) {
        ob.xy += spec.sparse_pixel_noise *
                 Eigen::Vector2d(obs_noise(rng), obs_noise(rng));
      }
      ob.scale = 2.0;
      sp.track.push_back(ob);
    }
    if (sp.track.size() < 2) continue;
    Eigen::Vector3d nn = h.normal;
    const Eigen::Vector3d a = Radiance(objs[h.object], X, nn);
    sp.rgb = a.cast<float>();
    out.scene.points.push_back(sp);
  }
  return out;
}

ImageCache::Loader SyntheticScene::Loader() const {
  std::vector<cv::Mat> imgs = images;  // shares the pixel buffers
  return [imgs](int view) -> cv::Mat {
    Require(view >= 0 && view < static_cast<int>(imgs.size()),
            "synthetic scene: no view ", view, " (", imgs.size(), " views)");
    return imgs[view].clone();
  };
}

PointCloud SyntheticScene::GroundTruthCloud(int stride) const {
  Require(stride >= 1, "GroundTruthCloud: stride = ", stride, " must be >= 1");
  PointCloud cloud;
  Require(depth.size() == scene.views.size() &&
              normals.size() == depth.size() && images.size() == depth.size() &&
              object_id.size() == depth.size(),
          "GroundTruthCloud: the scene's per-view maps are inconsistent");
  for (size_t i = 0; i < depth.size(); ++i) {
    const Camera& cam = scene.views[i].camera;
    const Eigen::Matrix3d Rt = cam.R.transpose();
    Require(depth[i].type() == CV_32F && normals[i].size() == depth[i].size() &&
                images[i].size() == depth[i].size() &&
                object_id[i].size() == depth[i].size(),
            "GroundTruthCloud: view ", i, " maps differ in size or type");
    for (int r = 0; r < depth[i].rows; r += stride) {
      for (int c = 0; c < depth[i].cols; c += stride) {
        const float z = depth[i].at<float>(r, c);
        if (!(z > 0)) continue;
        const int id = object_id[i].at<int>(r, c);
        if (id < 0 || id >= static_cast<int>(spec.objects.size()) ||
            spec.objects[id].only_in_view >= 0)
          continue;
        const Eigen::Vector3d X = cam.Backproject({c + 0.5, r + 0.5}, z);
        const cv::Vec3f nc = normals[i].at<cv::Vec3f>(r, c);
        const Eigen::Vector3d nw = Rt * Eigen::Vector3d(nc[0], nc[1], nc[2]);
        const cv::Vec3f col = images[i].at<cv::Vec3f>(r, c);
        cloud.xyz.push_back(X.cast<float>());
        cloud.normal.push_back(nw.cast<float>());
        cloud.rgb.emplace_back(LinearToSrgb(col[0]), LinearToSrgb(col[1]),
                               LinearToSrgb(col[2]));
      }
    }
  }
  return cloud;
}

// ---------------------------------------------------------------- presets

std::vector<Eigen::Vector3d> MakeRingCameras(int n, double radius,
                                             double height, double arc_deg) {
  Require(n >= 1, "MakeRingCameras: n = ", n, " must be >= 1");
  std::vector<Eigen::Vector3d> out;
  const bool full = arc_deg >= 360.0;
  for (int k = 0; k < n; ++k) {
    double deg;
    if (full) {
      deg = 360.0 * k / n;
    } else {
      deg = n == 1 ? 0.0 : -arc_deg / 2 + arc_deg * k / (n - 1);
    }
    const double a = deg * M_PI / 180.0;
    out.emplace_back(radius * std::sin(a), -radius * std::cos(a), height);
  }
  return out;
}

SyntheticSpec SlantedPlaneSpec(double slant_deg, int n) {
  SyntheticSpec s;
  SyntheticObject plane;
  plane.type = SyntheticObject::Type::kPlane;
  const double a = slant_deg * M_PI / 180.0;
  // Facing -y (towards the cameras) before the slant about the vertical axis.
  plane.center = Eigen::Vector3d(0, 0, 0);
  plane.axis_u = Eigen::Vector3d(std::cos(a), std::sin(a), 0);
  plane.axis_v = Eigen::Vector3d(0, 0, 1);
  plane.size = Eigen::Vector3d(3.0, 1.6, 1);
  plane.texture_seed = 3;
  plane.texture_scale = 0.05;
  s.objects.push_back(plane);
  s.camera_centers = MakeRingCameras(n, 2.0, 0.0, 20.0);
  s.look_at = Eigen::Vector3d(0, 0, 0);
  return s;
}

SyntheticSpec ClutteredSceneSpec(bool vary_lighting, bool occluder,
                                 double arc_deg) {
  SyntheticSpec s;
  using T = SyntheticObject::Type;
  SyntheticObject ground;
  ground.type = T::kPlane;
  ground.center = Eigen::Vector3d(0, 0, 0);
  ground.axis_u = Eigen::Vector3d(1, 0, 0);
  ground.axis_v = Eigen::Vector3d(0, 1, 0);
  ground.size = Eigen::Vector3d(2.2, 2.2, 1);
  ground.texture_seed = 11;
  ground.texture_scale = 0.06;
  s.objects.push_back(ground);

  SyntheticObject box1;
  box1.type = T::kBox;
  box1.center = Eigen::Vector3d(0.45, 0.3, 0.25);
  box1.size = Eigen::Vector3d(0.28, 0.22, 0.25);
  box1.rotation = Eigen::AngleAxisd(30 * M_PI / 180, Eigen::Vector3d::UnitZ())
                      .toRotationMatrix();
  box1.texture_seed = 21;
  box1.texture_scale = 0.05;
  s.objects.push_back(box1);

  SyntheticObject box2;
  box2.type = T::kBox;
  box2.center = Eigen::Vector3d(-0.5, -0.25, 0.2);
  box2.size = Eigen::Vector3d(0.2, 0.3, 0.2);
  box2.rotation = Eigen::AngleAxisd(-20 * M_PI / 180, Eigen::Vector3d::UnitZ())
                      .toRotationMatrix();
  box2.texture_seed = 31;
  box2.texture_scale = 0.05;
  s.objects.push_back(box2);

  SyntheticObject sphere;
  sphere.type = T::kSphere;
  sphere.center = Eigen::Vector3d(-0.15, 0.55, 0.3);
  sphere.size = Eigen::Vector3d(0.3, 0.3, 0.3);
  sphere.texture_seed = 41;
  sphere.texture_scale = 0.05;
  s.objects.push_back(sphere);

  s.camera_centers = MakeRingCameras(8, 2.6, 1.5, arc_deg);
  s.look_at = Eigen::Vector3d(0, 0, 0.15);

  if (occluder) {
    // A textured box 40 % of the way from camera 0 to the scene, off the
    // optical axis so it hides part of the scene in view 0 only.
    const Eigen::Vector3d c0 = s.camera_centers[0];
    const Eigen::Vector3d f = (s.look_at - c0).normalized();
    const Eigen::Vector3d right =
        f.cross(Eigen::Vector3d::UnitZ()).normalized();
    SyntheticObject occ;
    occ.type = T::kBox;
    occ.center = c0 + 0.4 * (s.look_at - c0) + 0.12 * right;
    occ.size = Eigen::Vector3d(0.12, 0.12, 0.15);
    occ.rotation = Eigen::AngleAxisd(15 * M_PI / 180, Eigen::Vector3d::UnitZ())
                       .toRotationMatrix();
    occ.texture_seed = 51;
    occ.texture_scale = 0.03;
    occ.only_in_view = 0;
    s.objects.push_back(occ);
  }

  if (vary_lighting) {
    static const double kExposure[8] = {1.0, 0.4, 2.5, 0.7, 1.6, 0.5, 2.0, 1.2};
    static const double kGamma[8] = {1.0, 2.2, 1.5, 1.0, 1.8, 2.2, 1.2, 1.6};
    static const double kWb[8][3] = {{1.0, 1.0, 1.0},    {1.3, 1.0, 0.75},
                                     {0.7, 1.0, 1.3},    {1.15, 0.9, 1.0},
                                     {0.8, 1.1, 1.2},    {1.3, 1.1, 0.7},
                                     {0.75, 0.95, 1.25}, {1.1, 1.0, 0.85}};
    for (int k = 0; k < 8; ++k) {
      ViewLighting l;
      l.exposure = kExposure[k];
      l.gamma = kGamma[k];
      l.white_balance = Eigen::Vector3d(kWb[k][0], kWb[k][1], kWb[k][2]);
      s.lighting.push_back(l);
    }
  }
  return s;
}

// ---------------------------------------------------------------- dataset

void WriteDataset(const SyntheticScene& s, const std::string& dir) {
  Require(s.images.size() == s.scene.views.size() &&
              s.depth.size() == s.scene.views.size(),
          "WriteDataset(", dir, "): scene has ", s.scene.views.size(),
          " views but ", s.images.size(), " images");
  WriteColmapText(s.scene, dir + "/sparse");
  for (size_t i = 0; i < s.images.size(); ++i) {
    const View& v = s.scene.views[i];
    // Linear -> 8-bit sRGB. When the scene was rendered with quantize, the
    // images hold exact 8-bit sRGB levels, so LoadViewImage of this PNG
    // returns `images[i]` exactly.
    cv::Mat out(s.images[i].size(), CV_8UC3);
    for (int r = 0; r < out.rows; ++r) {
      const auto* ip = s.images[i].ptr<cv::Vec3f>(r);
      auto* op = out.ptr<cv::Vec3b>(r);
      for (int c = 0; c < out.cols; ++c)
        for (int k = 0; k < 3; ++k)  // RGB -> BGR for OpenCV
          op[c][2 - k] = cv::saturate_cast<uchar>(
              std::round(LinearToSrgb(std::clamp(ip[c][k], 0.f, 1.f)) * 255.f));
    }
    const std::string path = dir + "/images/" + v.name;
    ProduceFileAtomically(path, [&](const std::string& tmp) {
      return cv::imwrite(tmp, out);  // tmp keeps the .png extension
    });
    WritePfm(dir + "/gt_depth/" + v.Stem() + ".pfm", s.depth[i]);
  }
}

}  // namespace testing
}  // namespace wild_mvs
