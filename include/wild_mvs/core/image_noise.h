// Copyright wild_mvs authors. Image noise as a function of brightness
// (beyond the paper; docs/ALGORITHM.md section 4.3): what every NCC between
// two windows loses to noise, so that NCCs of windows with different noise
// can be compared (the explain test, mpgc.h).
//
// Every camera adds noise, and its level in linear units depends on the
// brightness (shot noise, the camera's response curve). A window whose
// deviations from its mean have variance S (signal) + N (noise) correlates
// with a noise-free copy of itself at only sqrt(S / (S + N)): two windows
// that see the same surface have NCC sqrt(r_a r_b), r = S / (S + N) each
// window's reliability (Spearman's correction for attenuation). A dark or
// overcast view, a weakly textured surface and a window sampled at pixel
// centres (R) instead of interpolated (bilinear sampling averages four
// pixels' noise: the neighbours' windows) all have a lower r.
#pragma once

#include <array>
#include <cstddef>
#include <mutex>
#include <tuple>

#include "wild_mvs/core/lru_cache.h"

namespace wild_mvs {

struct MatchImage;  // patch.h

// Noise standard deviation of one image's values against their local mean
// brightness (mean over channels, the image's own units).
class NoiseProfile {
 public:
  static constexpr int kBins = 16;  // brightness bins, uniform in sqrt
  // A profile of zero noise (what an image without an estimate gets).
  NoiseProfile() { sigma_.fill(0.0f); }
  // Estimates the profile of `image` (below kBlock + 2 pixels a side:
  // zero). The residual of the 3 x 3 second-difference kernel
  // [1 -2 1] x [1 -2 1] / 6 (Immerkaer 1996) removes the mean and linear
  // gradients and keeps white noise's deviation; per kBlock x kBlock block
  // its RMS over pixels and channels, and per brightness bin (the blocks'
  // mean) the lower quintile of the blocks' RMS, divided by kQuintileBias
  // (where the quintile of pure noise lies): texture and edges only raise
  // a block's residual, so the smoothest fifth of the blocks measures the
  // noise where an image has any smooth parts (a wall, the sky, shade).
  // Bins with fewer than kMinBinBlocks blocks take the nearest estimated
  // bin's value.
  static NoiseProfile Estimate(const MatchImage& image);
  static constexpr int kBlock = 8;
  static constexpr int kMinBinBlocks = 8;
  static constexpr double kQuintileBias = 0.93;
  // Deviation at brightness `mean` (linear between bin centres).
  double Sigma(double mean) const;
  // The largest bin value (a summary for reports and tests).
  double MaxSigma() const;

 private:
  std::array<float, kBins> sigma_;
};

// The noise profiles of a run's working images, each estimated once: a
// view is matched as the reference and again as a neighbour of up to
// |N| other views, at the same size and with the same profile. Keyed by
// view, size and channels (the caller's promise: one view at one size and
// channel count is always the same image, as an ImageCache serves it).
// Thread-safe; holds at most `capacity` profiles, least recently used
// dropped first.
class NoiseProfileCache {
 public:
  explicit NoiseProfileCache(size_t capacity = 1024);
  // The profile of `image`, the matching copy of view `view`: Estimate on
  // first use (outside the lock; two threads may both estimate it, with
  // the same result).
  NoiseProfile Get(int view, const MatchImage& image);
  size_t size() const;
  void Clear();

 private:
  using Key = std::tuple<int, int, int, int>;  // view, width, height, channels
  size_t capacity_;
  mutable std::mutex mutex_;
  LruCache<Key, NoiseProfile> profiles_;  // cost 1 each
};

// Reliability r = S / (S + N) of a window with weighted sum of squared
// deviations `ss` (over channels, weights summing to w1, their squares to
// w2) when each sample carries noise of variance `noise_var` per channel:
// N = noise_var * channels * (w1 - w2 / w1), the expected weighted sum of
// squared deviations of pure noise. Clamped to [kMinReliability, 1].
constexpr double kMinReliability = 0.05;
double WindowReliability(double ss, double noise_var, int channels, double w1,
                         double w2);

// Noise variance of a bilinear sample relative to a pixel's, averaged over
// uniformly distributed sub-pixel positions: E[(1 - a)^2 + a^2]^2 = (2/3)^2.
constexpr double kBilinearNoiseFactor = 4.0 / 9.0;

}  // namespace wild_mvs
