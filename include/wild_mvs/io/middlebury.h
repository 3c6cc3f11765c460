// Copyright wild_mvs authors. Middlebury multi-view `*_par.txt` cameras.
//
// Format: first data line = number of images n; then one line per image:
//   name k11 k12 k13 k21 k22 k23 k31 k32 k33 r11 r12 r13 r21 r22 r23 r31 r32
//   r33 t1 t2 t3
// with P = K [R | t] world-to-camera. K uses integer pixel centres (the
// top-left pixel's centre is (0, 0)), so cx, cy get +0.5 (camera.h). K must
// have zero skew and last row (0 0 1) (up to a common scale); R is checked
// to be orthonormal (1e-3) and then re-orthonormalised. Image sizes are read
// from the image files (images_dir/name; default: the par file's folder).
// The format has no sparse points.
#pragma once

#include <string>

#include "wild_mvs/core/scene.h"

namespace wild_mvs {

Scene ReadMiddleburyPar(const std::string& par_file,
                        const std::string& images_dir = "");

}  // namespace wild_mvs
