// Copyright wild_mvs authors. 16-bit PNG depth maps in millimetres.
//
// Pixel value = round(depth * units_per_metre) (default 1000: millimetres),
// 0 = unknown. Depths that do not fit (> 65535 units) or are non-finite or
// <= 0 are written as 0 (unknown); the writer returns how many valid depths
// were dropped that way, so the caller can warn.
#pragma once

#include <opencv2/core.hpp>
#include <string>

namespace wild_mvs {

// depth: CV_32F in scene units (metres). Atomic write.
int WriteDepthPng16(const std::string& path, const cv::Mat& depth,
                    double units_per_metre = 1000.0);
// Returns CV_32F depth in metres (0 = unknown). Throws Error naming the file
// when it is missing or not a 16-bit single-channel PNG.
cv::Mat ReadDepthPng16(const std::string& path,
                       double units_per_metre = 1000.0);

}  // namespace wild_mvs
