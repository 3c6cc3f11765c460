// Copyright wild_mvs authors.
#include "wild_mvs/core/view_geometry.h"

namespace wild_mvs {

double FrustumGridOverlap(const Camera& cam, const Camera& other,
                          const std::vector<double>& depths) {
  constexpr int kGx = 8, kGy = 6;
  int in = 0, total = 0;
  for (double d : depths) {
    for (int gy = 0; gy < kGy; ++gy) {
      for (int gx = 0; gx < kGx; ++gx) {
        const Eigen::Vector2d px((gx + 0.5) * cam.width / kGx,
                                 (gy + 0.5) * cam.height / kGy);
        Eigen::Vector2d q;
        ++total;
        if (other.Project(cam.Backproject(px, d), &q) && other.InImage(q)) {
          ++in;
        }
      }
    }
  }
  return total ? static_cast<double>(in) / total : 0.0;
}

bool AxesClosestApproachDepth(const Camera& a, const Camera& b, double min_sin2,
                              double* depth) {
  const Eigen::Vector3d c0 = a.Center(), d0 = a.ViewDirection();
  const Eigen::Vector3d c1 = b.Center(), d1 = b.ViewDirection();
  const Eigen::Vector3d w = c0 - c1;
  const double cos = d0.dot(d1), d = d0.dot(w), e = d1.dot(w);
  const double den = 1 - cos * cos;
  if (den < min_sin2) return false;      // near-parallel axes
  const double s = (cos * e - d) / den;  // along a's axis
  const double u = (e - cos * d) / den;  // along b's axis
  if (!(s > 0 && u > 0)) return false;
  *depth = s;
  return true;
}

}  // namespace wild_mvs
