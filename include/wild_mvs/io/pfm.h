// Copyright wild_mvs authors. Portable Float Map (PFM) images.
//
// Format: "Pf" (1 channel) or "PF" (3 channels), then width height, then a
// scale whose sign gives the byte order (negative = little-endian), each
// separated by whitespace, one whitespace byte, then float32 pixels with the
// rows stored BOTTOM to TOP. In memory (cv::Mat) row 0 is the top row; the
// 3 channels are kept in file order (no RGB/BGR swap).
#pragma once

#include <opencv2/core.hpp>
#include <string>

namespace wild_mvs {

// Returns CV_32F or CV_32FC3. Reads little- and big-endian files. Throws
// Error naming the file for a bad header or truncated data. Values are
// returned as stored (NaN/Inf included).
cv::Mat ReadPfm(const std::string& path);

// Writes CV_32F / CV_32FC3 (other depths converted to float) little-endian
// (scale -1), atomically.
void WritePfm(const std::string& path, const cv::Mat& image);

}  // namespace wild_mvs
