// Copyright wild_mvs authors. SIFT features of one view.
#include "wild_mvs/core/features.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <opencv2/features2d.hpp>
#include <opencv2/imgproc.hpp>

#include "wild_mvs/core/error.h"
#include "wild_mvs/core/image.h"

namespace wild_mvs {
namespace {
// OpenCV SIFT: contrastThreshold below OpenCV's 0.04 (more features on
// weakly textured objects such as the Middlebury plaster models); Lowe's
// edge threshold, layers per octave and base sigma.
constexpr double kContrastThreshold = 0.02;
constexpr double kEdgeThreshold = 10;
constexpr int kOctaveLayers = 3;
constexpr double kSigma = 1.6;
}  // namespace

void FeatureOptions::Check() const {
  Require(max_features >= 0, "features.max_features = ", max_features,
          " must be >= 0 (0 = no cap)");
  Require(max_image_size == 0 || max_image_size >= 64,
          "features.max_image_size = ", max_image_size,
          " must be 0 (no limit) or >= 64");
}

void RegisterOptions(OptionRegistry* registry, const std::string& prefix,
                     FeatureOptions* o) {
  auto key = [&prefix](const char* name) {
    return OptionRegistry::Join(prefix, name);
  };
  registry
      ->Add(key("max_features"), &o->max_features,
            "keep at most this many SIFT features per view, 0 = no cap")
      .Min(0);
  registry
      ->Add(key("max_image_size"), &o->max_image_size,
            "detect features on images shrunk to this longest side, 0 = no "
            "limit")
      .Min(64)
      .OrZero();
}

size_t Features::bytes() const {
  return xy.capacity() * sizeof(Eigen::Vector2f) +
         scale.capacity() * sizeof(float) +
         rgb.capacity() * sizeof(Eigen::Matrix<uint8_t, 3, 1>) +
         descriptors.total() * descriptors.elemSize();
}

void Features::Select(const std::vector<int>& keep) {
  Features out;
  out.xy.reserve(keep.size());
  out.scale.reserve(keep.size());
  out.rgb.reserve(keep.size());
  out.descriptors.create(static_cast<int>(keep.size()), 128, CV_8U);
  for (size_t i = 0; i < keep.size(); ++i) {
    const int k = keep[i];
    out.xy.push_back(xy[k]);
    out.scale.push_back(scale[k]);
    if (!rgb.empty()) out.rgb.push_back(rgb[k]);
    descriptors.row(k).copyTo(out.descriptors.row(static_cast<int>(i)));
  }
  *this = std::move(out);
}

int DescriptorDistanceSquared(const uint8_t* a, const uint8_t* b) {
  int sum = 0;
  for (int i = 0; i < 128; ++i) {
    const int d = static_cast<int>(a[i]) - static_cast<int>(b[i]);
    sum += d * d;
  }
  return sum;
}

namespace {

// OpenCV keypoint coordinate -> camera.h coordinate: +0.5 for the pixel
// centre convention, -0.25 for the SIFT upsampling bias (see below).
constexpr double kOpenCvToPixel = 0.5 - 0.25;

// Display-encoded 8-bit grey image for detection.
cv::Mat ToGrey8(const cv::Mat& image, bool srgb_encode) {
  if (image.type() == CV_8UC1) return image;
  cv::Mat grey;
  if (image.type() == CV_32FC3) {
    cv::cvtColor(image, grey, cv::COLOR_RGB2GRAY);
  } else if (image.type() == CV_32FC1) {
    grey = image;
  } else {
    throw Error(Msg("ExtractFeatures: unsupported image type ", image.type(),
                    " (want CV_32FC3 linear RGB, CV_32FC1 or CV_8UC1)"));
  }
  cv::Mat out(grey.size(), CV_8UC1);
  // Lookup-free per-pixel encode; fast enough next to SIFT itself.
  for (int r = 0; r < grey.rows; ++r) {
    const float* in = grey.ptr<float>(r);
    uint8_t* o = out.ptr<uint8_t>(r);
    for (int c = 0; c < grey.cols; ++c) {
      float v = std::min(1.0f, std::max(0.0f, in[c]));
      if (!(v == v)) v = 0;
      if (srgb_encode) v = LinearToSrgb(v);
      o[c] = static_cast<uint8_t>(std::lround(v * 255.0f));
    }
  }
  return out;
}

}  // namespace

Features ExtractFeatures(const cv::Mat& image, const FeatureOptions& options,
                         const cv::Mat& mask) {
  options.Check();
  Require(!image.empty(), "ExtractFeatures: empty image");
  Require(
      mask.empty() || (mask.type() == CV_8UC1 && mask.size() == image.size()),
      "ExtractFeatures: mask must be CV_8UC1 of the image size");
  const cv::Mat grey_full = ToGrey8(image, true);
  cv::Mat grey = grey_full;
  cv::Mat det_mask = mask;
  double factor = 1.0;
  const int longest = std::max(image.cols, image.rows);
  if (options.max_image_size > 0 && longest > options.max_image_size)
    factor = static_cast<double>(longest) / options.max_image_size;
  // Full-resolution pixels per detection pixel, per axis (equal up to the
  // rounding of the shrunk size).
  double sx = 1.0, sy = 1.0;
  if (factor > 1.0) {
    const int w =
        std::max(1, static_cast<int>(std::lround(grey.cols / factor)));
    const int h =
        std::max(1, static_cast<int>(std::lround(grey.rows / factor)));
    cv::Mat small;
    cv::resize(grey, small, cv::Size(w, h), 0, 0, cv::INTER_AREA);
    grey = small;
    if (!mask.empty()) {
      cv::resize(mask, det_mask, cv::Size(w, h), 0, 0, cv::INTER_NEAREST);
    }
    sx = static_cast<double>(image.cols) / w;
    sy = static_cast<double>(image.rows) / h;
  }

  // nfeatures = 0: detect all, then keep the strongest ourselves with a
  // deterministic tie-break (position).
  cv::Ptr<cv::SIFT> sift = cv::SIFT::create(
      0, kOctaveLayers, kContrastThreshold, kEdgeThreshold, kSigma, CV_32F);
  std::vector<cv::KeyPoint> kps;
  cv::Mat desc;
  sift->detectAndCompute(grey, det_mask, kps, desc);

  std::vector<int> order(kps.size());
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(), [&kps](int a, int b) {
    if (kps[a].response != kps[b].response)
      return kps[a].response > kps[b].response;
    if (kps[a].pt.y != kps[b].pt.y) return kps[a].pt.y < kps[b].pt.y;
    return kps[a].pt.x < kps[b].pt.x;
  });
  if (options.max_features > 0 &&
      static_cast<int>(order.size()) > options.max_features) {
    order.resize(options.max_features);
  }

