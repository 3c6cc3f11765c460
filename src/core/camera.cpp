// Copyright wild_mvs authors.
#include "wild_mvs/core/camera.h"

#include <Eigen/SVD>
#include <cmath>

#include "wild_mvs/core/error.h"

namespace wild_mvs {

Eigen::Matrix3d Camera::K() const {
  Eigen::Matrix3d k;
  k << fx, 0, cx, 0, fy, cy, 0, 0, 1;
  return k;
}

Eigen::Matrix<double, 3, 4> Camera::P() const {
  Eigen::Matrix<double, 3, 4> rt;
  rt.leftCols<3>() = R;
  rt.col(3) = t;
  return K() * rt;
}

Eigen::Vector3d Camera::RayCam(const Eigen::Vector2d& px) const {
  return Eigen::Vector3d((px.x() - cx) / fx, (px.y() - cy) / fy, 1.0)
      .normalized();
}

Camera Camera::Resized(int new_width, int new_height) const {
  Camera c = *this;
  const double sx = static_cast<double>(new_width) / width;
  const double sy = static_cast<double>(new_height) / height;
  c.fx = fx * sx;
  c.fy = fy * sy;
  c.cx = cx * sx;
  c.cy = cy * sy;
  c.width = new_width;
  c.height = new_height;
  return c;
}

Camera Camera::Scaled(double factor) const {
  const int w = std::max(1, static_cast<int>(std::lround(width * factor)));
  const int h = std::max(1, static_cast<int>(std::lround(height * factor)));
  return Resized(w, h);
}

void Camera::Validate(const std::string& what) const {
  auto finite = [](double v) { return std::isfinite(v); };
  Require(finite(fx) && finite(fy) && finite(cx) && finite(cy), what,
          ": intrinsics are not finite (fx=", fx, " fy=", fy, " cx=", cx,
          " cy=", cy, ")");
  Require(fx > 0 && fy > 0, what, ": focal length must be positive (fx=", fx,
          " fy=", fy, ")");
  Require(width > 0 && height > 0, what, ": image size must be positive (",
          width, "x", height, ")");
  Require(R.allFinite() && t.allFinite(), what, ": pose contains NaN or Inf");
  const double orth = (R * R.transpose() - Eigen::Matrix3d::Identity()).norm();
  Require(orth < 1e-3, what,
          ": rotation is not orthonormal (|R R^T - I| = ", orth, ")");
  Require(R.determinant() > 0, what,
          ": rotation is a reflection (det R = ", R.determinant(), ")");
}

Eigen::Matrix3d NearestRotation(const Eigen::Matrix3d& R) {
  Eigen::JacobiSVD<Eigen::Matrix3d> svd(
      R, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d out = svd.matrixU() * svd.matrixV().transpose();
  if (out.determinant() < 0) {
    Eigen::Matrix3d u = svd.matrixU();
    u.col(2) *= -1;
    out = u * svd.matrixV().transpose();
  }
  return out;
}

}  // namespace wild_mvs
