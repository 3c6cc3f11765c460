// Copyright wild_mvs authors. The SIMD kernels of MPGC (mpgc_kernels.h) give
// the same numbers on every instruction set the CPU has as on Highway's
// portable HWY_SCALAR target (plain loops), kernel by kernel and for a
// whole reconstruction of a rendered view. (Thread-count determinism:
// test_mvs_end_to_end DeterministicAcrossThreadCounts, bit-identical.)
#include <gtest/gtest.h>
#include <hwy/targets.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <opencv2/core.hpp>
#include <random>
#include <string>
#include <vector>

#include "synthetic_scene.h"
#include "wild_mvs/core/image.h"
#include "wild_mvs/core/mpgc_kernels.h"
#include "wild_mvs/core/reconstruct_view.h"
#include "wild_mvs/core/thread_pool.h"

namespace wild_mvs {
namespace {

namespace mk = mpgc_kernels;

// Dispatches the kernels to `target` while alive (0 = back to the CPU's).
struct UseTarget {
  explicit UseTarget(int64_t target) {
    hwy::SetSupportedTargetsForTest(target);
  }
  ~UseTarget() { hwy::SetSupportedTargetsForTest(0); }
};

// The targets compiled into the binary and supported here, scalar last.
// The portable fallback the binary has: HWY_SCALAR (GCC < 12.3, plain
// loops) or HWY_EMU128 (other compilers, e.g. clang for the sanitizers).
int64_t FallbackTarget() {
  for (int64_t x : hwy::SupportedAndGeneratedTargets())
    if (x == HWY_SCALAR) return HWY_SCALAR;
  return HWY_EMU128;
}

std::vector<int64_t> VectorTargets() {
  std::vector<int64_t> t;
  for (int64_t x : hwy::SupportedAndGeneratedTargets())
    if (x != HWY_SCALAR && x != HWY_EMU128) t.push_back(x);
  return t;
}

double RelDiff(double a, double b) {
  return std::abs(a - b) / std::max({std::abs(a), std::abs(b), 1e-12});
}

// Random windows of a random-textured image under random patches.
struct KernelCase {
  std::vector<float> image;  // interleaved
  int width = 97, height = 61, channels = 3;
  mk::WindowRays rays;
  alignas(64) double oi[mk::kWindowPixels], oj[mk::kWindowPixels];
  alignas(64) float ref[mk::kWindowFloats], ref_c[mk::kWindowFloats];
  alignas(64) float mask[mk::kWindowFloats], wi[mk::kWindowFloats],
      wj[mk::kWindowFloats];
  int n = 5, npix = 25;
  mk::SampleArgs args;

