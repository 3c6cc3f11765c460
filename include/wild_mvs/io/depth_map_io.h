// Copyright wild_mvs authors. On-disk layout of `wild_mvs reconstruct`.
//
// For the depth map of a view with file stem S (View::Stem()):
//   OUT/depth/S.pfm          CV_32F z along the optical axis, 0 = unknown
//   OUT/normal/S.pfm         3 channels: unit normal, camera frame (x right,
//                            y down, z forward), 0 0 0 = unknown [optional]
//   OUT/confidence/S.pfm     CV_32F in [0, 1], 0 = unknown       [optional]
//   OUT/cameras/S.txt        the depth map's camera + neighbour names
//   OUT/preview/S_depth.png, S_confidence.png, S_normal.png  (previews)
// cameras/S.txt is written LAST, so its presence means the set is complete
// (DepthMapFilesExist, used to resume). Its format (text, '#' comments):
//   width height
//   fx fy cx cy                 (wild_mvs pixel convention, camera.h)
//   r11 r12 r13                 (world-to-camera rotation, 3 rows)
//   r21 r22 r23
//   r31 r32 r33
//   t1 t2 t3                    (world-to-camera translation)
//   N                           (number of neighbour views)
//   name_1                      (N lines: neighbour view names, in order;
//   ...                          a name may contain spaces)
// Every file is written atomically.
#pragma once

#include <string>
#include <vector>

#include "wild_mvs/core/depth_map.h"
#include "wild_mvs/core/scene.h"

namespace wild_mvs {

struct DepthMapPaths {
  std::string depth, normal, confidence, camera;
  std::string preview_depth, preview_confidence, preview_normal;
};
DepthMapPaths MakeDepthMapPaths(const std::string& out_dir,
                                const std::string& stem);

// Writes the files above (normal / confidence only when present in `map`,
// previews when `previews`). Throws Error on invalid maps (size mismatch
// between depth, normal, confidence and the camera) or write failure.
void WriteDepthMapFiles(const std::string& out_dir, const std::string& stem,
                        const DepthMap& map,
                        const std::vector<std::string>& neighbor_names,
                        bool previews = true);

struct DepthMapFiles {
  DepthMap map;  // view = -1, neighbors empty (indices are scene-specific)
  std::vector<std::string> neighbor_names;
};
// Reads depth + camera (+ normal / confidence when present). Throws Error
// naming the file and line for malformed or inconsistent files.
DepthMapFiles ReadDepthMapFiles(const std::string& out_dir,
                                const std::string& stem);
// Same, resolving the reference view (by stem) and the neighbour names to
// view indices of `scene` (Error when a name is not in the scene).
DepthMap ReadDepthMapFiles(const std::string& out_dir, const std::string& stem,
                           const Scene& scene);

// True when depth/S.pfm and cameras/S.txt exist.
bool DepthMapFilesExist(const std::string& out_dir, const std::string& stem);

// The camera file alone.
void WriteDepthMapCamera(const std::string& path, const Camera& camera,
                         const std::vector<std::string>& neighbor_names);
Camera ReadDepthMapCamera(const std::string& path,
                          std::vector<std::string>* neighbor_names);

}  // namespace wild_mvs
