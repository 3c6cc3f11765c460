// Copyright wild_mvs authors. Per-frame 3x4 projection matrices
// (pavilion_chair_sequence: cameras/NNN.projmatrix).
//
// Each file holds P (3 lines of 4 numbers), x ~ P [X; 1], pixel origin at the
// top-left with integer pixel centres (+0.5 is added to cx, cy, camera.h).
// P is decomposed by RQ into K (positive diagonal) and R (det +1), t =
// K^-1 P(:,3); a skew |K12| up to 1e-3 fx is dropped, more is an error.
// Images are matched to cameras by frame number: the trailing digits of the
// image file stem (".../midday-640x-0007.png" -> 7) equal the number of the
// .projmatrix file stem ("007" -> 7). Every image file (png/jpg/jpeg/tif/
// tiff/bmp/ppm) anywhere under images_dir with a matching camera becomes a
// View named by its path relative to images_dir (so several lightings of one
// frame become several views with the same camera). Image sizes come from
// the image headers.
#pragma once

#include <string>

#include "wild_mvs/core/scene.h"

namespace wild_mvs {

// Decomposes P = K [R | t] (P's overall sign and scale are free). Throws
// Error naming `what` when P is degenerate or K has a large skew.
Camera DecomposeProjectionMatrix(const Eigen::Matrix<double, 3, 4>& P,
                                 const std::string& what);

// Reads one .projmatrix file (no image size set).
Eigen::Matrix<double, 3, 4> ReadProjectionMatrix(const std::string& path);

Scene ReadProjectionMatrices(const std::string& cameras_dir,
                             const std::string& images_dir);

}  // namespace wild_mvs