  // weighted: the lanes of `mask` hold random root weights in [0.2, 1] per
  // pixel (the bilateral window, MpgcOptions::bilateral_*), and
  // ref_c is R's weighted deviation from its weighted mean, times w.
  KernelCase(std::mt19937* rng, int window, int ch, bool weighted = false)
      : channels(ch) {
    std::uniform_real_distribution<float> u(0.f, 1.f);
    image.resize(static_cast<size_t>(width) * height * channels);
    for (float& v : image) v = u(*rng);
    n = window;
    npix = n * n;
    const int half = n / 2;
    std::fill(ref, ref + mk::kWindowFloats, 0.f);
    std::fill(ref_c, ref_c + mk::kWindowFloats, 0.f);
    std::fill(mask, mask + mk::kWindowFloats, 0.f);
    std::fill(wi, wi + mk::kWindowFloats, 0.f);
    std::fill(wj, wj + mk::kWindowFloats, 0.f);
    // A plane seen from a shifted, slightly rotated camera: rays a (the
    // window's pixel rays, z = 1), centre b at the origin.
    std::uniform_real_distribution<double> cx(20, width - 20),
        cy(20, height - 20), tilt(-0.05, 0.05);
    const double x0 = cx(*rng), y0 = cy(*rng), tx = tilt(*rng), ty = tilt(*rng);
    for (int k = 0; k < mk::kWindowPixels; ++k) {
      const int p = k < npix ? k : 0;
      const int i = p % n - half, j = p / n - half;
      oi[k] = i;
      oj[k] = j;
      rays.ax[k] = x0 + 1.1 * i + tx * j;
      rays.ay[k] = y0 + 0.9 * j + ty * i;
      rays.az[k] = 1.0 + 0.001 * (i + j);
    }
    double mean[3] = {0, 0, 0}, wsum = 0;
    for (int k = 0; k < npix; ++k) {
      const float r = weighted ? 0.2f + 0.8f * u(*rng) : 1.f;
      const double w = static_cast<double>(r) * r;
      wsum += w;
      for (int c = 0; c < 4; ++c) {
        mask[4 * k + c] = c < channels ? r : 0.f;
        wi[4 * k + c] = static_cast<float>(oi[k]);
        wj[4 * k + c] = static_cast<float>(oj[k]);
        if (c < channels) {
          ref[4 * k + c] = u(*rng);
          mean[c] += w * ref[4 * k + c];
        }
      }
    }
    for (double& m : mean) m /= wsum;
    for (int k = 0; k < npix; ++k)
      for (int c = 0; c < channels; ++c)
        ref_c[4 * k + c] =
            static_cast<float>(static_cast<double>(mask[4 * k + c]) *
                               mask[4 * k + c] * (ref[4 * k + c] - mean[c]));
    args.data = image.data();
    args.width = width;
    args.height = height;
    args.channels = channels;
    args.rays = &rays;
    args.oi = oi;
    args.oj = oj;
    args.npix = npix;
    args.h = 1.0 + 0.1 * u(*rng);
    args.hs = 0.01 * (u(*rng) - 0.5);
    args.ht = 0.01 * (u(*rng) - 0.5);
  }
};

struct KernelOut {
  bool inside = false;
  alignas(64) float val[mk::kWindowFloats] = {};
  alignas(64) float dval[mk::kWindowFloats] = {};
  double sbb = 0, sab = 0;
  mk::ChannelSums full[4], depth[4];
};

// The kernels' input for the case's R and the samples in o, colour
// scales 1.1, 0.9, 1.
mk::SumsInput SumsOf(const KernelCase& kc, const KernelOut& o, bool center,
                     bool depth_only) {
  static const float kScale[3] = {1.1f, 0.9f, 1.0f};
  mk::SumsInput in;
  in.ref = kc.ref;
  in.ref_c = kc.ref_c;
  in.val = o.val;
  in.dval = o.dval;
  in.scale = kScale;
  in.mask = kc.mask;
  in.wi = kc.wi;
  in.wj = kc.wj;
  in.npix = kc.npix;
  in.center = center;
  in.depth_only = depth_only;
  return in;
}

KernelOut RunKernels(const KernelCase& kc, bool center) {
  KernelOut o;
  o.inside = mk::SampleWindow(kc.args, o.val, o.dval);
  if (!o.inside) return o;
  mk::NccSums(kc.ref_c, o.val, kc.mask, kc.npix, &o.sbb, &o.sab);
  mk::SumsInput in = SumsOf(kc, o, center, /*depth_only=*/false);
  mk::NormalSums(in, o.full);
  in.depth_only = true;
  mk::NormalSums(in, o.depth);
  return o;
}

// Every kernel output on each vector target within 1e-5 (samples: absolute,
// images in [0, 1]) or 1e-4 relative (sums, which float accumulation in a
// different order perturbs) of HWY_SCALAR's; the sampling window also
// leaves the image the same way.
TEST(MpgcKernels, VectorTargetsMatchScalar) {
  const std::vector<int64_t> targets = VectorTargets();
  if (targets.empty()) GTEST_SKIP() << "no vector target on this CPU";
  std::mt19937 rng(7);
  int compared = 0, outside = 0;
  for (int trial = 0; trial < 300; ++trial) {
    const int window = 3 + 2 * (trial % 4);  // 3, 5, 7, 9
    const int channels = trial % 5 == 0 ? 1 : 3;
    KernelCase kc(&rng, window, channels, /*weighted=*/trial % 3 == 1);
    if (trial % 10 == 9) kc.args.b[0] = 500;  // off the image: must fail
    const bool center = trial % 2 == 0;
    KernelOut ref;
    {
      UseTarget scalar(FallbackTarget());
      ASSERT_STREQ(mk::KernelTarget(), hwy::TargetName(FallbackTarget()));
      ref = RunKernels(kc, center);
    }
    for (int64_t t : targets) {
      UseTarget use(t);
      ASSERT_STREQ(mk::KernelTarget(), hwy::TargetName(t));
      const KernelOut o = RunKernels(kc, center);
      ASSERT_EQ(o.inside, ref.inside) << hwy::TargetName(t);
      if (!o.inside) {
        ++outside;
        continue;
      }
      ++compared;
      for (int k = 0; k < mk::kWindowFloats; ++k) {
        ASSERT_NEAR(o.val[k], ref.val[k], 1e-5) << hwy::TargetName(t) << k;
        ASSERT_NEAR(o.dval[k], ref.dval[k], 1e-5 * (1 + std::abs(ref.dval[k])))
            << hwy::TargetName(t) << k;
        if (k >= 4 * kc.npix || k % 4 >= channels) {
          ASSERT_EQ(o.val[k], 0.f);  // unused lanes stay zero
          ASSERT_EQ(o.dval[k], 0.f);
        }
      }
      EXPECT_LT(RelDiff(o.sbb, ref.sbb), 1e-4);
      EXPECT_LT(std::abs(o.sab - ref.sab), 1e-4 * (std::abs(ref.sab) + 1e-3));
      for (int c = 0; c < channels; ++c) {
        const mk::ChannelSums &a = o.full[c], &b = ref.full[c];
        const double tol = 1e-4 * (std::abs(b.h[0]) + std::abs(b.h[3]) +
                                   std::abs(b.h[5]) + 1e-6);
        for (int k = 0; k < 6; ++k) EXPECT_NEAR(a.h[k], b.h[k], tol);
        const double gt = 1e-4 * (std::abs(b.g[0]) + std::abs(b.g[1]) +
                                  std::abs(b.g[2]) + std::sqrt(b.h[0]) + 1e-6);
        for (int k = 0; k < 3; ++k) EXPECT_NEAR(a.g[k], b.g[k], gt);
        for (int k = 0; k < 3; ++k)
          EXPECT_NEAR(
              a.ic[k], b.ic[k],
              1e-4 * (std::abs(b.ic[k]) + std::sqrt(b.h[0] * b.ii)) + 1e-9);
        EXPECT_LT(RelDiff(a.ii, b.ii), 1e-4);
        EXPECT_NEAR(a.ie, b.ie, 1e-4 * (std::abs(b.ii) + std::abs(b.ie)));
        EXPECT_LT(RelDiff(o.depth[c].h[0], a.h[0]), 1e-5);
        EXPECT_LT(RelDiff(o.depth[c].g[0], a.g[0]),
                  1e-4 + 1e-6 / (std::abs(a.g[0]) + 1e-12));
      }
    }
  }
  std::printf("compared %d windows (%d outside) on %zu vector targets\n",
              compared, outside, targets.size());
  EXPECT_GT(compared, 100);
  EXPECT_GT(outside, 0);
}

// With weights (mask = root weights r, w = r^2) the kernels' sums are the
// w-weighted sums about the w-weighted means, computed here directly in
// double precision on the kernels' own samples; with every weight 1 they
// are the plain window's.
TEST(MpgcKernels, WeightedSumsAreTheWeightedDefinitions) {
  std::mt19937 rng(11);
  int compared = 0;
  for (int trial = 0; trial < 60; ++trial) {
    const int channels = trial % 4 == 0 ? 1 : 3;
    const KernelCase kc(&rng, 5, channels, /*weighted=*/trial % 2 == 0);
    const KernelOut o = RunKernels(kc, /*center=*/true);
    if (!o.inside) continue;
    ++compared;
    const float scale[3] = {1.1f, 0.9f, 1.0f};
    double sbb = 0, sab = 0;
    for (int c = 0; c < channels; ++c) {
      double sw = 0, mv = 0, mq = 0, me = 0;
      for (int k = 0; k < kc.npix; ++k) {
        const double w =
            static_cast<double>(kc.mask[4 * k + c]) * kc.mask[4 * k + c];
        const double v = o.val[4 * k + c];
        sw += w;
        mv += w * v;
        mq += w * scale[c] * o.dval[4 * k + c];
        me += w * (kc.ref[4 * k + c] - scale[c] * v);
      }
      mv /= sw;
      mq /= sw;
      me /= sw;
      double h0 = 0, g0 = 0;
      for (int k = 0; k < kc.npix; ++k) {
        const double w =
            static_cast<double>(kc.mask[4 * k + c]) * kc.mask[4 * k + c];
        const double v = o.val[4 * k + c];
        const double q = scale[c] * o.dval[4 * k + c] - mq;
        const double e = kc.ref[4 * k + c] - scale[c] * v - me;
        sbb += w * (v - mv) * (v - mv);
        sab += kc.ref_c[4 * k + c] * v;
        h0 += w * q * q;
        g0 += w * q * e;
      }
      EXPECT_LT(RelDiff(o.full[c].h[0], h0), 1e-4) << trial << " " << c;
      EXPECT_NEAR(o.full[c].g[0], g0, 1e-4 * (std::abs(g0) + std::sqrt(h0)));
      EXPECT_LT(RelDiff(o.depth[c].h[0], h0), 1e-4);
    }
    EXPECT_LT(RelDiff(o.sbb, sbb), 1e-4) << trial;
    EXPECT_NEAR(o.sab, sab, 1e-4 * (std::abs(sab) + 1e-3)) << trial;
  }
  std::printf("compared %d windows on %s\n", compared, mk::KernelTarget());
  EXPECT_GT(compared, 30);
}

// NormalAndNccSums gives exactly (bit for bit) what NormalSums and NccSums
// give on the same samples, on every target the binary has for this CPU
// (the scalar fallback included), centred or not, depth only or full,
// plain or weighted windows: MPGC takes the NCC test's and the next
// update's sums in one pass and must match the schedule step by step.
TEST(MpgcKernels, NormalAndNccSumsAreTheTwoKernels) {
  std::vector<int64_t> targets = VectorTargets();
  targets.push_back(FallbackTarget());
  std::mt19937 rng(5);
  int compared = 0;
  for (int64_t t : targets) {
    UseTarget use(t);
    for (int trial = 0; trial < 80; ++trial) {
      const int window = 3 + 2 * (trial % 4);
      const int channels = trial % 5 == 0 ? 1 : 3;
      const KernelCase kc(&rng, window, channels, /*weighted=*/trial % 3 == 1);
      const bool center = trial % 2 == 0, depth_only = trial % 4 < 2;
      KernelOut o;
      if (!mk::SampleWindow(kc.args, o.val, o.dval)) continue;
      const mk::SumsInput in = SumsOf(kc, o, center, depth_only);
      double sbb = 0, sab = 0;
      mk::ChannelSums two[4], one[4];
      mk::NccSums(kc.ref_c, o.val, kc.mask, kc.npix, &sbb, &sab);
      mk::NormalSums(in, two);
      double fbb = -1, fab = -1;
      mk::NormalAndNccSums(in, one, &fbb, &fab);
      ++compared;
      EXPECT_EQ(fbb, sbb) << hwy::TargetName(t) << " trial " << trial;
      EXPECT_EQ(fab, sab) << hwy::TargetName(t) << " trial " << trial;
      for (int c = 0; c < channels; ++c) {
        const int nh = depth_only ? 1 : 6, ng = depth_only ? 1 : 3;
        for (int k = 0; k < nh; ++k) EXPECT_EQ(one[c].h[k], two[c].h[k]);
        for (int k = 0; k < ng; ++k) EXPECT_EQ(one[c].g[k], two[c].g[k]);
        if (depth_only) continue;
        for (int k = 0; k < 3; ++k) EXPECT_EQ(one[c].ic[k], two[c].ic[k]);
        EXPECT_EQ(one[c].ii, two[c].ii);
        EXPECT_EQ(one[c].ie, two[c].ie);
      }
    }
  }
  std::printf("compared %d windows on %zu targets\n", compared, targets.size());
  EXPECT_GT(compared, 50 * static_cast<int>(targets.size()));
}

// WILD_MVS_SIMD_TARGET (mpgc_kernels::LimitTarget): capping at each target
// the binary has for this CPU makes the kernels dispatch to exactly it; an
// unknown name changes nothing.
TEST(MpgcKernels, LimitTargetCapsTheDispatch) {
  const std::string best = mk::KernelTarget();
  EXPECT_FALSE(mk::LimitTarget("NOPE"));
  EXPECT_EQ(mk::KernelTarget(), best);
  for (int64_t t : hwy::SupportedAndGeneratedTargets()) {  // best first
    ASSERT_TRUE(mk::LimitTarget(hwy::TargetName(t)));
    EXPECT_STREQ(mk::KernelTarget(), hwy::TargetName(t));
  }
  hwy::DisableTargets(0);  // back to the CPU's best
  EXPECT_EQ(mk::KernelTarget(), best);
}

// A whole view reconstructed with the best vector target and with
// HWY_SCALAR: region growing amplifies last-bit differences (a pixel that
// converges one iteration later grows its neighbours from a slightly
// different plane), so the maps are compared statistically: measured on
// this scene (AVX3 vs SCALAR) 99.73 % of the pixels valid in either map are
// valid in both with depths within 1e-4 relative; required >= 99 %, and the
// valid counts within 1 %.
TEST(MpgcKernels, ReconstructionMatchesScalar) {
  const std::vector<int64_t> targets = VectorTargets();
  if (targets.empty()) GTEST_SKIP() << "no vector target on this CPU";
  testing::SyntheticSpec spec = testing::ClutteredSceneSpec(true, false, 105);
  spec.width = 200;
  spec.height = 150;
  spec.focal = 190;
  spec.num_sparse_points = 150;
  const testing::SyntheticScene s = testing::Render(spec);
  auto run = [&](int64_t target) {
    UseTarget use(target);
    ImageCache cache(s.Loader(), 64);
    ThreadPool pool(2);
    return ReconstructView(s.scene, 3, cache, MvsOptions(), &pool, nullptr);
  };
  const DepthMap a = run(FallbackTarget());
  const DepthMap b = run(targets.front());
  int valid_a = 0, valid_b = 0, either = 0, close = 0;
  for (int y = 0; y < a.depth.rows; ++y)
    for (int x = 0; x < a.depth.cols; ++x) {
      const float da = a.depth.at<float>(y, x), db = b.depth.at<float>(y, x);
      valid_a += da > 0;
      valid_b += db > 0;
      if (!(da > 0) && !(db > 0)) continue;
      ++either;
      close += da > 0 && db > 0 && std::abs(da - db) <= 1e-4 * da;
    }
  std::printf("%s vs SCALAR: valid %d / %d, %d of %d within 1e-4 (%.2f %%)\n",
              hwy::TargetName(targets.front()), valid_b, valid_a, close, either,
              100.0 * close / std::max(1, either));
  ASSERT_GT(valid_a, 5000);
  EXPECT_NEAR(valid_b, valid_a, 0.01 * valid_a);
  EXPECT_GE(close, 0.99 * either);
}

}  // namespace
}  // namespace wild_mvs
