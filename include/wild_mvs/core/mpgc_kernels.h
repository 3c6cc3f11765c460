// Copyright wild_mvs authors. The inner loops of MPGC (mpgc.cpp) in SIMD:
// sampling a window of a neighbour view under the patch model (patch.h),
// the NCC sums and the sums of the linearised least squares (equation 10).
// (Public for the tests that compare instruction sets.)
//
// Runtime dispatch: mpgc_kernels.cpp is compiled once per instruction set
// by Google Highway (hwy/foreach_target.h: SSSE3, SSE4, AVX2, AVX-512 and
// the portable EMU128 fallback on x86) and HWY_DYNAMIC_DISPATCH picks the
// best one the CPU has at the first call, so one binary, built without
// -march, uses AVX2 / AVX-512 where present. (Highway rather than xsimd:
// Debian 12's xsimd 8 has no built-in dispatch; std::experimental::simd
// none at all.)
//
// Layout (chosen by measurement, docs/ARCHITECTURE.md): a window of n x n
// pixels is stored pixel-interleaved with 4 float lanes per pixel (R, G, B,
// 0; grey: g, 0, 0, 0), so one 128-bit load takes a pixel's channels from
// the interleaved image and every reduction runs over 4 * n * n contiguous
// floats whatever the vector width. Buffers have kWindowFloats floats,
// 64-byte aligned; lanes past 4 * n * n are zero (the callers keep them so).
#pragma once

#include <cstdint>
#include <string>

#include "wild_mvs/core/patch.h"

namespace wild_mvs {
namespace mpgc_kernels {

// Doubles in the widest vector the kernels use (AVX-512).
constexpr int kMaxDoubleLanes = 8;
// npix window pixels rounded up to whole vectors of kMaxDoubleLanes.
constexpr int PaddedPixels(int npix) {
  return (npix + kMaxDoubleLanes - 1) / kMaxDoubleLanes * kMaxDoubleLanes;
}
// Pixels of the largest window, padded.
constexpr int kWindowPixels = PaddedPixels(kMaxWindowPixels);
// Floats of a window buffer: 4 per pixel, a multiple of 16 (AVX-512).
constexpr int kWindowFloats = (4 * kMaxWindowPixels + 15) / 16 * 16;

// The window's rays mapped into a view, structure of arrays; entries from
// npix to PaddedPixels(npix) repeat pixel 0, so padded lanes stay valid.
struct WindowRays {
  alignas(64) double ax[kWindowPixels];
  alignas(64) double ay[kWindowPixels];
  alignas(64) double az[kWindowPixels];
};

struct SampleArgs {
  const float* data = nullptr;  // interleaved image (MatchImage)
  int width = 0, height = 0, channels = 3;
  double b[3] = {0, 0, 0};           // PatchView::b
  const WindowRays* rays = nullptr;  // PatchMatcher::PrepareView
  const double* oi = nullptr;        // window column offset per pixel
  const double* oj = nullptr;        // window row offset per pixel
  int npix = 0;
  double h = 0, hs = 0, ht = 0;  // the patch
};

// Samples the window (bilinear, pixel centres at +0.5): val[4 k + c] for
// pixel k and channel c, lanes >= channels zero; with dval also the
// derivative along the ray (d sample / d h). False when any pixel falls
// outside the sampling range or behind the camera (outputs then undefined).
bool SampleWindow(const SampleArgs& args, float* val, float* dval);

// Weights: `mask` holds the square root r of each lane's weight w = r^2
// (1 on the lanes of real pixels and channels for the plain window, the
// bilateral weights of R's window otherwise, 0 on unused lanes); every mean
// below is the w-weighted mean and every sum of products is w-weighted.
//
// NCC sums of a window against R's centred window ref_c (same layout, R's
// weighted deviations from its weighted mean, times w): *sbb = sum over
// channels of w (val - mean_w)^2, *sab = sum of ref_c * val.
void NccSums(const float* ref_c, const float* val, const float* mask, int npix,
             double* sbb, double* sab);

// Sums of the least squares of one view, per channel c (lanes): with
// q = scale_c * dval, e = ref - scale_c * val and the window offsets
// (i, j) = (wi, wj) of each pixel, u = (q, q i, q j) (SumsInput below):
//   h = sum u u^T (upper triangle: 00 01 02 11 12 22), g = sum u e,
//   ic = sum u val, ii = sum val^2, ie = sum val e;
// with `center` every term is taken about its window mean (the photometric
// offset eliminated at its optimum); every sum weighted by w = mask^2.
// depth_only: only h[0] and g[0].
struct ChannelSums {
  double h[6], g[3], ic[3], ii, ie;
};
// The windows of one view's least squares (pointers into kWindowFloats
// buffers in the layout above).
struct SumsInput {
  const float* ref = nullptr;    // R's window
  const float* ref_c = nullptr;  // R's centred window times w (NccSums)
  const float* val = nullptr;    // the view's samples
  const float* dval = nullptr;   // their derivative along the ray
  const float* scale = nullptr;  // the view's colour scale, per channel (3)
  const float* mask = nullptr;   // root weights
  const float* wi = nullptr;     // window column offset i per lane
  const float* wj = nullptr;     // window row offset j per lane
  int npix = 0;
  bool center = true;       // every term about its window mean
  bool depth_only = false;  // only h[0] and g[0]
};
void NormalSums(const SumsInput& in, ChannelSums out[4]);

// NormalSums and NccSums(in.ref_c, in.val, in.mask, in.npix, sbb, sab) of
// the same samples in one pass over the window, each sum the same value as
// the two calls give (MPGC's NCC test and the update after it read the
// same samples).
void NormalAndNccSums(const SumsInput& in, ChannelSums out[4], double* sbb,
                      double* sab);

// Name of the instruction set the kernels dispatch to (e.g. "AVX3").
const char* KernelTarget();

// Caps the instruction set the kernels dispatch to at `name` (a Highway
// target name as KernelTarget() prints it, e.g. "AVX2" on an AVX-512 CPU:
// to measure what a CPU without AVX-512 gets): every better target is
// disabled for the process. False (nothing changed) when this binary has
// no such target for this CPU. Call before the kernels run.
bool LimitTarget(const std::string& name);

}  // namespace mpgc_kernels
}  // namespace wild_mvs
