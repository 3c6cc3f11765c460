// Copyright wild_mvs authors. COLMAP's dense workspace: the folder that
// `colmap image_undistorter --output_type COLMAP` writes and
// `colmap patch_match_stereo`, `stereo_fusion`, `poisson_mesher` and
// `delaunay_mesher` read and write:
//
//   WS/images/NAME                 undistorted images (PINHOLE cameras)
//   WS/sparse/                     the model (cameras, images, points3D .bin)
//   WS/stereo/depth_maps/NAME.{photometric,geometric}.bin
//   WS/stereo/normal_maps/NAME.{photometric,geometric}.bin
//   WS/stereo/patch-match.cfg      per image: its name, then a line with the
//                                  source images (comma-separated names, or
//                                  "__auto__, N" / "__all__")
//   WS/stereo/fusion.cfg           the names of the images to fuse, one a line
//   WS/fused.ply, WS/fused.ply.vis the fused cloud and its visibility
//
// NAME is the image's name in the model including its extension (and any
// sub-folder), e.g. depth_maps/image1.jpg.geometric.bin.
//
// Array files (.bin): an ASCII header "W&H&C&" (width, height, channels),
// then W*H*C little-endian float32, x fastest, then y, then channel (planar:
// the whole first channel, then the second...). Depth maps have C = 1: z along
// the optical axis in the model's units, 0 = unknown (wild_mvs's convention).
// Normal maps have C = 3: unit normals in the camera frame (x right, y down,
// z forward), facing the camera (n . ray < 0, as COLMAP's patch match keeps
// them), 0 0 0 = unknown; also wild_mvs's convention, so nothing is
// converted. A map may be smaller than its image: COLMAP scales the camera by
// the ratio of the sizes, per axis, as wild_mvs's Camera::Resized does.
//
// fused.ply: binary little-endian PLY, vertex x y z nx ny nz (float) red
// green blue (uchar). fused.ply.vis: uint64 number of points, then per point
// uint32 n and n uint32 image indices; an image index is the image's position
// in the model file (COLMAP's order of registered images; wild_mvs's
// ReadColmapModel keeps it, so it is the view index of the Scene read from
// WS/sparse).
#pragma once

#include <cstdint>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "wild_mvs/core/depth_map.h"
#include "wild_mvs/core/point_cloud.h"
#include "wild_mvs/core/scene.h"

namespace wild_mvs {

// Writes a CV_32F (C = 1) or CV_32FC3 (C = 3) matrix as a COLMAP array file,
// atomically. Throws Error naming the path for other types or empty images.
void WriteColmapArray(const std::string& path, const cv::Mat& image);
// Reads a COLMAP array file into a CV_32FC(C) matrix (C in 1..4). Throws
// Error naming the file for a bad header, a size that does not match the
// header, or more than 4 channels.
cv::Mat ReadColmapArray(const std::string& path);

// True when `dir` looks like a COLMAP dense workspace: dir/images and
// dir/stereo are folders and dir/sparse holds a model (.bin or .txt).
bool IsColmapDenseWorkspace(const std::string& dir);

// "geometric" or "photometric": COLMAP's two kinds of maps (photometric =
// before the consistency filter, geometric = after).
enum class ColmapMapKind { kPhotometric, kGeometric };
const char* ColmapMapKindName(ColmapMapKind kind);

// WS/stereo/depth_maps/NAME.KIND.bin and WS/stereo/normal_maps/NAME.KIND.bin.
std::string ColmapDepthMapPath(const std::string& workspace,
                               const std::string& name, ColmapMapKind kind);
std::string ColmapNormalMapPath(const std::string& workspace,
                                const std::string& name, ColmapMapKind kind);

// Writes `map`'s depth and normal (0 0 0 where the normal is missing) as the
// NAME.KIND.bin pair of the workspace (parent folders created).
void WriteColmapDepthNormal(const std::string& workspace,
                            const std::string& name, ColmapMapKind kind,
                            const DepthMap& map);

// One image's entry of patch-match.cfg: its name and the source images it
// was matched against (empty sources: "__auto__, 20", COLMAP's default).
struct ColmapStereoEntry {
  std::string name;
  std::vector<std::string> sources;
};
// Writes WS/stereo/patch-match.cfg (name, then sources) and
// WS/stereo/fusion.cfg (the names), atomically.
void WriteColmapStereoConfig(const std::string& workspace,
                             const std::vector<ColmapStereoEntry>& entries);
// Reads WS/stereo/patch-match.cfg back (tests, and a user's own file).
std::vector<ColmapStereoEntry> ReadColmapPatchMatchConfig(
    const std::string& path);

// Which views see each point of `cloud`: view v sees point p when p
// projects inside v's depth map and the map's depth at that pixel agrees
// with p's depth within `relative_tolerance` (|d - z| <= tol * z). `maps`
// are the views' depth maps (an empty map sees nothing); result[p] lists
// view indices in increasing order.
std::vector<std::vector<uint32_t>> ComputePointVisibility(
    const PointCloud& cloud, const std::vector<DepthMap>& maps,
    double relative_tolerance);
// The same for one view at a time (memory: one map): appends `view` to
// (*visibility)[p] (resized to the cloud) for each point p that `map` sees.
void AddPointVisibility(const PointCloud& cloud, const DepthMap& map,
                        uint32_t view, double relative_tolerance,
                        std::vector<std::vector<uint32_t>>* visibility);

// Writes `cloud` as COLMAP's fused.ply (x y z nx ny nz red green blue;
// colours from the cloud's sRGB [0, 1], grey when it has none, normals zero
// when it has none) and `visibility` (one entry per point) as PATH.vis,
// both atomically.
void WriteColmapFusedCloud(
    const std::string& path, const PointCloud& cloud,
    const std::vector<std::vector<uint32_t>>& visibility);
// Reads a .vis file. Throws Error naming the file when it is truncated or
// its counts are absurd.
std::vector<std::vector<uint32_t>> ReadColmapVisibility(
    const std::string& path);

}  // namespace wild_mvs