  Features f;
  const int n = static_cast<int>(order.size());
  f.xy.reserve(n);
  f.scale.reserve(n);
  f.rgb.reserve(n);
  f.descriptors.create(n, 128, CV_8U);
  const bool colour = image.type() == CV_32FC3;
  for (int i = 0; i < n; ++i) {
    const cv::KeyPoint& kp = kps[order[i]];
    // OpenCV puts pixel centres at integer coordinates -> +0.5 (camera.h).
    // OpenCV 4.6's SIFT also reports every keypoint 0.25 px too far right and
    // down: it doubles the image with a centre-aligned linear resize and
    // maps octave coordinates back by plain scaling (opencv/opencv#23123,
    // fixed by `enable_precise_upscale` only in 4.8). Both are compensated
    // (kOpenCvToPixel), measured on synthetic blobs in the tests. Then the
    // edge-based coordinates are scaled to full resolution.
    const float x = static_cast<float>((kp.pt.x + kOpenCvToPixel) * sx);
    const float y = static_cast<float>((kp.pt.y + kOpenCvToPixel) * sy);
    f.xy.emplace_back(x, y);
    f.scale.push_back(static_cast<float>(kp.size * 0.5 * (sx + sy)));
    // Colour at the nearest full-resolution pixel.
    const int col = std::min(image.cols - 1, std::max(0, static_cast<int>(x)));
    const int row = std::min(image.rows - 1, std::max(0, static_cast<int>(y)));
    Eigen::Matrix<uint8_t, 3, 1> rgb;
    if (colour) {
      const cv::Vec3f& p = image.at<cv::Vec3f>(row, col);
      for (int c = 0; c < 3; ++c) {
        float v = std::min(1.0f, std::max(0.0f, p[c]));
        v = LinearToSrgb(v);
        rgb(c) = static_cast<uint8_t>(std::lround(v * 255.0f));
      }
    } else {
      rgb.setConstant(grey_full.at<uint8_t>(row, col));
    }
    f.rgb.push_back(rgb);

    // RootSIFT (Arandjelovic & Zisserman 2012: L1-normalise, square root),
    // store as bytes scaled by kDescriptorScale.
    const float* d = desc.ptr<float>(order[i]);
    float v[128];
    double l1 = 0;
    for (int k = 0; k < 128; ++k) l1 += std::abs(d[k]);
    for (int k = 0; k < 128; ++k)
      v[k] = l1 > 0 ? static_cast<float>(std::sqrt(std::abs(d[k]) / l1)) : 0;
    uint8_t* o = f.descriptors.ptr<uint8_t>(i);
    for (int k = 0; k < 128; ++k) {
      o[k] = static_cast<uint8_t>(
          std::min(255L, std::lround(v[k] * Features::kDescriptorScale)));
    }
  }
  return f;
}

}  // namespace wild_mvs
