// Copyright wild_mvs authors. Colourised PNG previews of per-view maps.
//
// Returned images are 8-bit BGR / grey (ready for cv::imwrite); unknown
// pixels (depth <= 0, non-finite, zero normal) are black.
#pragma once

#include <opencv2/core.hpp>
#include <string>
#include <vector>

namespace wild_mvs {

// Depth (CV_32F) through the TURBO colour map; near = blue, far = red. The
// range is robust: the 2nd and 98th percentiles of the valid depths, unless
// min_depth < max_depth are given.
cv::Mat DepthPreview(const cv::Mat& depth, double min_depth = 0,
                     double max_depth = 0);
// Confidence (CV_32F, [0, 1]) as grey (0 = black, 1 = white).
cv::Mat ConfidencePreview(const cv::Mat& confidence);
// Camera-frame unit normals (CV_32FC3, x right, y down, z forward) as
// colour: R = (1 + nx) / 2, G = (1 + ny) / 2, B = (1 + nz) / 2 (x 255).
cv::Mat NormalPreview(const cv::Mat& normal);

// cv::imwrite through a temporary file and rename (atomic), with optional
// cv::imwrite parameters (e.g. {cv::IMWRITE_PNG_COMPRESSION, 9}). Throws
// Error naming the path when it fails.
void WriteImageAtomically(const std::string& path, const cv::Mat& image,
                          const std::vector<int>& params = {});

}  // namespace wild_mvs
