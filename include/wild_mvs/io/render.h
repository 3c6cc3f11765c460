// Copyright wild_mvs authors. Small offscreen renderer for pictures of fused
// clouds and meshes (docs, previews): no OpenGL, no window.
//
// Points are drawn as z-buffered square splats whose side follows the
// cloud's sample spacing (perspective: near points are bigger); triangles
// are rasterised with a z-buffer (1/z interpolated in screen space, exact
// for planar faces) and flat-shaded. Lighting is Lambert from a light fixed
// to the camera (upper left, slightly behind the viewer) plus an ambient
// term, two-sided (a normal facing away from the viewer is flipped). Points
// with colour are drawn in their colour unless `shade_colors`; points
// without colour and all triangles are grey (or vertex colour when
// `mesh_vertex_colors`). Images are 8-bit BGR, ready for cv::imwrite /
// WriteImageAtomically; pixels that nothing covers get the background.
#pragma once

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "wild_mvs/core/camera.h"
#include "wild_mvs/core/point_cloud.h"

namespace wild_mvs {

struct RenderOptions {
  // Splat side in world units; 0 = automatic (1.5 x the median distance
  // between a point and its nearest neighbour, over a subsample).
  double point_size = 0;
  // Splat side in pixels is clamped to [min_splat_px, max_splat_px].
  double min_splat_px = 1.0;
  double max_splat_px = 12.0;
  // Light direction in the camera frame (x right, y down, z forward),
  // pointing from the light towards the scene; normalised internally.
  Eigen::Vector3d light_dir_cam = Eigen::Vector3d(0.4, 0.6, 1.0);
  // Ambient fraction of the shading, in [0, 1].
  double ambient = 0.25;
  // Grey albedo of uncoloured points and of triangles, in [0, 1].
  double albedo = 0.85;
  // Points with colour: multiply their colour by the Lambert shading
  // (true) or draw the colour as is (false, a photo-like look).
  bool shade_colors = false;
  // Meshes: use vertex colours (averaged over the face) instead of grey.
  bool mesh_vertex_colors = false;
  // Render at this many times the resolution and shrink (anti-aliasing).
  int supersample = 2;
  // Background colour, RGB in [0, 1].
  Eigen::Vector3d background = Eigen::Vector3d(1, 1, 1);

  // Throws Error naming the option when a value is out of range.
  void Check() const;
};

// A camera of width x height pixels (horizontal field of view `hfov_deg`,
// principal point at the centre) with the rotation of `orientation`
// (world-to-camera; its position is ignored), placed on the optical axis
// through the centre of the points' robust bounding box (2nd..98th
// percentiles per axis) and pulled back until that box, seen from there,
// fills the image up to `margin` (a fraction of each side). Throws Error
// when the cloud is empty.
Camera FitCameraToPoints(const std::vector<Eigen::Vector3f>& points,
                         const Eigen::Matrix3d& orientation, int width,
                         int height, double hfov_deg = 40,
                         double margin = 0.05);

// A viewing rotation (world-to-camera) when no dataset camera is wanted:
// the optical axis is the direction of least spread of the points (PCA),
// looking against the points' mean normal (along +z without normals); image
// "up" (camera -y) is `up_hint` made orthogonal to the axis, or the
// direction of largest spread when `up_hint` is zero or along the axis.
Eigen::Matrix3d AutoViewRotation(const PointCloud& cloud,
                                 const Eigen::Vector3d& up_hint);

// Point splats seen by `camera` (image of camera.width x camera.height).
cv::Mat RenderPointCloud(const PointCloud& cloud, const Camera& camera,
                         const RenderOptions& options = {});
// Flat-shaded triangles (mesh.faces; vertices from mesh.vertices).
cv::Mat RenderMesh(const Mesh& mesh, const Camera& camera,
                   const RenderOptions& options = {});

}  // namespace wild_mvs
