// Copyright wild_mvs authors. Strecha et al. (CVPR 2008) `.camera` files
// (fountain-P11, Herz-Jesus-P8, ...).
//
// One text file per image, NAME.camera (e.g. "0000.jpg.camera" for image
// "0000.jpg"), 9 lines:
//   K (3 lines, integer pixel centres)
//   radial distortion (1 line, 3 numbers; must be 0: images are undistorted)
//   R (3 lines) = camera-to-world rotation (columns = camera axes)
//   C (1 line)  = camera centre in world coordinates
//   width height
// Converted: R_w2c = R^T (checked orthonormal, re-orthonormalised),
// t = -R^T C, cx, cy += 0.5 (camera.h). The image size must match the file
// on disk (checked by LoadDataset).
#pragma once

#include <string>

#include "wild_mvs/core/scene.h"

namespace wild_mvs {

// Reads one .camera file.
Camera ReadStrechaCamera(const std::string& path);

// Every *.camera file in cameras_dir (sorted by name) becomes a View named
// by the file name minus ".camera", image_path = images_dir/name. No points.
Scene ReadStrechaCameras(const std::string& cameras_dir,
                         const std::string& images_dir);

}  // namespace wild_mvs
