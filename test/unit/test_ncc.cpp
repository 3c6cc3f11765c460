// Copyright wild_mvs authors. NCC (paper 6.2): invariant to gain and
// offset of either window, low for unrelated windows.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "wild_mvs/core/ncc.h"

namespace wild_mvs {
namespace {

TEST(MvsNcc, InvariantToGainAndOffsetDropsForUnrelated) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> u(0.f, 1.f);
  const int n = 25;
  std::vector<float> a(3 * n), b(3 * n), c(3 * n);
  for (auto& x : a) x = u(rng);
  for (auto& x : c) x = u(rng);
  // Separate gain and offset per channel.
  const float gain[3] = {0.3f, 2.5f, 1.1f}, offset[3] = {0.2f, -0.4f, 0.05f};
  for (int ch = 0; ch < 3; ++ch)
    for (int i = 0; i < n; ++i)
      b[ch * n + i] = gain[ch] * a[ch * n + i] + offset[ch];

  for (int ch = 0; ch < 3; ++ch) {
    EXPECT_NEAR(Ncc(&a[ch * n], &b[ch * n], n), 1.0, 1e-5);
    EXPECT_LT(std::abs(Ncc(&a[ch * n], &c[ch * n], n)), 0.6);
  }
  // Joint NCC over channels: invariant to a common gain and a separate
  // offset per channel (separate gains are the colour scales' job).
  std::vector<float> common(3 * n);
  for (int ch = 0; ch < 3; ++ch)
    for (int i = 0; i < n; ++i)
      common[ch * n + i] = 1.7f * a[ch * n + i] + offset[ch];
  EXPECT_NEAR(NccChannels(a.data(), common.data(), n, 3, n), 1.0, 1e-5);
  EXPECT_GT(NccChannels(a.data(), b.data(), n, 3, n), 0.5);
  EXPECT_LT(std::abs(NccChannels(a.data(), c.data(), n, 3, n)), 0.4);
  // A negative gain anti-correlates.
  std::vector<float> neg(n);
  for (int i = 0; i < n; ++i) neg[i] = 0.7f - 0.5f * a[i];
  EXPECT_NEAR(Ncc(a.data(), neg.data(), n), -1.0, 1e-5);
  // A constant window carries no information.
  std::vector<float> flat(n, 0.3f);
  EXPECT_EQ(Ncc(a.data(), flat.data(), n), -1.0);
  // Noise lowers the score but keeps it well above unrelated windows.
  std::normal_distribution<float> noise(0.f, 0.05f);
  std::vector<float> noisy(3 * n);
  for (int i = 0; i < 3 * n; ++i) noisy[i] = b[i] + noise(rng);
  const double nn = NccChannels(a.data(), noisy.data(), n, 3, n);
  EXPECT_GT(nn, 0.8);
  EXPECT_LT(nn, 1.0);
}

}  // namespace
}  // namespace wild_mvs
