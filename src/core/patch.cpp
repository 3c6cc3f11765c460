// Copyright wild_mvs authors.
#include "wild_mvs/core/patch.h"

#include <Eigen/Geometry>
#include <cmath>

#include "wild_mvs/core/error.h"

namespace wild_mvs {

void PatchContext::AddView(int scene_view, const Camera& cam,
                           const MatchImage& image, double global_score) {
  Require(static_cast<int>(views.size()) < kMaxNeighbors,
          "PatchContext: at most ", kMaxNeighbors, " neighbours");
  Require(image.width == cam.width && image.height == cam.height,
          "PatchContext: image of view ", scene_view, " is ", image.width, "x",
          image.height, " but its camera ", cam.width, "x", cam.height);
  Require(image.width >= 2 && image.height >= 2, "PatchContext: image of view ",
          scene_view, " is too small");
  const Camera& r = ref_camera;
  PatchView v;
  v.scene_view = scene_view;
  v.image = image;
  v.A = cam.K() * cam.R * r.R.transpose() * r.K().inverse();
  v.b = cam.K() * (cam.R * r.Center() + cam.t);
  v.epipole = r.K() * (r.R * cam.Center() + r.t);
  v.global_score = global_score;
  views.push_back(v);
}

double PlaneToPatch(const Camera& c, int s, int t, double z,
                    const Eigen::Vector3d& n, double* hs, double* ht) {
  const double u = s + 0.5, v = t + 0.5;
  const Eigen::Vector3d r0 = RayAt(c, u, v);
  const double h = z / r0.z();
  const double d = n.dot(r0 * h);  // plane: n . X = d
  auto h_at = [&](double uu, double vv) {
    const double den = n.dot(RayAt(c, uu, vv));
    if (std::abs(den) < 1e-9) return h;
    return d / den;
  };
  *hs = 0.5 * (h_at(u + 1, v) - h_at(u - 1, v));
  *ht = 0.5 * (h_at(u, v + 1) - h_at(u, v - 1));
  if (!std::isfinite(*hs) || !std::isfinite(*ht)) *hs = *ht = 0;
  return h;
}

Eigen::Vector3d PatchNormal(const Camera& c, int s, int t, double h, double hs,
                            double ht) {
  const double u = s + 0.5, v = t + 0.5;
  const Eigen::Vector3d tu =
      RayAt(c, u + 1, v) * (h + hs) - RayAt(c, u - 1, v) * (h - hs);
  const Eigen::Vector3d tv =
      RayAt(c, u, v + 1) * (h + ht) - RayAt(c, u, v - 1) * (h - ht);
  Eigen::Vector3d n = tv.cross(tu);  // = -(tu x tv): towards the camera
  const double len = n.norm();
  if (!(len > 0)) return Eigen::Vector3d(0, 0, -1);
  n /= len;
  if (n.dot(RayAt(c, u, v)) > 0) n = -n;
  return n;
}

double PlaneDepthAt(const Camera& c, int s, int t, const Eigen::Vector3d& X0,
                    const Eigen::Vector3d& n, double fallback) {
  const Eigen::Vector3d d((s + 0.5 - c.cx) / c.fx, (t + 0.5 - c.cy) / c.fy,
                          1.0);
  const double den = n.dot(d);
  if (std::abs(den) < 1e-6) return fallback;
  const double z = n.dot(X0) / den;
  if (!(z > 0) || !std::isfinite(z)) return fallback;
  return z;
}

}  // namespace wild_mvs
