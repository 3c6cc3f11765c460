// Copyright wild_mvs authors. Pinhole camera model.
//
// Conventions (used everywhere in wild_mvs; readers convert to them):
//  - Pose is world-to-camera: x_cam = R * x_world + t. Camera centre is
//    C = -R^T t. Camera frame is the optical frame of REP 103: x right,
//    y down, z forward (along the optical axis).
//  - Pixel coordinates are continuous with the COLMAP convention: the
//    top-left pixel covers [0,1) x [0,1) and its centre is (0.5, 0.5). The
//    pixel with integer index (col, row) has its centre at
//    (col + 0.5, row + 0.5). A projected point (u, v) = (fx * x / z + cx,
//    fy * y / z + cy).
//  - Depth is z along the optical axis, in scene units (metres on ROS). The
//    paper's h (distance along the viewing ray) is converted explicitly where
//    the patch model needs it.
//  - No distortion: images with lens distortion are undistorted at load, so
//    algorithms only ever see this model.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <string>

namespace wild_mvs {

struct Camera {
  double fx = 0, fy = 0, cx = 0, cy = 0;
  int width = 0, height = 0;
  Eigen::Matrix3d R = Eigen::Matrix3d::Identity();  // world-to-camera
  Eigen::Vector3d t = Eigen::Vector3d::Zero();      // world-to-camera

  Eigen::Matrix3d K() const;
  // 3x4 projection matrix K [R | t].
  Eigen::Matrix<double, 3, 4> P() const;
  Eigen::Vector3d Center() const { return -R.transpose() * t; }
  // Unit vector of the optical axis (camera +z) in world coordinates.
  Eigen::Vector3d ViewDirection() const { return R.row(2).transpose(); }

  Eigen::Vector3d WorldToCamera(const Eigen::Vector3d& X) const {
    return R * X + t;
  }
  Eigen::Vector3d CameraToWorld(const Eigen::Vector3d& Xc) const {
    return R.transpose() * (Xc - t);
  }
  // Projects a camera-frame point (z must be > 0) to pixel coordinates.
  Eigen::Vector2d ProjectCam(const Eigen::Vector3d& Xc) const {
    return {fx * Xc.x() / Xc.z() + cx, fy * Xc.y() / Xc.z() + cy};
  }
  // Projects a world point; returns false when it is not in front of the
  // camera (z <= 0). Does not test the image bounds (see InImage).
  bool Project(const Eigen::Vector3d& X, Eigen::Vector2d* px) const {
    const Eigen::Vector3d xc = WorldToCamera(X);
    if (!(xc.z() > 0)) return false;
    *px = ProjectCam(xc);
    return true;
  }
  // Depth (camera z) of a world point.
  double Depth(const Eigen::Vector3d& X) const {
    return R.row(2).dot(X) + t.z();
  }
  // Camera-frame point at pixel px with depth z (z along the optical axis).
  Eigen::Vector3d BackprojectCam(const Eigen::Vector2d& px, double z) const {
    return {(px.x() - cx) / fx * z, (px.y() - cy) / fy * z, z};
  }
  // World point at pixel px with depth z.
  Eigen::Vector3d Backproject(const Eigen::Vector2d& px, double z) const {
    return CameraToWorld(BackprojectCam(px, z));
  }
  // Unit viewing ray through pixel px, in the camera frame / world frame.
  Eigen::Vector3d RayCam(const Eigen::Vector2d& px) const;
  Eigen::Vector3d RayWorld(const Eigen::Vector2d& px) const {
    return R.transpose() * RayCam(px);
  }
  bool InImage(const Eigen::Vector2d& px, double margin = 0) const {
    return px.x() >= margin && px.y() >= margin && px.x() <= width - margin &&
           px.y() <= height - margin;
  }
  // Size in world units of one pixel at depth z (the paper's s_X(f)).
  double PixelFootprint(double z) const { return 2.0 * z / (fx + fy); }

  // The camera of the same view resampled to new_width x new_height (pixel
  // centres kept consistent: cx' = cx * sx with the (0.5, 0.5) convention).
  Camera Resized(int new_width, int new_height) const;
  // Resized by a factor (rounded size).
  Camera Scaled(double factor) const;

  // Throws Error naming `what` (e.g. "images.txt line 12") when the camera is
  // unusable: non-finite values, non-positive focal length or size,
  // non-orthonormal or reflecting rotation.
  void Validate(const std::string& what) const;
};

// Re-orthonormalises a rotation that is orthonormal up to rounding.
Eigen::Matrix3d NearestRotation(const Eigen::Matrix3d& R);

}  // namespace wild_mvs
