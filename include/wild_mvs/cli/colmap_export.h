// Copyright wild_mvs authors. `wild_mvs reconstruct` into a COLMAP dense
// workspace: after the depth (and fuse) stages, the results in OUT are
// written into the workspace as `colmap patch_match_stereo` and
// `colmap stereo_fusion` would (io/colmap_dense.h), so that COLMAP's own
// stereo_fusion, poisson_mesher and delaunay_mesher run on them.
#pragma once

#include <ostream>
#include <string>
#include <vector>

#include "wild_mvs/core/scene.h"

namespace wild_mvs {
namespace cli {

struct ColmapExportResult {
  int views = 0;                      // views whose maps were written
  size_t points = 0;                  // points of WS/fused.ply (0: not written)
  bool photometric_from_raw = false;  // photometric = OUT/raw (else = OUT)
};

// For every view of `views` with finished maps in OUT: WS/stereo/depth_maps
// and normal_maps NAME.geometric.bin (OUT's maps, after the consistency
// filter) and NAME.photometric.bin (OUT/raw's maps before it when present,
// else the same maps); WS/stereo/patch-match.cfg (each view's neighbours)
// and fusion.cfg; when OUT/fused.ply exists, WS/fused.ply + .vis (a view
// sees a point when its geometric map agrees within `depth_tolerance`,
// relative). Image indices and camera sizes come from WS/sparse; a view
// missing there, or whose depth map's camera is not WS's camera resized to
// the map, is an Error naming both.
ColmapExportResult ExportToColmapWorkspace(
    const Scene& scene, const std::vector<int>& views, const std::string& out,
    const std::string& workspace, double depth_tolerance, std::ostream& log);

}  // namespace cli
}  // namespace wild_mvs
