// Copyright wild_mvs authors. SIMD kernels of MPGC (mpgc_kernels.h), one
// copy per instruction set through Highway's foreach_target.h.
#include "wild_mvs/core/mpgc_kernels.h"

#include <algorithm>
#include <cstddef>
#include <cstring>

#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "src/core/mpgc_kernels.cpp"
#include <hwy/foreach_target.h>  // NOLINT: must precede highway.h
#include <hwy/highway.h>
#include <hwy/targets.h>

HWY_BEFORE_NAMESPACE();
namespace wild_mvs {
namespace mpgc_kernels {
namespace HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

#if HWY_TARGET == HWY_SCALAR
// The portable fallback (one lane: Highway's HWY_SCALAR, which GCC < 12.3
// gets instead of EMU128): the same arithmetic as the vector code below,
// as plain loops over pixels and channels.

bool SampleWindowImpl(const SampleArgs& s, float* HWY_RESTRICT val,
                      float* HWY_RESTRICT dval) {
  const WindowRays& r = *s.rays;
  const int C = s.channels;
  const size_t row = static_cast<size_t>(s.width) * C;
  const double xmax = s.width - 0.5, ymax = s.height - 0.5;
  for (int k = 0; k < s.npix; ++k) {
    const double hh = (s.h + s.oj[k] * s.ht) + s.oi[k] * s.hs;
    const double q2 = s.b[2] + hh * r.az[k];
    const double inv = 1.0 / q2;
    const double x = (s.b[0] + hh * r.ax[k]) * inv;
    const double y = (s.b[1] + hh * r.ay[k]) * inv;
    if (!(q2 > 1e-12 && x >= 0.5 && y >= 0.5 && x < xmax && y < ymax))
      return false;
    const double fxd = x - 0.5, fyd = y - 0.5;
    const int x0 = std::min(static_cast<int>(fxd), s.width - 2);
    const int y0 = std::min(static_cast<int>(fyd), s.height - 2);
    const float fx = static_cast<float>(fxd - x0),
                fy = static_cast<float>(fyd - y0);
    const float* p00 = s.data + static_cast<size_t>(y0) * row + x0 * C;
    const float* p01 = p00 + row;
    const float dx = static_cast<float>((r.ax[k] - x * r.az[k]) * inv);
    const float dy = static_cast<float>((r.ay[k] - y * r.az[k]) * inv);
    for (int c = 0; c < 4; ++c) {
      float v = 0, dv = 0;
      if (c < C) {
        const float dtop = p00[C + c] - p00[c], dbot = p01[C + c] - p01[c];
        const float top = p00[c] + fx * dtop, bot = p01[c] + fx * dbot;
        const float gy = bot - top;
        v = top + fy * gy;
        dv = (dtop + fy * (dbot - dtop)) * dx + gy * dy;
      }
      val[4 * k + c] = v;
      if (dval) dval[4 * k + c] = dv;
    }
  }
  return true;
}

void NccSumsImpl(const float* HWY_RESTRICT ref_c, const float* HWY_RESTRICT val,
                 const float* HWY_RESTRICT mask, int npix, double* sbb,
                 double* sab) {
  float sum[4] = {0, 0, 0, 0}, wsum[4] = {0, 0, 0, 0};
  for (int k = 0; k < 4 * npix; ++k) {
    const float w = mask[k] * mask[k];
    sum[k & 3] += w * val[k];
    wsum[k & 3] += w;
  }
  float mean[4];
  for (int c = 0; c < 4; ++c)
    mean[c] = wsum[c] > 0 ? static_cast<float>(sum[c] / wsum[c]) : 0.0f;
  float bb = 0, ab = 0;
  for (int k = 0; k < 4 * npix; ++k) {
    const float d = (val[k] - mean[k & 3]) * mask[k];
    bb += d * d;
    ab += ref_c[k] * val[k];
  }
  *sbb = bb;
  *sab = ab;
}

void NormalSumsImpl(const SumsInput& in, ChannelSums out[4]) {
  const float* HWY_RESTRICT ref = in.ref;
  const float* HWY_RESTRICT val = in.val;
  const float* HWY_RESTRICT dval = in.dval;
  const float* HWY_RESTRICT mask = in.mask;
  const float* HWY_RESTRICT wi = in.wi;
  const float* HWY_RESTRICT wj = in.wj;
  const int npix = in.npix;
  const bool center = in.center, depth_only = in.depth_only;
  const float sc[4] = {in.scale[0], in.scale[1], in.scale[2], 0.0f};
  float m[5][4] = {};
  if (center) {
    float wsum[4] = {0, 0, 0, 0};
    for (int k = 0; k < 4 * npix; ++k) {
      const int c = k & 3;
      const float w = mask[k] * mask[k];
      const float q = sc[c] * dval[k];
      m[0][c] += w * q;
      m[1][c] += w * (q * wi[k]);
      m[2][c] += w * (q * wj[k]);
      m[3][c] += w * val[k];
      m[4][c] += w * (ref[k] - sc[c] * val[k]);
      wsum[c] += w;
    }
    for (auto& mk : m)
      for (int c = 0; c < 4; ++c)
        mk[c] = wsum[c] > 0 ? static_cast<float>(mk[c] / wsum[c]) : 0.0f;
  }
  float f[14][4] = {};
  for (int k = 0; k < 4 * npix; ++k) {
    const int c = k & 3;
    const float w = mask[k];
    const float q = sc[c] * dval[k];
    const float e = ref[k] - sc[c] * val[k];
    const float u0 = (q - m[0][c]) * w, ue = (e - m[4][c]) * w;
    f[0][c] += u0 * u0;
    f[6][c] += u0 * ue;
    if (depth_only) continue;
    const float u1 = (q * wi[k] - m[1][c]) * w;
    const float u2 = (q * wj[k] - m[2][c]) * w;
    const float ui = (val[k] - m[3][c]) * w;
    f[1][c] += u0 * u1;
    f[2][c] += u0 * u2;
    f[3][c] += u1 * u1;
    f[4][c] += u1 * u2;
    f[5][c] += u2 * u2;
    f[7][c] += u1 * ue;
    f[8][c] += u2 * ue;
    f[9][c] += u0 * ui;
    f[10][c] += u1 * ui;
    f[11][c] += u2 * ui;
    f[12][c] += ui * ui;
    f[13][c] += ui * ue;
  }
  for (int c = 0; c < 4; ++c) {
    ChannelSums& o = out[c];
    for (int k = 0; k < 6; ++k) o.h[k] = f[k][c];
    for (int k = 0; k < 3; ++k) o.g[k] = f[6 + k][c];
    for (int k = 0; k < 3; ++k) o.ic[k] = f[9 + k][c];
    o.ii = f[12][c];
    o.ie = f[13][c];
  }
}

void NormalAndNccSumsImpl(const SumsInput& in, ChannelSums out[4], double* sbb,
                          double* sab) {
  NormalSumsImpl(in, out);
  NccSumsImpl(in.ref_c, in.val, in.mask, in.npix, sbb, sab);
}

#else  // vector targets: at least 4 float lanes

// v's 128-bit blocks added up (lane l of the result = the sum of the lanes
// l mod 4): all vector adds.
template <class D>
HWY_INLINE hn::Vec<hn::FixedTag<float, 4> > FoldTo128(D d, hn::Vec<D> v) {
  if constexpr (hn::MaxLanes(d) > 4) {
    const hn::Half<D> dh;
    return FoldTo128(dh, hn::Add(hn::LowerHalf(dh, v), hn::UpperHalf(dh, v)));
  } else {
    return v;
  }
}

// Lane sums of v folded to the 4 channel lanes (lane l -> channel l % 4).
template <class D, class V>
HWY_INLINE void FoldChannels(D d, V v, double out[4]) {
  alignas(16) float lanes[4];
  hn::Store(FoldTo128(d, v), hn::FixedTag<float, 4>(), lanes);
  for (int c = 0; c < 4; ++c) out[c] = lanes[c];
}

template <class D, class V>
HWY_INLINE double SumLanes(D d, V v) {
  double c[4];
  FoldChannels(d, v, c);
  return c[0] + c[1] + c[2] + c[3];
}

// m[c] /= the channel's total weight (lane sums of w folded; 0 where a
// channel has no weight, e.g. the unused fourth lane).
template <class D, class V>
HWY_INLINE void DivideByWeights(D d, V w, double m[4]) {
  double ws[4];
  FoldChannels(d, w, ws);
  for (int c = 0; c < 4; ++c) m[c] = ws[c] > 0 ? m[c] / ws[c] : 0.0;
}

// Four per-channel values repeated over every 128-bit block of a vector.
template <class D>
HWY_INLINE hn::Vec<D> Channels(D d, const double c[4]) {
  alignas(16) float f[4] = {static_cast<float>(c[0]), static_cast<float>(c[1]),
                            static_cast<float>(c[2]), static_cast<float>(c[3])};
  return hn::LoadDup128(d, f);
}

// Floats of a window of npix pixels rounded up to whole vectors of d.
template <class D>
HWY_INLINE int Floats(D d, int npix) {
  const int n = static_cast<int>(hn::Lanes(d));
  return (4 * npix + n - 1) / n * n;
}

// The 4-float pixels at p[q] + off (q < lanes / 4) side by side.
template <class D>
HWY_INLINE hn::Vec<D> LoadPixels(D d, const float* const* p, size_t off) {
  if constexpr (hn::MaxLanes(d) > 4) {
    const hn::Half<D> dh;
    constexpr size_t kHalf = hn::MaxLanes(d) / 8;  // pixels per half
    return hn::Combine(d, LoadPixels(dh, p + kHalf, off),
                       LoadPixels(dh, p, off));
  } else {
    return hn::LoadU(d, p[0] + off);
  }
}

// One value per pixel (v[q], q < lanes / 4) repeated over its 4 lanes.
template <class D>
HWY_INLINE hn::Vec<D> PerPixel(D d, const float* v) {
  if constexpr (hn::MaxLanes(d) > 4) {
    alignas(64) static constexpr int32_t kRep[16] = {0, 0, 0, 0, 1, 1, 1, 1,
                                                     2, 2, 2, 2, 3, 3, 3, 3};
    return hn::TableLookupLanes(hn::LoadDup128(d, v),
                                hn::SetTableIndices(d, kRep));
  } else {
    return hn::Set(d, v[0]);
  }
}

// Where a window's samples fall in the view: per pixel the top-left
// pixel of its bilinear cell, the fractions inside it and (with the
// gradient) the pixel offsets per unit of h.
struct SamplePositions {
  alignas(64) int32_t x0[kWindowPixels], y0[kWindowPixels];
  alignas(64) float fx[kWindowPixels], fy[kWindowPixels];
  alignas(64) float dx[kWindowPixels], dy[kWindowPixels];
};

// SamplePositions of pixels [k, k + Lanes(dd)) in double precision (as
// the scalar code does); false when one falls outside the sampling range or
// behind the camera.
template <class DD>
HWY_INLINE bool PositionsAt(DD dd, const SampleArgs& s, int k, bool gradient,
                            SamplePositions* p) {
  const hn::Rebind<int32_t, DD> di;
  const hn::Rebind<float, DD> df;
  const auto half = hn::Set(dd, 0.5);
  const WindowRays& r = *s.rays;
  const auto hh =
      hn::Add(hn::Add(hn::Set(dd, s.h),
                      hn::Mul(hn::Load(dd, s.oj + k), hn::Set(dd, s.ht))),
              hn::Mul(hn::Load(dd, s.oi + k), hn::Set(dd, s.hs)));
  const auto ax = hn::Load(dd, r.ax + k), ay = hn::Load(dd, r.ay + k),
             az = hn::Load(dd, r.az + k);
  const auto q2 = hn::Add(hn::Set(dd, s.b[2]), hn::Mul(hh, az));
  const auto inv = hn::Div(hn::Set(dd, 1.0), q2);
  const auto x = hn::Mul(hn::Add(hn::Set(dd, s.b[0]), hn::Mul(hh, ax)), inv);
  const auto y = hn::Mul(hn::Add(hn::Set(dd, s.b[1]), hn::Mul(hh, ay)), inv);
  const auto ok = hn::And(hn::And(hn::Gt(q2, hn::Set(dd, 1e-12)),
                                  hn::And(hn::Ge(x, half), hn::Ge(y, half))),
                          hn::And(hn::Lt(x, hn::Set(dd, s.width - 0.5)),
                                  hn::Lt(y, hn::Set(dd, s.height - 0.5))));
  if (!hn::AllTrue(dd, ok)) return false;
  const auto fxd = hn::Sub(x, half), fyd = hn::Sub(y, half);
  const auto x0 = hn::Min(hn::DemoteTo(di, fxd), hn::Set(di, s.width - 2));
  const auto y0 = hn::Min(hn::DemoteTo(di, fyd), hn::Set(di, s.height - 2));
  hn::Store(x0, di, p->x0 + k);
  hn::Store(y0, di, p->y0 + k);
  hn::Store(hn::DemoteTo(df, hn::Sub(fxd, hn::PromoteTo(dd, x0))), df,
            p->fx + k);
  hn::Store(hn::DemoteTo(df, hn::Sub(fyd, hn::PromoteTo(dd, y0))), df,
            p->fy + k);
  if (gradient) {
    hn::Store(hn::DemoteTo(df, hn::Mul(hn::Sub(ax, hn::Mul(x, az)), inv)), df,
              p->dx + k);
    hn::Store(hn::DemoteTo(df, hn::Mul(hn::Sub(ay, hn::Mul(y, az)), inv)), df,
              p->dy + k);
  }
  return true;
}

bool SampleWindowImpl(const SampleArgs& s, float* HWY_RESTRICT val,
                      float* HWY_RESTRICT dval) {
  // 1. Pixel positions in the view, vectorised over the window's pixels.
  // Step 2 reads them up to the next multiple of P = half the double lanes,
  // so a last group of at most that many pixels takes a half vector (a 5 x 5
  // window: 3 full vectors of 8 and a half one, on AVX-512).
  const hn::ScalableTag<double> dd;
  const int nd = static_cast<int>(hn::Lanes(dd));
  SamplePositions pos;
  int k = 0;
  for (; k + nd <= s.npix; k += nd)
    if (!PositionsAt(dd, s, k, dval != nullptr, &pos)) return false;
  if (k < s.npix) {
    bool ok;
    if constexpr (hn::MaxLanes(dd) >= 4) {
      ok = s.npix - k <= nd / 2 ? PositionsAt(hn::Half<decltype(dd)>(), s, k,
                                              dval != nullptr, &pos)
                                : PositionsAt(dd, s, k, dval != nullptr, &pos);
    } else {
      ok = PositionsAt(dd, s, k, dval != nullptr, &pos);
    }
    if (!ok) return false;
  }
  const int32_t* x0s = pos.x0;
  const int32_t* y0s = pos.y0;
  const float *fxs = pos.fx, *fys = pos.fy, *dxs = pos.dx, *dys = pos.dy;
  // 2. Bilinear interpolation, P = lanes / 4 pixels per vector: each
  // pixel's channels are one 128-bit load straight from the interleaved
  // image (lanes past the channels hold the next pixel's values and are
  // zeroed), so the window is written in its 4-lane layout with no shuffle.
  const hn::ScalableTag<float> d;
  const int P = static_cast<int>(hn::Lanes(d)) / 4;
  alignas(64) static constexpr float kLane4[16] = {0, 1, 2, 3, 0, 1, 2, 3,
                                                   0, 1, 2, 3, 0, 1, 2, 3};
  const auto chan_keep = hn::Lt(hn::Load(d, kLane4), hn::Set(d, s.channels));
  const size_t C = static_cast<size_t>(s.channels);
  const size_t row = static_cast<size_t>(s.width) * C;
  const size_t total = row * static_cast<size_t>(s.height);
  for (int k = 0; k < s.npix; k += P) {
    const float* p00[4];
    const float* p01[4];
    bool inside = true;
    for (int q = 0; q < P; ++q) {
      const size_t o = static_cast<size_t>(y0s[k + q]) * row + x0s[k + q] * C;
      p00[q] = s.data + o;
      p01[q] = p00[q] + row;
      inside = inside && o + row + C + 4 <= total;
    }
    hn::Vec<decltype(d)> v00, v10, v01, v11;
    if (inside) {
      v00 = LoadPixels(d, p00, 0);
      v10 = LoadPixels(d, p00, C);
      v01 = LoadPixels(d, p01, 0);
      v11 = LoadPixels(d, p01, C);
    } else {  // the image's last pixels: never read past its end
      alignas(64) float t[4][64] = {};
      for (int q = 0; q < P; ++q)
        for (size_t c = 0; c < C; ++c) {
          t[0][4 * q + c] = p00[q][c];
          t[1][4 * q + c] = p00[q][C + c];
          t[2][4 * q + c] = p01[q][c];
          t[3][4 * q + c] = p01[q][C + c];
        }
      v00 = hn::Load(d, t[0]);
      v10 = hn::Load(d, t[1]);
      v01 = hn::Load(d, t[2]);
      v11 = hn::Load(d, t[3]);
    }
    auto keep = chan_keep;
    if (k + P > s.npix)
      keep =
          hn::And(keep, hn::FirstN(d, static_cast<size_t>(4 * (s.npix - k))));
    const auto fx = PerPixel(d, fxs + k), fy = PerPixel(d, fys + k);
    const auto dtop = hn::Sub(v10, v00), dbot = hn::Sub(v11, v01);
    const auto top = hn::Add(v00, hn::Mul(fx, dtop));
    const auto bot = hn::Add(v01, hn::Mul(fx, dbot));
    const auto gy = hn::Sub(bot, top);
    hn::Store(hn::IfThenElseZero(keep, hn::Add(top, hn::Mul(fy, gy))), d,
              val + 4 * k);
    if (dval) {
      const auto gx = hn::Add(dtop, hn::Mul(fy, hn::Sub(dbot, dtop)));
      const auto dv = hn::Add(hn::Mul(gx, PerPixel(d, dxs + k)),
                              hn::Mul(gy, PerPixel(d, dys + k)));
      hn::Store(hn::IfThenElseZero(keep, dv), d, dval + 4 * k);
    }
  }
  return true;
}

void NccSumsImpl(const float* HWY_RESTRICT ref_c, const float* HWY_RESTRICT val,
                 const float* HWY_RESTRICT mask, int npix, double* sbb,
                 double* sab) {
  const hn::ScalableTag<float> d;
  const int n = static_cast<int>(hn::Lanes(d));
  const int nf = Floats(d, npix);
  // Two passes (mean, then centred sums): float keeps its precision.
  auto sum = hn::Zero(d), wsum = sum;
  for (int k = 0; k < nf; k += n) {
    const auto r = hn::Load(d, mask + k);
    const auto w = hn::Mul(r, r);
    sum = hn::MulAdd(w, hn::Load(d, val + k), sum);
    wsum = hn::Add(wsum, w);
  }
  double mean[4];
  FoldChannels(d, sum, mean);
  DivideByWeights(d, wsum, mean);
  const auto mv = Channels(d, mean);
  auto bb = hn::Zero(d), ab = hn::Zero(d);
  for (int k = 0; k < nf; k += n) {
    const auto v = hn::Load(d, val + k);
    const auto c = hn::Mul(hn::Sub(v, mv), hn::Load(d, mask + k));
    bb = hn::MulAdd(c, c, bb);
    ab = hn::MulAdd(hn::Load(d, ref_c + k), v, ab);
  }
  *sbb = SumLanes(d, bb);
  *sab = SumLanes(d, ab);
}

// NormalSums; with kNcc also NccSums of the same samples (ref_c, sbb,
// sab), each of its sums accumulated from the same terms in the same order
// as NccSumsImpl does, so with the same value.
template <bool kNcc>
HWY_INLINE void NormalSumsT(const SumsInput& in, ChannelSums out[4],
                            double* sbb, double* sab) {
  const float* HWY_RESTRICT ref = in.ref;
  const float* HWY_RESTRICT ref_c = in.ref_c;
  const float* HWY_RESTRICT val = in.val;
  const float* HWY_RESTRICT dval = in.dval;
  const float* HWY_RESTRICT mask = in.mask;
  const float* HWY_RESTRICT wi = in.wi;
  const float* HWY_RESTRICT wj = in.wj;
  const int npix = in.npix;
  const bool center = in.center, depth_only = in.depth_only;
  const float* scale = in.scale;
  const hn::ScalableTag<float> d;
  const int n = static_cast<int>(hn::Lanes(d));
  const int nf = Floats(d, npix);
  const double sc4[4] = {scale[0], scale[1], scale[2], 0.0};
  const auto sc = Channels(d, sc4);
  // Pass 1: the window means of q, q i, q j, I and e per channel (and the
  // NCC's mean of I, the same sums as m[3]).
  double m[5][4] = {};
  double ncc_mean[4] = {};
  if (center && depth_only) {
    auto sq = hn::Zero(d), se = sq, sw = sq, sv = sq;
    for (int k = 0; k < nf; k += n) {
      const auto r = hn::Load(d, mask + k);
      const auto w = hn::Mul(r, r);
      const auto I = hn::Load(d, val + k);
      const auto q = hn::Mul(sc, hn::Load(d, dval + k));
      sq = hn::MulAdd(w, q, sq);
      se = hn::MulAdd(w, hn::Sub(hn::Load(d, ref + k), hn::Mul(sc, I)), se);
      if constexpr (kNcc) sv = hn::MulAdd(w, I, sv);
      sw = hn::Add(sw, w);
    }
    FoldChannels(d, sq, m[0]);
    FoldChannels(d, se, m[4]);
    DivideByWeights(d, sw, m[0]);
    DivideByWeights(d, sw, m[4]);
    if constexpr (kNcc) {
      FoldChannels(d, sv, ncc_mean);
      DivideByWeights(d, sw, ncc_mean);
    }
  } else if (center) {
    auto sq = hn::Zero(d), sqi = sq, sqj = sq, si = sq, se = sq, sw = sq;
    for (int k = 0; k < nf; k += n) {
      const auto r = hn::Load(d, mask + k);
      const auto w = hn::Mul(r, r);
      const auto I = hn::Load(d, val + k);
      const auto q = hn::Mul(sc, hn::Load(d, dval + k));
      const auto e = hn::Sub(hn::Load(d, ref + k), hn::Mul(sc, I));
      sq = hn::MulAdd(w, q, sq);
      sqi = hn::MulAdd(w, hn::Mul(q, hn::Load(d, wi + k)), sqi);
      sqj = hn::MulAdd(w, hn::Mul(q, hn::Load(d, wj + k)), sqj);
      si = hn::MulAdd(w, I, si);
      se = hn::MulAdd(w, e, se);
      sw = hn::Add(sw, w);
    }
    FoldChannels(d, sq, m[0]);
    FoldChannels(d, sqi, m[1]);
    FoldChannels(d, sqj, m[2]);
    FoldChannels(d, si, m[3]);
    FoldChannels(d, se, m[4]);
    for (auto& mk : m) DivideByWeights(d, sw, mk);
    if constexpr (kNcc)
      for (int c = 0; c < 4; ++c) ncc_mean[c] = m[3][c];
  } else if (kNcc) {  // no centring: the NCC's mean alone
    auto sv = hn::Zero(d), sw = sv;
    for (int k = 0; k < nf; k += n) {
      const auto r = hn::Load(d, mask + k);
      const auto w = hn::Mul(r, r);
      sv = hn::MulAdd(w, hn::Load(d, val + k), sv);
      sw = hn::Add(sw, w);
    }
    FoldChannels(d, sv, ncc_mean);
    DivideByWeights(d, sw, ncc_mean);
  }
  const auto mq = Channels(d, m[0]), mqi = Channels(d, m[1]),
             mqj = Channels(d, m[2]), mi = Channels(d, m[3]),
             me = Channels(d, m[4]), mv = Channels(d, ncc_mean);
  // Pass 2: the centred (or plain) products (and the NCC's sums).
  auto h00 = hn::Zero(d), g0 = h00, bb = h00, ab = h00;
  if (depth_only) {
    for (int k = 0; k < nf; k += n) {
      const auto w = hn::Load(d, mask + k);
      const auto I = hn::Load(d, val + k);
      const auto q = hn::Mul(sc, hn::Load(d, dval + k));
      const auto e = hn::Sub(hn::Load(d, ref + k), hn::Mul(sc, I));
      const auto u0 = hn::Mul(hn::Sub(q, mq), w);
      const auto ue = hn::Mul(hn::Sub(e, me), w);
      h00 = hn::MulAdd(u0, u0, h00);
      g0 = hn::MulAdd(u0, ue, g0);
      if constexpr (kNcc) {
        const auto cv = hn::Mul(hn::Sub(I, mv), w);
        bb = hn::MulAdd(cv, cv, bb);
        ab = hn::MulAdd(hn::Load(d, ref_c + k), I, ab);
      }
    }
    if constexpr (kNcc) {
      *sbb = SumLanes(d, bb);
      *sab = SumLanes(d, ab);
    }
    double a[4], b[4];
    FoldChannels(d, h00, a);
    FoldChannels(d, g0, b);
    for (int c = 0; c < 4; ++c) {
      out[c] = ChannelSums{};
      out[c].h[0] = a[c];
      out[c].g[0] = b[c];
    }
    return;
  }
  auto h01 = h00, h02 = h00, h11 = h00, h12 = h00, h22 = h00;
  auto g1 = h00, g2 = h00, i0 = h00, i1 = h00, i2 = h00, ii = h00, ie = h00;
  for (int k = 0; k < nf; k += n) {
    const auto w = hn::Load(d, mask + k);
    const auto I = hn::Load(d, val + k);
    const auto q = hn::Mul(sc, hn::Load(d, dval + k));
    const auto e = hn::Sub(hn::Load(d, ref + k), hn::Mul(sc, I));
    const auto u0 = hn::Mul(hn::Sub(q, mq), w);
    const auto u1 = hn::Mul(hn::Sub(hn::Mul(q, hn::Load(d, wi + k)), mqi), w);
    const auto u2 = hn::Mul(hn::Sub(hn::Mul(q, hn::Load(d, wj + k)), mqj), w);
    const auto ui = hn::Mul(hn::Sub(I, mi), w);
    const auto ue = hn::Mul(hn::Sub(e, me), w);
    h00 = hn::MulAdd(u0, u0, h00);
    h01 = hn::MulAdd(u0, u1, h01);
    h02 = hn::MulAdd(u0, u2, h02);
    h11 = hn::MulAdd(u1, u1, h11);
    h12 = hn::MulAdd(u1, u2, h12);
    h22 = hn::MulAdd(u2, u2, h22);
    g0 = hn::MulAdd(u0, ue, g0);
    g1 = hn::MulAdd(u1, ue, g1);
    g2 = hn::MulAdd(u2, ue, g2);
    i0 = hn::MulAdd(u0, ui, i0);
    i1 = hn::MulAdd(u1, ui, i1);
    i2 = hn::MulAdd(u2, ui, i2);
    ii = hn::MulAdd(ui, ui, ii);
    ie = hn::MulAdd(ui, ue, ie);
    if constexpr (kNcc) {
      if (!center) {  // centred, ui is the NCC's deviation: bb = ii
        const auto cv = hn::Mul(hn::Sub(I, mv), w);
        bb = hn::MulAdd(cv, cv, bb);
      }
      ab = hn::MulAdd(hn::Load(d, ref_c + k), I, ab);
    }
  }
  if constexpr (kNcc) {
    *sbb = SumLanes(d, center ? ii : bb);
    *sab = SumLanes(d, ab);
  }
  double f[14][4];
  FoldChannels(d, h00, f[0]);
  FoldChannels(d, h01, f[1]);
  FoldChannels(d, h02, f[2]);
  FoldChannels(d, h11, f[3]);
  FoldChannels(d, h12, f[4]);
  FoldChannels(d, h22, f[5]);
  FoldChannels(d, g0, f[6]);
  FoldChannels(d, g1, f[7]);
  FoldChannels(d, g2, f[8]);
  FoldChannels(d, i0, f[9]);
  FoldChannels(d, i1, f[10]);
  FoldChannels(d, i2, f[11]);
  FoldChannels(d, ii, f[12]);
  FoldChannels(d, ie, f[13]);
  for (int c = 0; c < 4; ++c) {
    ChannelSums& o = out[c];
    for (int k = 0; k < 6; ++k) o.h[k] = f[k][c];
    for (int k = 0; k < 3; ++k) o.g[k] = f[6 + k][c];
    for (int k = 0; k < 3; ++k) o.ic[k] = f[9 + k][c];
    o.ii = f[12][c];
    o.ie = f[13][c];
  }
}

void NormalSumsImpl(const SumsInput& in, ChannelSums out[4]) {
  NormalSumsT<false>(in, out, nullptr, nullptr);
}

void NormalAndNccSumsImpl(const SumsInput& in, ChannelSums out[4], double* sbb,
                          double* sab) {
  NormalSumsT<true>(in, out, sbb, sab);
}

#endif  // HWY_TARGET == HWY_SCALAR

const char* KernelTargetImpl() { return hwy::TargetName(HWY_TARGET); }

}  // namespace HWY_NAMESPACE
}  // namespace mpgc_kernels
}  // namespace wild_mvs
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace wild_mvs {
namespace mpgc_kernels {

HWY_EXPORT(SampleWindowImpl);
HWY_EXPORT(NccSumsImpl);
HWY_EXPORT(NormalSumsImpl);
HWY_EXPORT(NormalAndNccSumsImpl);
HWY_EXPORT(KernelTargetImpl);

bool SampleWindow(const SampleArgs& args, float* val, float* dval) {
  return HWY_DYNAMIC_DISPATCH(SampleWindowImpl)(args, val, dval);
}

void NccSums(const float* ref_c, const float* val, const float* mask, int npix,
             double* sbb, double* sab) {
  HWY_DYNAMIC_DISPATCH(NccSumsImpl)(ref_c, val, mask, npix, sbb, sab);
}

void NormalSums(const SumsInput& in, ChannelSums out[4]) {
  HWY_DYNAMIC_DISPATCH(NormalSumsImpl)(in, out);
}

void NormalAndNccSums(const SumsInput& in, ChannelSums out[4], double* sbb,
                      double* sab) {
  HWY_DYNAMIC_DISPATCH(NormalAndNccSumsImpl)(in, out, sbb, sab);
}

const char* KernelTarget() { return HWY_DYNAMIC_DISPATCH(KernelTargetImpl)(); }

bool LimitTarget(const std::string& name) {
  for (int64_t t : hwy::SupportedAndGeneratedTargets()) {
    if (name != hwy::TargetName(t)) continue;
    // Highway's target bits: a lower bit is a better target.
    hwy::DisableTargets(t - 1);
    return true;
  }
  return false;
}

}  // namespace mpgc_kernels
}  // namespace wild_mvs
#endif  // HWY_ONCE
