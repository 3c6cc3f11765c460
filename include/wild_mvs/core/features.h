// Copyright wild_mvs authors. SIFT features of one view, stored compactly.
//
// Keypoint positions are in the pixel convention of camera.h (the top-left
// pixel's centre is (0.5, 0.5)): OpenCV puts pixel centres at integer
// coordinates, so 0.5 is added, minus the 0.25 px bias of OpenCV 4.6's SIFT
// (opencv/opencv#23123; checked on synthetic blobs), and positions found on a
// downscaled image are mapped back to the full-resolution view. The scale is
// the SIFT keypoint size (diameter of the meaningful neighbourhood) in
// full-resolution pixels; global view selection uses it as the feature scale.
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <cstdint>
#include <opencv2/core.hpp>
#include <vector>

#include "wild_mvs/core/option_registry.h"

namespace wild_mvs {

struct FeatureOptions {
  // Keep at most this many features per view (strongest response first);
  // bounds memory (128 bytes per descriptor) and matching time. 0 = no cap.
  int max_features = 4000;
  // Features are detected on the image shrunk so that its longest side is
  // at most this many pixels (large photos: SIFT time grows with the pixel
  // count while the extra features of a 6-megapixel image rarely help);
  // positions and scales are reported in full-resolution pixels. 0 = no
  // limit, else >= 64.
  int max_image_size = 2000;
  void Check() const;
};
// Registers the fields under `prefix` (option_registry.h), e.g.
// "tracker.features".
void RegisterOptions(OptionRegistry* registry, const std::string& prefix,
                     FeatureOptions* options);

// Features of one view. Descriptors are 128 bytes each (CV_8U), unit L2 norm
// scaled by kDescriptorScale, so the L2 distance of two normalised
// descriptors is sqrt(sum (a - b)^2) / kDescriptorScale.
struct Features {
  static constexpr float kDescriptorScale = 512.0f;
  std::vector<Eigen::Vector2f> xy;  // pixel coordinates (camera.h)
  std::vector<float> scale;         // SIFT size in full-resolution pixels
  std::vector<Eigen::Matrix<uint8_t, 3, 1>> rgb;  // sRGB colour at xy
  cv::Mat descriptors;                            // size() x 128, CV_8U

  int size() const { return static_cast<int>(xy.size()); }
  size_t bytes() const;
  // Keeps the features whose index is in `keep` (in that order).
  void Select(const std::vector<int>& keep);
};

// Extracts SIFT features from an image: CV_32FC3 linear RGB in [0, 1] (the
// core's image type), CV_32FC1 linear grey, or CV_8UC1 grey (taken as
// display-encoded). `mask` (optional, CV_8U, same size, 0 = ignore) limits
// where features are detected. Deterministic. Throws Error on a bad image.
Features ExtractFeatures(const cv::Mat& image, const FeatureOptions& options,
                         const cv::Mat& mask = cv::Mat());

// Squared L2 distance of two descriptors (rows of Features::descriptors).
int DescriptorDistanceSquared(const uint8_t* a, const uint8_t* b);

}  // namespace wild_mvs
