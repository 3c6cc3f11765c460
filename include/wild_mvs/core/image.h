// Copyright wild_mvs authors. View images: radiometry and a bounded cache.
// (Reading them from files is the I/O layer's: wild_mvs/io/image_files.h.)
//
// Inside the core an image is a cv::Mat of type CV_32FC3, RGB channel order
// (not OpenCV's BGR), linear radiometry (inverse sRGB applied once at load,
// switchable), values nominally in [0, 1]. Row r, column c holds the pixel
// whose centre is at (c + 0.5, r + 0.5) (camera.h).
#pragma once

#include <cstddef>
#include <functional>
#include <memory>
#include <mutex>
#include <opencv2/core.hpp>
#include <string>
#include <utility>

#include "wild_mvs/core/image_noise.h"
#include "wild_mvs/core/lru_cache.h"
#include "wild_mvs/core/option_registry.h"
#include "wild_mvs/core/scene.h"

namespace wild_mvs {

struct ImageOptions {
  // Apply the inverse sRGB transfer function at load (the paper matches in
  // linear radiometric space). Not registered: the command line sets it from
  // ablation.linearize (AblationOptions).
  bool linearize = true;
  // Budget of the image cache in megabytes; least recently used images are
  // evicted beyond it, so memory does not grow with the number of views.
  double cache_mb = 1024;
  // Images larger than this (longest side, pixels) are downscaled at load
  // and the camera with them; 0 = no limit.
  int max_image_size = 0;
  void Check() const;
};
// Registers the fields under `prefix` (option_registry.h), e.g. "image".
void RegisterOptions(OptionRegistry* registry, const std::string& prefix,
                     ImageOptions* options);

// sRGB <-> linear for one value in [0, 1].
float SrgbToLinear(float v);
float LinearToSrgb(float v);

// Converts an 8/16-bit or float, 1/3/4-channel BGR(A) image as returned by
// cv::imread into CV_32FC3 linear (or not) RGB in [0, 1].
cv::Mat ToLinearRgb(const cv::Mat& bgr, bool linearize);

// Reading images and masks from files (LoadViewImage, LoadViewMask,
// MakeSceneLoader): wild_mvs/io/image_files.h.

// Thread-safe LRU cache of view images, bounded in bytes. Images come from a
// loader function, so algorithms never see file paths and tests can feed
// in-memory images.
class ImageCache {
 public:
  using Loader = std::function<cv::Mat(int view)>;
  ImageCache(Loader loader, double capacity_mb);

  // The full-resolution image of `view`.
  std::shared_ptr<const cv::Mat> Get(int view);
  // The image of `view` resampled to width x height (area averaging when
  // shrinking), cached separately.
  std::shared_ptr<const cv::Mat> GetResized(int view, int width, int height);
  // The full-resolution image of `view` from the loader, not cached (for a
  // stage that reads each image once: caching it would only hold memory).
  cv::Mat Load(int view) const { return loader_(view); }
  // Drops every cached image (images in use elsewhere live on) and noise
  // profile.
  void Clear();
  // The noise profiles of the images served (image_noise.h), estimated once
  // per view, size and channels.
  NoiseProfileCache& noise_profiles() { return noise_profiles_; }

  size_t bytes() const;
  size_t peak_bytes() const;

 private:
  using Key = std::pair<int, std::pair<int, int>>;  // view, (w, h); (0,0)=full
  std::shared_ptr<const cv::Mat> Lookup(const Key& key);
  void Insert(const Key& key, std::shared_ptr<const cv::Mat> img);

  Loader loader_;
  size_t capacity_bytes_;
  mutable std::mutex mutex_;
  LruCache<Key, std::shared_ptr<const cv::Mat>> images_;  // cost: bytes
  size_t peak_bytes_ = 0;
  NoiseProfileCache noise_profiles_;
};

}  // namespace wild_mvs
