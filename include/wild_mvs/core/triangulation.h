// Copyright wild_mvs authors. Multi-view triangulation with known cameras.
//
// Observations are pixel coordinates in the convention of camera.h. The
// linear method (DLT) works in normalised camera coordinates (K^-1 x) for
// conditioning; the refinement minimises the sum of squared reprojection
// errors in pixels (Gauss-Newton with Levenberg-Marquardt damping).
#pragma once

#include <Eigen/Core>
#include <vector>

#include "wild_mvs/core/camera.h"

namespace wild_mvs {

// One observation of a 3-D point: the camera it is seen in and where.
struct TriangulationInput {
  const Camera* camera = nullptr;
  Eigen::Vector2d xy{0, 0};
};

// Linear multi-view triangulation (homogeneous DLT, smallest singular
// vector). Needs >= 2 observations. Returns false when the system is
// degenerate (e.g. identical camera centres) or the point is at infinity.
bool TriangulateLinear(const std::vector<TriangulationInput>& obs,
                       Eigen::Vector3d* X);

// Refines X in place by minimising the squared reprojection error over all
// observations (at most `iterations` Gauss-Newton/LM steps; stops when the
// step is negligible). Returns false when X is not finite or behind a camera
// after refinement (X is then left at the best finite estimate).
bool RefineTriangulation(const std::vector<TriangulationInput>& obs,
                         Eigen::Vector3d* X, int iterations = 10);

// Linear then nonlinear. Returns false when either fails.
bool Triangulate(const std::vector<TriangulationInput>& obs, Eigen::Vector3d* X,
                 int iterations = 10);

// Reprojection error in pixels (infinity when X is behind the camera).
double ReprojectionError(const Camera& camera, const Eigen::Vector3d& X,
                         const Eigen::Vector2d& xy);

// Angle (radians) between the lines of sight from two camera centres to X.
double TriangulationAngle(const Eigen::Vector3d& center1,
                          const Eigen::Vector3d& center2,
                          const Eigen::Vector3d& X);
// Largest pairwise triangulation angle (radians) over the observations.
double MaxTriangulationAngle(const std::vector<TriangulationInput>& obs,
                             const Eigen::Vector3d& X);

// Fundamental matrix F with x2^T F x1 = 0 for homogeneous pixel coordinates
// (camera.h convention) of the same world point in cameras 1 and 2.
Eigen::Matrix3d FundamentalMatrix(const Camera& camera1, const Camera& camera2);

}  // namespace wild_mvs
