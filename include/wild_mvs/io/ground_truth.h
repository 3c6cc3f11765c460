// Copyright wild_mvs authors. Ground-truth depth maps for evaluation.
//
// Readers return CV_32F planar depth (z along the optical axis); invalid
// pixels (non-finite, <= 0, or > kMaxValidDepth, e.g. the 65504 "no mesh"
// value of half-float renders) are 0.
//
// fountain-P11 adapter: its EXR depth maps were rendered with a centred
// principal point and square pixels, K_render = [2759.48 0 1536; 0 2759.48
// 1024] for 3072x2048 (same R, C as the .camera files). We take the render's
// principal point at the exact image centre in continuous coordinates, i.e.
// (1536, 1024) in wild_mvs's convention (top-left pixel centre at 0.5), and
// the real camera as read by ReadStrechaCamera (cx = K13 + 0.5). Depth of a
// real pixel (u, v): x = (u - cx)/fx, y = (v - cy)/fy, then sample the render
// at (2759.48 x + 1536, 2759.48 y + 1024); z is unchanged (same optical
// centre and axis). The staging notes' mapping (u_r = u + 15.31, v_r =
// (v - 1006.81) * 2759.48/2764.16 + 1024) is the same up to the 0.5 px
// convention question they leave open (+-0.5 px).
#pragma once

#include <opencv2/core.hpp>
#include <string>

#include "wild_mvs/core/metrics.h"
#include "wild_mvs/core/scene.h"

namespace wild_mvs {

constexpr double kMaxValidDepth = 1e4;

// OpenEXR depth: channel Z, else R, else Y, else the first channel.
cv::Mat ReadExrDepth(const std::string& path);
// Writes a single-channel FLOAT EXR with channel Z (for tests and tools).
void WriteExrDepth(const std::string& path, const cv::Mat& depth);
// .pfm or .exr by extension (case-insensitive); invalid values -> 0.
cv::Mat ReadGroundTruthDepth(const std::string& path);

// Resampling between cameras of the same pose: ResampleDepth in
// wild_mvs/core/metrics.h (bilinear in inverse depth where the 4 neighbours
// agree within 1 %, nearest otherwise: no mixing across depth edges).

// The render camera of the fountain-P11 GT depth for a real camera (its
// pose), at the render's full size 3072x2048.
Camera FountainRenderCamera(const Camera& real);
// Reads a fountain-P11 GT EXR and returns its depth in `target`'s pixel grid
// (target = the real camera of that view at any working resolution).
cv::Mat FountainGroundTruthDepth(const std::string& exr_path,
                                 const Camera& target);

// Ground truth for a view of a dataset folder, in `target`'s pixel grid
// (the view's camera at any resolution), or an empty Mat when the dataset
// has none. Looks for DIR/gt_depth/<stem>.pfm|.exr (rendered with the view's
// own camera: synthetic datasets) and DIR/gt_depth_blender_exr/<stem>.exr
// (fountain-P11, with the render-camera adapter above).
cv::Mat LoadGroundTruthDepthForView(const std::string& dataset_dir,
                                    const View& view, const Camera& target);

}  // namespace wild_mvs
