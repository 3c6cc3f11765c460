// Copyright wild_mvs authors. The per-view output of multi-view stereo.
#pragma once

#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "wild_mvs/core/camera.h"

namespace wild_mvs {

// Depth, normal and confidence of one reference view at its working
// resolution. `camera` is the camera of that resolution (it may be smaller
// than the input image after rescaling). Pixel (col, row) has its centre at
// (col + 0.5, row + 0.5) in `camera`'s pixel coordinates.
struct DepthMap {
  int view = -1;               // index of the reference view in the Scene
  Camera camera;               // camera of the depth map's resolution
  cv::Mat depth;               // CV_32F, z along the optical axis; 0 = unknown
  cv::Mat normal;              // CV_32FC3, unit normal in the camera frame,
                               // facing the camera (n . ray < 0); 0 = unknown
  cv::Mat confidence;          // CV_32F in [0, 1]; 0 = unknown
  std::vector<int> neighbors;  // views it was matched against (global
                               // view selection order)

  int width() const { return depth.cols; }
  int height() const { return depth.rows; }
  bool empty() const { return depth.empty(); }
  // Number of pixels with a valid depth.
  int CountValid() const;
};

}  // namespace wild_mvs
