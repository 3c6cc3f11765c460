// Copyright wild_mvs authors.
#include "wild_mvs/io/preview.h"

#include <algorithm>
#include <cmath>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <vector>

#include "wild_mvs/core/error.h"
#include "wild_mvs/io/atomic_file.h"

namespace wild_mvs {

cv::Mat DepthPreview(const cv::Mat& depth, double min_depth, double max_depth) {
  Require(depth.type() == CV_32F, "DepthPreview: depth must be CV_32F");
  cv::Mat out = cv::Mat::zeros(depth.size(), CV_8UC3);
  if (depth.empty()) return out;
  std::vector<float> valid;
  for (int r = 0; r < depth.rows; ++r) {
    const float* d = depth.ptr<float>(r);
    for (int c = 0; c < depth.cols; ++c)
      if (std::isfinite(d[c]) && d[c] > 0) valid.push_back(d[c]);
  }
  if (valid.empty()) return out;
  double lo = min_depth, hi = max_depth;
  if (!(lo < hi)) {
    const size_t n = valid.size();
    const size_t i_lo = static_cast<size_t>(0.02 * (n - 1));
    const size_t i_hi = static_cast<size_t>(0.98 * (n - 1));
    std::nth_element(valid.begin(), valid.begin() + i_lo, valid.end());
    lo = valid[i_lo];
    std::nth_element(valid.begin(), valid.begin() + i_hi, valid.end());
    hi = valid[i_hi];
    if (!(hi > lo)) hi = lo + std::max(1e-6, std::abs(lo) * 1e-3);
  }
  cv::Mat grey(depth.size(), CV_8U, cv::Scalar(0));
  cv::Mat mask(depth.size(), CV_8U, cv::Scalar(0));
  for (int r = 0; r < depth.rows; ++r) {
    const float* d = depth.ptr<float>(r);
    uint8_t* g = grey.ptr<uint8_t>(r);
    uint8_t* m = mask.ptr<uint8_t>(r);
    for (int c = 0; c < depth.cols; ++c) {
      if (!(std::isfinite(d[c]) && d[c] > 0)) continue;
      const double s = std::clamp((d[c] - lo) / (hi - lo), 0.0, 1.0);
      g[c] = static_cast<uint8_t>(std::lround(s * 255));
      m[c] = 255;
    }
  }
  cv::Mat colour;
  cv::applyColorMap(grey, colour, cv::COLORMAP_TURBO);
  colour.copyTo(out, mask);
  return out;
}

cv::Mat ConfidencePreview(const cv::Mat& confidence) {
  Require(confidence.type() == CV_32F,
          "ConfidencePreview: confidence must be CV_32F");
  cv::Mat out(confidence.size(), CV_8U, cv::Scalar(0));
  for (int r = 0; r < confidence.rows; ++r) {
    const float* s = confidence.ptr<float>(r);
    uint8_t* d = out.ptr<uint8_t>(r);
    for (int c = 0; c < confidence.cols; ++c)
      d[c] = std::isfinite(s[c]) ? static_cast<uint8_t>(std::lround(
                                       std::clamp(s[c], 0.0f, 1.0f) * 255))
                                 : 0;
  }
  return out;
}

cv::Mat NormalPreview(const cv::Mat& normal) {
  Require(normal.type() == CV_32FC3, "NormalPreview: normal must be CV_32FC3");
  cv::Mat out = cv::Mat::zeros(normal.size(), CV_8UC3);
  for (int r = 0; r < normal.rows; ++r) {
    const cv::Vec3f* s = normal.ptr<cv::Vec3f>(r);
    cv::Vec3b* d = out.ptr<cv::Vec3b>(r);
    for (int c = 0; c < normal.cols; ++c) {
      const cv::Vec3f n = s[c];
      if (!(std::isfinite(n[0]) && std::isfinite(n[1]) &&
            std::isfinite(n[2])) ||
          (n[0] == 0 && n[1] == 0 && n[2] == 0))
        continue;
      auto to8 = [](float v) {
        return static_cast<uint8_t>(
            std::lround(std::clamp((v + 1.0f) * 0.5f, 0.0f, 1.0f) * 255));
      };
      d[c] = cv::Vec3b(to8(n[2]), to8(n[1]), to8(n[0]));  // BGR
    }
  }
  return out;
}

void WriteImageAtomically(const std::string& path, const cv::Mat& image,
                          const std::vector<int>& params) {
  Require(!image.empty(), path, ": cannot write an empty image");
  ProduceFileAtomically(path, [&](const std::string& tmp) {
    try {
      return cv::imwrite(tmp, image, params);
    } catch (const cv::Exception& e) {
      throw Error(Msg(path, ": cannot write image: ", e.what()));
    }
  });
}

}  // namespace wild_mvs
