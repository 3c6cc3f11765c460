// Copyright wild_mvs authors. Multi-view triangulation with known cameras.
#include "wild_mvs/core/triangulation.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <limits>

namespace wild_mvs {

bool TriangulateLinear(const std::vector<TriangulationInput>& obs,
                       Eigen::Vector3d* X) {
  if (obs.size() < 2) return false;
  // Rows x_n * P3 - P1 and y_n * P3 - P2 in normalised coordinates, each row
  // scaled to unit norm; accumulate A^T A (4x4).
  Eigen::Matrix4d AtA = Eigen::Matrix4d::Zero();
  for (const TriangulationInput& o : obs) {
    const Camera& c = *o.camera;
    const double xn = (o.xy.x() - c.cx) / c.fx;
    const double yn = (o.xy.y() - c.cy) / c.fy;
    Eigen::Matrix<double, 3, 4> P;
    P.leftCols<3>() = c.R;
    P.col(3) = c.t;
    for (int k = 0; k < 2; ++k) {
      Eigen::Matrix<double, 1, 4> row =
          (k == 0 ? xn : yn) * P.row(2) - P.row(k);
      const double n = row.norm();
      if (!(n > 0)) return false;
      row /= n;
      AtA += row.transpose() * row;
    }
  }
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix4d> es(AtA);
  if (es.info() != Eigen::Success) return false;
  const Eigen::Vector4d h = es.eigenvectors().col(0);  // smallest eigenvalue
  // Degenerate when the two smallest eigenvalues are (nearly) equal: the
  // null space is not a single point.
  const Eigen::Vector4d ev = es.eigenvalues();
  if (!(ev(1) > 1e-14 * std::max(1.0, ev(3)))) return false;
  if (!(std::abs(h(3)) > 1e-12 * h.head<3>().norm())) return false;
  *X = h.head<3>() / h(3);
  return X->allFinite();
}

bool RefineTriangulation(const std::vector<TriangulationInput>& obs,
                         Eigen::Vector3d* X, int iterations) {
  auto cost = [&obs](const Eigen::Vector3d& P) {
    double sum = 0;
    for (const TriangulationInput& o : obs) {
      const Eigen::Vector3d Xc = o.camera->WorldToCamera(P);
      if (!(Xc.z() > 0)) return std::numeric_limits<double>::infinity();
      sum += (o.camera->ProjectCam(Xc) - o.xy).squaredNorm();
    }
    return sum;
  };
  if (!X->allFinite()) return false;
  double current = cost(*X);
  double lambda = 1e-4;
  for (int it = 0; it < iterations && std::isfinite(current); ++it) {
    Eigen::Matrix3d H = Eigen::Matrix3d::Zero();
    Eigen::Vector3d g = Eigen::Vector3d::Zero();
    for (const TriangulationInput& o : obs) {
      const Camera& c = *o.camera;
      const Eigen::Vector3d Xc = c.WorldToCamera(*X);
      const double iz = 1.0 / Xc.z();
      const Eigen::Vector2d r = c.ProjectCam(Xc) - o.xy;
      // d(u,v)/d(Xc), then chain with d(Xc)/dX = R.
      Eigen::Matrix<double, 2, 3> Jc;
      Jc << c.fx * iz, 0, -c.fx * Xc.x() * iz * iz, 0, c.fy * iz,
          -c.fy * Xc.y() * iz * iz;
      const Eigen::Matrix<double, 2, 3> J = Jc * c.R;
      H += J.transpose() * J;
      g += J.transpose() * r;
    }
    bool improved = false;
    for (int attempt = 0; attempt < 8; ++attempt) {
      Eigen::Matrix3d Hd = H;
      Hd.diagonal() *= 1.0 + lambda;
      const Eigen::Vector3d step = Hd.ldlt().solve(-g);
      if (!step.allFinite()) break;
      const Eigen::Vector3d candidate = *X + step;
      const double c = cost(candidate);
      if (c < current) {
        const bool tiny = step.norm() <= 1e-12 * (1.0 + X->norm()) ||
                          current - c <= 1e-12 * current;
        *X = candidate;
        current = c;
        lambda = std::max(lambda * 0.1, 1e-10);
        improved = !tiny;
        break;
      }
      lambda *= 10;
    }
    if (!improved) break;
  }
  return X->allFinite() && std::isfinite(current);
}

bool Triangulate(const std::vector<TriangulationInput>& obs, Eigen::Vector3d* X,
                 int iterations) {
  return TriangulateLinear(obs, X) && RefineTriangulation(obs, X, iterations);
}

double ReprojectionError(const Camera& camera, const Eigen::Vector3d& X,
                         const Eigen::Vector2d& xy) {
  const Eigen::Vector3d Xc = camera.WorldToCamera(X);
  if (!(Xc.z() > 0)) return std::numeric_limits<double>::infinity();
  return (camera.ProjectCam(Xc) - xy).norm();
}

double TriangulationAngle(const Eigen::Vector3d& center1,
                          const Eigen::Vector3d& center2,
                          const Eigen::Vector3d& X) {
  const Eigen::Vector3d a = center1 - X, b = center2 - X;
  // atan2 of |a x b| and a.b is accurate for small and large angles.
  return std::atan2(a.cross(b).norm(), a.dot(b));
}

double MaxTriangulationAngle(const std::vector<TriangulationInput>& obs,
                             const Eigen::Vector3d& X) {
  double best = 0;
  std::vector<Eigen::Vector3d> rays;
  rays.reserve(obs.size());
  for (const TriangulationInput& o : obs) {
    rays.push_back((o.camera->Center() - X).normalized());
  }
  for (size_t i = 0; i < rays.size(); ++i) {
    for (size_t j = i + 1; j < rays.size(); ++j) {
      best = std::max(best, std::atan2(rays[i].cross(rays[j]).norm(),
                                       rays[i].dot(rays[j])));
    }
  }
  return best;
}

Eigen::Matrix3d FundamentalMatrix(const Camera& camera1,
                                  const Camera& camera2) {
  // Relative pose x2 = R x1 + t; E = [t]x R; F = K2^-T E K1^-1.
  const Eigen::Matrix3d R = camera2.R * camera1.R.transpose();
  const Eigen::Vector3d t = camera2.t - R * camera1.t;
  Eigen::Matrix3d tx;
  tx << 0, -t.z(), t.y(), t.z(), 0, -t.x(), -t.y(), t.x(), 0;
  const Eigen::Matrix3d E = tx * R;
  return camera2.K().inverse().transpose() * E * camera1.K().inverse();
}

}  // namespace wild_mvs
