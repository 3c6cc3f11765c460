// Copyright wild_mvs authors.
#include "wild_mvs/core/image.h"

#include <array>
#include <cmath>
#include <opencv2/imgproc.hpp>

#include "wild_mvs/core/error.h"

namespace wild_mvs {

void ImageOptions::Check() const {
  Require(cache_mb > 0, "image.cache_mb = ", cache_mb, " must be > 0");
  Require(max_image_size >= 0, "image.max_image_size = ", max_image_size,
          " must be >= 0 (0 = no limit)");
}

void RegisterOptions(OptionRegistry* registry, const std::string& prefix,
                     ImageOptions* o) {
  registry
      ->Add(OptionRegistry::Join(prefix, "cache_mb"), &o->cache_mb,
            "image cache budget in MB (least recently used images evicted)")
      .Above(0);
  registry
      ->Add(OptionRegistry::Join(prefix, "max_image_size"), &o->max_image_size,
            "downscale images (and cameras) whose longest side exceeds this "
            "many pixels; 0 = full size")
      .Min(0);
}

float SrgbToLinear(float v) {
  if (v <= 0.04045f) return v / 12.92f;
  return std::pow((v + 0.055f) / 1.055f, 2.4f);
}

float LinearToSrgb(float v) {
  if (v <= 0.0031308f) return 12.92f * v;
  return 1.055f * std::pow(v, 1.0f / 2.4f) - 0.055f;
}

cv::Mat ToLinearRgb(const cv::Mat& in, bool linearize) {
  Require(!in.empty(), "ToLinearRgb: empty image");
  cv::Mat rgb;
  switch (in.channels()) {
    case 1:
      cv::cvtColor(in, rgb, cv::COLOR_GRAY2RGB);
      break;
    case 3:
      cv::cvtColor(in, rgb, cv::COLOR_BGR2RGB);
      break;
    case 4:
      cv::cvtColor(in, rgb, cv::COLOR_BGRA2RGB);
      break;
    default:
      throw Error(
          Msg("ToLinearRgb: unsupported channel count ", in.channels()));
  }
  cv::Mat out;
  switch (rgb.depth()) {
    case CV_8U: {
      if (linearize) {
        // Lookup table: exact and fast for 8-bit input.
        std::array<float, 256> lut;
        for (int i = 0; i < 256; ++i) lut[i] = SrgbToLinear(i / 255.0f);
        out.create(rgb.size(), CV_32FC3);
        for (int r = 0; r < rgb.rows; ++r) {
          const uint8_t* s = rgb.ptr<uint8_t>(r);
          float* d = out.ptr<float>(r);
          for (int i = 0; i < rgb.cols * 3; ++i) d[i] = lut[s[i]];
        }
        return out;
      }
      rgb.convertTo(out, CV_32FC3, 1.0 / 255.0);
      return out;
    }
    case CV_16U:
      rgb.convertTo(out, CV_32FC3, 1.0 / 65535.0);
      break;
    case CV_32F:
      out = rgb;
      break;
    default:
      rgb.convertTo(out, CV_32FC3);
      break;
  }
  if (linearize) {
    out.forEach<cv::Vec3f>([](cv::Vec3f& p, const int*) {
      for (int c = 0; c < 3; ++c) p[c] = SrgbToLinear(std::max(0.0f, p[c]));
    });
  }
  return out;
}

ImageCache::ImageCache(Loader loader, double capacity_mb)
    : loader_(std::move(loader)),
      capacity_bytes_(static_cast<size_t>(capacity_mb * 1024.0 * 1024.0)) {}

std::shared_ptr<const cv::Mat> ImageCache::Lookup(const Key& key) {
  std::lock_guard<std::mutex> lock(mutex_);
  const auto* hit = images_.Find(key);
  return hit ? *hit : nullptr;
}

void ImageCache::Insert(const Key& key, std::shared_ptr<const cv::Mat> img) {
  std::lock_guard<std::mutex> lock(mutex_);
  const size_t bytes = img->total() * img->elemSize();
  // Present already: another thread loaded it meanwhile.
  if (!images_.Insert(key, std::move(img), bytes)) return;
  peak_bytes_ = std::max(peak_bytes_, images_.cost());
  images_.Evict(capacity_bytes_, /*keep=*/1);  // the newest always stays
}

std::shared_ptr<const cv::Mat> ImageCache::Get(int view) {
  const Key key{view, {0, 0}};
  if (auto hit = Lookup(key)) return hit;
  auto img = std::make_shared<const cv::Mat>(loader_(view));
  Insert(key, img);
  return img;
}

std::shared_ptr<const cv::Mat> ImageCache::GetResized(int view, int width,
                                                      int height) {
  auto full = Get(view);
  if (full->cols == width && full->rows == height) return full;
  const Key key{view, {width, height}};
  if (auto hit = Lookup(key)) return hit;
  cv::Mat out;
  const bool shrink = width < full->cols;
  cv::resize(*full, out, cv::Size(width, height), 0, 0,
             shrink ? cv::INTER_AREA : cv::INTER_LINEAR);
  auto img = std::make_shared<const cv::Mat>(std::move(out));
  Insert(key, img);
  return img;
}

void ImageCache::Clear() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    images_.Clear();
  }
  noise_profiles_.Clear();
}

size_t ImageCache::bytes() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return images_.cost();
}

size_t ImageCache::peak_bytes() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return peak_bytes_;
}

}  // namespace wild_mvs
