// Copyright wild_mvs authors. Normalised cross-correlation (mean-removed),
// the paper's measure of matching confidence and convergence.
#pragma once

#include <cmath>

namespace wild_mvs {

// Below this variance (per sample, in linear radiance units squared) a window
// counts as textureless and its NCC as -1 (no information).
constexpr double kNccMinVariance = 1e-10;

// NCC of two sequences of n values: invariant to gain (> 0) and offset.
// Returns -1 when either sequence is (nearly) constant.
inline double Ncc(const float* a, const float* b, int n) {
  double sa = 0, sb = 0;
  for (int i = 0; i < n; ++i) {
    sa += a[i];
    sb += b[i];
  }
  const double ma = sa / n, mb = sb / n;
  double saa = 0, sbb = 0, sab = 0;
  for (int i = 0; i < n; ++i) {
    const double da = a[i] - ma, db = b[i] - mb;
    saa += da * da;
    sbb += db * db;
    sab += da * db;
  }
  if (saa < kNccMinVariance * n || sbb < kNccMinVariance * n) return -1;
  return sab / std::sqrt(saa * sbb);
}

// NCC of multi-channel windows stored planar (channel c at a + c * stride),
// each channel mean-removed separately, then correlated jointly: invariant
// to a separate gain and offset per channel (the colour scale model).
inline double NccChannels(const float* a, const float* b, int n, int channels,
                          int stride) {
  double saa = 0, sbb = 0, sab = 0;
  for (int c = 0; c < channels; ++c) {
    const float* pa = a + c * stride;
    const float* pb = b + c * stride;
    double sa = 0, sb = 0;
    for (int i = 0; i < n; ++i) {
      sa += pa[i];
      sb += pb[i];
    }
    const double ma = sa / n, mb = sb / n;
    for (int i = 0; i < n; ++i) {
      const double da = pa[i] - ma, db = pb[i] - mb;
      saa += da * da;
      sbb += db * db;
      sab += da * db;
    }
  }
  const double m = static_cast<double>(n) * channels;
  if (saa < kNccMinVariance * m || sbb < kNccMinVariance * m) return -1;
  return sab / std::sqrt(saa * sbb);
}

}  // namespace wild_mvs
