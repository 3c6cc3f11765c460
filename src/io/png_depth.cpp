// Copyright wild_mvs authors.
#include "wild_mvs/io/png_depth.h"

#include <cmath>
#include <opencv2/imgcodecs.hpp>

#include "wild_mvs/core/error.h"
#include "wild_mvs/io/preview.h"

namespace wild_mvs {

int WriteDepthPng16(const std::string& path, const cv::Mat& depth,
                    double units_per_metre) {
  Require(depth.type() == CV_32F, path, ": depth must be CV_32F");
  Require(units_per_metre > 0, path, ": units_per_metre must be > 0");
  cv::Mat out(depth.size(), CV_16U, cv::Scalar(0));
  int dropped = 0;
  for (int r = 0; r < depth.rows; ++r) {
    const float* d = depth.ptr<float>(r);
    uint16_t* o = out.ptr<uint16_t>(r);
    for (int c = 0; c < depth.cols; ++c) {
      if (!(std::isfinite(d[c]) && d[c] > 0)) continue;
      const double v = std::round(d[c] * units_per_metre);
      if (v > 65535 || v < 1) {
        ++dropped;
        continue;
      }
      o[c] = static_cast<uint16_t>(v);
    }
  }
  WriteImageAtomically(path, out);
  return dropped;
}

cv::Mat ReadDepthPng16(const std::string& path, double units_per_metre) {
  Require(units_per_metre > 0, path, ": units_per_metre must be > 0");
  const cv::Mat raw = cv::imread(path, cv::IMREAD_UNCHANGED);
  Require(!raw.empty(), path, ": cannot read depth PNG");
  Require(raw.type() == CV_16U, path,
          ": depth PNG must be 16-bit single-channel");
  cv::Mat depth;
  raw.convertTo(depth, CV_32F, 1.0 / units_per_metre);
  return depth;
}

}  // namespace wild_mvs
