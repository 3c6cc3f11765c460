// Copyright wild_mvs authors. Image noise against brightness
// (image_noise.h).
#include "wild_mvs/core/image_noise.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include "wild_mvs/core/patch.h"

namespace wild_mvs {
namespace {

// Brightness bin of a mean value: uniform in sqrt over [0, 1].
int BinOf(double mean) {
  const double u = std::sqrt(std::clamp(mean, 0.0, 1.0));
  return std::min(NoiseProfile::kBins - 1,
                  static_cast<int>(u * NoiseProfile::kBins));
}

}  // namespace

NoiseProfile NoiseProfile::Estimate(const MatchImage& im) {
  NoiseProfile p;
  const int b = kBlock;
  if (im.data == nullptr || im.width < b + 2 || im.height < b + 2) return p;
  const int w = im.width, ch = im.channels;
  // Per block: the RMS residual over its pixels and channels, and its
  // brightness.
  std::vector<std::vector<float>> block_sigma(kBins);
  static const int k[3] = {1, -2, 1};
  for (int by = 1; by + b < im.height; by += b)
    for (int bx = 1; bx + b < w; bx += b) {
      double sum_r2 = 0, sum_v = 0;
      for (int y = by; y < by + b; ++y)
        for (int x = bx; x < bx + b; ++x)
          for (int c = 0; c < ch; ++c) {
            double lap = 0;
            for (int j = -1; j <= 1; ++j)
              for (int i = -1; i <= 1; ++i)
                lap += k[i + 1] * k[j + 1] *
                       im.data[(static_cast<size_t>(y + j) * w + (x + i)) * ch +
                               c];
            sum_r2 += lap * lap / 36.0;
            sum_v += im.data[(static_cast<size_t>(y) * w + x) * ch + c];
          }
      const double n = static_cast<double>(b) * b * ch;
      block_sigma[BinOf(sum_v / n)].push_back(
          static_cast<float>(std::sqrt(sum_r2 / n)));
    }
  std::array<bool, kBins> known{};
  for (int i = 0; i < kBins; ++i) {
    std::vector<float>& v = block_sigma[i];
    if (static_cast<int>(v.size()) < kMinBinBlocks) continue;
    const size_t q = v.size() / 5;
    std::nth_element(v.begin(), v.begin() + q, v.end());
    p.sigma_[i] = static_cast<float>(v[q] / kQuintileBias);
    known[i] = true;
  }
  for (int i = 0; i < kBins; ++i) {
    if (known[i]) continue;
    for (int d = 1; d < kBins; ++d) {
      if (i - d >= 0 && known[i - d]) {
        p.sigma_[i] = p.sigma_[i - d];
        break;
      }
      if (i + d < kBins && known[i + d]) {
        p.sigma_[i] = p.sigma_[i + d];
        break;
      }
    }
  }
  return p;
}

double NoiseProfile::Sigma(double mean) const {
  const double u = std::sqrt(std::clamp(mean, 0.0, 1.0)) * kBins - 0.5;
  if (u <= 0) return sigma_[0];
  if (u >= kBins - 1) return sigma_[kBins - 1];
  const int b = static_cast<int>(u);
  const double f = u - b;
  return (1 - f) * sigma_[b] + f * sigma_[b + 1];
}

double NoiseProfile::MaxSigma() const {
  return *std::max_element(sigma_.begin(), sigma_.end());
}

NoiseProfileCache::NoiseProfileCache(size_t capacity)
    : capacity_(std::max<size_t>(capacity, 1)) {}

NoiseProfile NoiseProfileCache::Get(int view, const MatchImage& image) {
  const Key key{view, image.width, image.height, image.channels};
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (const NoiseProfile* hit = profiles_.Find(key)) return *hit;
  }
  const NoiseProfile profile = NoiseProfile::Estimate(image);
  std::lock_guard<std::mutex> lock(mutex_);
  // Present already: another thread estimated it (the same profile).
  if (profiles_.Insert(key, profile, 1)) profiles_.Evict(capacity_);
  return profile;
}

size_t NoiseProfileCache::size() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return profiles_.size();
}

void NoiseProfileCache::Clear() {
  std::lock_guard<std::mutex> lock(mutex_);
  profiles_.Clear();
}

double WindowReliability(double ss, double noise_var, int channels, double w1,
                         double w2) {
  if (!(ss > 0) || !(w1 > 0)) return kMinReliability;
  const double noise = noise_var * channels * (w1 - w2 / w1);
  return std::clamp(1.0 - noise / ss, kMinReliability, 1.0);
}

}  // namespace wild_mvs
