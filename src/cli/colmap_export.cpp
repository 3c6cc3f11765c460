// Copyright wild_mvs authors.
#include "wild_mvs/cli/colmap_export.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <map>

#include "wild_mvs/core/error.h"
#include "wild_mvs/io/colmap.h"
#include "wild_mvs/io/colmap_dense.h"
#include "wild_mvs/io/depth_map_io.h"
#include "wild_mvs/io/ply.h"

namespace wild_mvs {
namespace cli {

namespace fs = std::filesystem;

namespace {

// COLMAP scales the workspace camera to a smaller map by the ratio of the
// sizes, per axis; the map's own camera must be exactly that.
void CheckSameCamera(const Camera& map_cam, const Camera& ws_cam,
                     const std::string& name, const std::string& ws_model) {
  const Camera expect = ws_cam.Resized(map_cam.width, map_cam.height);
  const double err = std::max(
      {std::abs(expect.fx - map_cam.fx), std::abs(expect.fy - map_cam.fy),
       std::abs(expect.cx - map_cam.cx), std::abs(expect.cy - map_cam.cy)});
  const double pose =
      (expect.R - map_cam.R).norm() +
      (expect.t - map_cam.t).norm() / std::max(1.0, expect.t.norm());
  Require(err < 1e-3 * std::max(1, map_cam.width) && pose < 1e-6, name,
          ": the depth map's camera (fx=", map_cam.fx, " fy=", map_cam.fy,
          " cx=", map_cam.cx, " cy=", map_cam.cy, ") is not the camera of ",
          ws_model, " resized to ", map_cam.width, "x", map_cam.height,
          " (fx=", expect.fx, " fy=", expect.fy, " cx=", expect.cx,
          " cy=", expect.cy,
          ") or its pose differs: reconstruct from this workspace "
          "(undistorted PINHOLE images) to write into it");
}

}  // namespace

ColmapExportResult ExportToColmapWorkspace(
    const Scene& scene, const std::vector<int>& views, const std::string& out,
    const std::string& workspace, double depth_tolerance, std::ostream& log) {
  const std::string ws_model = (fs::path(workspace) / "sparse").string();
  const Scene ws = ReadColmapModel(ws_model);
  std::map<std::string, int> ws_index;
  for (size_t i = 0; i < ws.views.size(); ++i)
    ws_index[ws.views[i].name] = static_cast<int>(i);

  ColmapExportResult r;
  std::vector<ColmapStereoEntry> entries;
  std::vector<std::pair<int, std::string>> written;  // WS index, stem
  for (int v : views) {
    const View& view = scene.views[v];
    const std::string stem = view.Stem();
    if (!DepthMapFilesExist(out, stem)) continue;
    const auto it = ws_index.find(view.name);
    Require(it != ws_index.end(), ws_model, ": image '", view.name,
            "' of the reconstruction is not in the workspace's model");
    DepthMapFiles geometric = ReadDepthMapFiles(out, stem);
    CheckSameCamera(geometric.map.camera, ws.views[it->second].camera,
                    MakeDepthMapPaths(out, stem).camera, ws_model);
    WriteColmapDepthNormal(workspace, view.name, ColmapMapKind::kGeometric,
                           geometric.map);
    const std::string raw = out + "/raw";
    if (DepthMapFilesExist(raw, stem)) {
      const DepthMapFiles photometric = ReadDepthMapFiles(raw, stem);
      WriteColmapDepthNormal(workspace, view.name, ColmapMapKind::kPhotometric,
                             photometric.map);
      r.photometric_from_raw = true;
    } else {
      WriteColmapDepthNormal(workspace, view.name, ColmapMapKind::kPhotometric,
                             geometric.map);
    }
    entries.push_back({view.name, geometric.neighbor_names});
    written.emplace_back(it->second, stem);
    ++r.views;
  }
  WriteColmapStereoConfig(workspace, entries);

  const std::string fused = out + "/fused.ply";
  if (fs::exists(fused)) {
    const PointCloud cloud = ReadPlyCloud(fused);
    std::vector<std::vector<uint32_t>> vis(cloud.size());
    // Views in the workspace's order, so that each list is sorted.
    std::sort(written.begin(), written.end());
    for (const auto& [index, stem] : written) {
      const DepthMapFiles files = ReadDepthMapFiles(out, stem);
      AddPointVisibility(cloud, files.map, static_cast<uint32_t>(index),
                         depth_tolerance, &vis);
    }
    WriteColmapFusedCloud((fs::path(workspace) / "fused.ply").string(), cloud,
                          vis);
    r.points = cloud.size();
  }
  log << "colmap: " << r.views << " depth and normal maps (geometric; "
      << (r.photometric_from_raw ? "photometric = before the consistency "
                                   "filter"
                                 : "photometric = the same maps")
      << ") in " << workspace << "/stereo";
  if (r.points > 0) log << ", " << r.points << " points in fused.ply(.vis)";
  log << "\n";
  return r;
}

}  // namespace cli
}  // namespace wild_mvs
