// Copyright wild_mvs authors. Image noise against brightness
// (image_noise.h): the estimate recovers a known noise level on textured
// images, follows it across brightness, ignores texture, and the
// reliability it gives undoes what noise takes from an NCC.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <thread>
#include <vector>

#include "wild_mvs/core/image_noise.h"
#include "wild_mvs/core/ncc.h"
#include "wild_mvs/core/patch.h"

namespace wild_mvs {
namespace {

// A colour texture of mean brightness `mean` (a quarter of it on the left
// half) and relative amplitude `amp`: smooth (wavelengths of 30-40 pixels)
// in bands of 40 rows, fine (4-7 pixels) in the bands between, as images
// have smooth and textured parts; plus Gaussian noise of deviation
// `sigma(brightness)`.
template <typename SigmaFn>
std::vector<float> Textured(int w, int h, double mean, double amp,
                            SigmaFn sigma, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> n01(0, 1);
  std::vector<float> im(static_cast<size_t>(w) * h * 3);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      for (int c = 0; c < 3; ++c) {
        const bool fine = (y / 40) % 2 == 1;
        const double t = std::sin(0.16 * x + 0.3 * c) * std::cos(0.21 * y) +
                         (fine ? 0.5 * std::sin(0.9 * x + 0.7 * y + c) +
                                     0.3 * std::sin(1.5 * x - 1.1 * y)
                               : 0.0);
        const double m = mean * (x < w / 2 ? 0.25 : 1.0);  // two brightnesses
        const double v = m + amp * m * t;
        im[(static_cast<size_t>(y) * w + x) * 3 + c] =
            static_cast<float>(v + sigma(m) * n01(rng));
      }
  return im;
}

MatchImage View(const std::vector<float>& im, int w, int h) {
  MatchImage m;
  m.data = im.data();
  m.width = w;
  m.height = h;
  m.channels = 3;
  return m;
}

TEST(ImageNoise, RecoversAKnownLevelOnTexture) {
  const int w = 320, h = 240;
  for (double sigma : {0.003, 0.01, 0.03}) {
    const auto im = Textured(
        w, h, 0.4, 0.3, [&](double) { return sigma; }, 3);
    const NoiseProfile p = NoiseProfile::Estimate(View(im, w, h));
    for (double b : {0.1, 0.4})  // the dark and the bright half
      EXPECT_NEAR(p.Sigma(b), sigma, 0.2 * sigma) << "sigma " << sigma;
  }
}

TEST(ImageNoise, FollowsBrightnessAndIgnoresTexture) {
  const int w = 320, h = 240;
  // Shot-noise-like: deviation grows with brightness.
  const auto im = Textured(
      w, h, 0.4, 0.3, [](double m) { return 0.02 * std::sqrt(m); }, 4);
  const NoiseProfile p = NoiseProfile::Estimate(View(im, w, h));
  EXPECT_NEAR(p.Sigma(0.1), 0.02 * std::sqrt(0.1), 0.25 * 0.02 * 0.32);
  EXPECT_NEAR(p.Sigma(0.4), 0.02 * std::sqrt(0.4), 0.2 * 0.02 * 0.63);
  // Texture alone (no noise): far below the texture's own amplitude.
  const auto clean = Textured(
      w, h, 0.4, 0.3, [](double) { return 0.0; }, 5);
  const NoiseProfile q = NoiseProfile::Estimate(View(clean, w, h));
  EXPECT_LT(q.MaxSigma(), 0.004);
  // Too small an image: no estimate (zero noise).
  EXPECT_EQ(NoiseProfile::Estimate(View(clean, 6, 6)).MaxSigma(), 0.0);
  EXPECT_EQ(NoiseProfile().Sigma(0.5), 0.0);
}

TEST(ImageNoise, ReliabilityUndoesTheAttenuationOfNcc) {
  // Two noisy copies of one window, one much noisier: their NCC is about
  // sqrt(r_a r_b) and the corrected NCC about 1; an unrelated window stays
  // low after the correction.
  std::mt19937 rng(9);
  std::normal_distribution<double> n01(0, 1);
  const int n = 25, ch = 3, trials = 4000;
  const double sa = 0.02, sb = 0.06;
  double sum_raw = 0, sum_corrected = 0, sum_unrelated = 0;
  for (int k = 0; k < trials; ++k) {
    std::vector<float> sig(n * ch), a(n * ch), b(n * ch), u(n * ch);
    for (int i = 0; i < n * ch; ++i) {
      sig[i] = static_cast<float>(0.05 * n01(rng));
      a[i] = static_cast<float>(sig[i] + sa * n01(rng));
      b[i] = static_cast<float>(sig[i] + sb * n01(rng));
      u[i] = static_cast<float>(0.05 * n01(rng) + sb * n01(rng));
    }
    auto ss = [&](const std::vector<float>& v) {
      double s = 0;
      for (int c = 0; c < ch; ++c) {
        double m = 0;
        for (int i = 0; i < n; ++i) m += v[c * n + i];
        m /= n;
        for (int i = 0; i < n; ++i)
          s += (v[c * n + i] - m) * (v[c * n + i] - m);
      }
      return s;
    };
    const double ra = WindowReliability(ss(a), sa * sa, ch, n, n);
    const double rb = WindowReliability(ss(b), sb * sb, ch, n, n);
    const double ru = WindowReliability(ss(u), sb * sb, ch, n, n);
    const double ncc = NccChannels(a.data(), b.data(), n, ch, n);
    sum_raw += ncc;
    sum_corrected += ncc / std::sqrt(ra * rb);
    sum_unrelated +=
        NccChannels(a.data(), u.data(), n, ch, n) / std::sqrt(ra * ru);
  }
  const double expected = std::sqrt(0.05 * 0.05 / (0.05 * 0.05 + sa * sa)) *
                          std::sqrt(0.05 * 0.05 / (0.05 * 0.05 + sb * sb));
  EXPECT_NEAR(sum_raw / trials, expected, 0.05);  // about 0.59
  EXPECT_NEAR(sum_corrected / trials, 1.0, 0.1);
  EXPECT_LT(std::abs(sum_unrelated / trials), 0.1);
  // Limits: no noise = fully reliable; pure noise = the floor.
  EXPECT_DOUBLE_EQ(WindowReliability(1.0, 0.0, 3, 25, 25), 1.0);
  EXPECT_DOUBLE_EQ(WindowReliability(0.1, 1.0, 3, 25, 25), kMinReliability);
}

TEST(ImageNoise, CacheEstimatesEachViewSizeAndChannelsOnce) {
  const auto sigma = [](double m) { return 0.01 + 0.02 * m; };
  const std::vector<float> a = Textured(160, 120, 0.5, 0.3, sigma, 1);
  const std::vector<float> b = Textured(
      160, 120, 0.5, 0.3, [](double) { return 0.05; }, 2);
  const std::vector<float> small = Textured(80, 60, 0.5, 0.3, sigma, 3);
  NoiseProfileCache cache(3);
  // The profile is Estimate's.
  const NoiseProfile pa = cache.Get(0, View(a, 160, 120));
  EXPECT_EQ(pa.MaxSigma(),
            NoiseProfile::Estimate(View(a, 160, 120)).MaxSigma());
  EXPECT_EQ(cache.size(), 1u);
  // A view at a size it was estimated at keeps its profile: the cache's
  // promise is that view 0 at 160 x 120 is always image a.
  EXPECT_EQ(cache.Get(0, View(b, 160, 120)).MaxSigma(), pa.MaxSigma());
  EXPECT_EQ(cache.size(), 1u);
  // Another view, size or channel count is another entry.
  EXPECT_EQ(cache.Get(1, View(b, 160, 120)).MaxSigma(),
            NoiseProfile::Estimate(View(b, 160, 120)).MaxSigma());
  EXPECT_NE(cache.Get(1, View(b, 160, 120)).MaxSigma(), pa.MaxSigma());
  cache.Get(0, View(small, 80, 60));
  EXPECT_EQ(cache.size(), 3u);
  // At capacity the least recently used goes (view 0 at 160 x 120 was
  // used before view 1 and the small one): it is estimated again.
  MatchImage grey = View(a, 160, 120);
  grey.channels = 1;
  grey.width = 240;  // the same floats read as one grey channel
  cache.Get(2, grey);
  EXPECT_EQ(cache.size(), 3u);
  EXPECT_EQ(cache.Get(0, View(b, 160, 120)).MaxSigma(),
            NoiseProfile::Estimate(View(b, 160, 120)).MaxSigma());
  cache.Clear();
  EXPECT_EQ(cache.size(), 0u);
  // Four threads asking for the same views at once get Estimate's profiles.
  std::vector<std::thread> threads;
  std::vector<double> got(8);
  for (int k = 0; k < 4; ++k)
    threads.emplace_back([&, k] {
      got[2 * k] = cache.Get(0, View(a, 160, 120)).MaxSigma();
      got[2 * k + 1] = cache.Get(1, View(b, 160, 120)).MaxSigma();
    });
  for (std::thread& t : threads) t.join();
  for (int k = 0; k < 4; ++k) {
    EXPECT_EQ(got[2 * k], pa.MaxSigma());
    EXPECT_EQ(got[2 * k + 1],
              NoiseProfile::Estimate(View(b, 160, 120)).MaxSigma());
  }
  EXPECT_EQ(cache.size(), 2u);
}

}  // namespace
}  // namespace wild_mvs
