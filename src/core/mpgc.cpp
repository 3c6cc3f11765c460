// Copyright wild_mvs authors.
#include "wild_mvs/core/mpgc.h"

#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>
#include <limits>

#include "wild_mvs/core/error.h"
#include "wild_mvs/core/ncc.h"

namespace wild_mvs {

int AutoWindowStep(int step, int width, int height) {
  if (step > 0) return step;
  return std::max(width, height) >= kWideWindowFromPx ? 2 : 1;
}

void UseWideThresholds(int width, int height, MpgcOptions* mpgc,
                       LocalViewSelectionOptions* local) {
  if (AutoWindowStep(mpgc->window_step, width, height) < 2) return;
  mpgc->drop_ncc = mpgc->wide_drop_ncc;
  local->min_ncc = local->wide_min_ncc;
}

void MpgcOptions::Check() const {
  Require(window >= 3 && window <= kMaxWindow && window % 2 == 1,
          "mvs.mpgc.window = ", window, " must be odd and in [3, ", kMaxWindow,
          "]");
  Require(window_step >= 0 && window_step <= 4,
          "mvs.mpgc.window_step = ", window_step,
          " must be in [0, 4] (0 = by image size)");
  Require(drop_ncc >= -1 && drop_ncc <= 1, "mvs.mpgc.drop_ncc = ", drop_ncc,
          " must be in [-1, 1]");
  Require(wide_drop_ncc >= -1 && wide_drop_ncc <= 1,
          "mvs.mpgc.wide_drop_ncc = ", wide_drop_ncc, " must be in [-1, 1]");
  Require(explain_margin >= 0 && explain_margin <= 2,
          "mvs.mpgc.explain_margin = ", explain_margin,
          " must be in [0, 2] (ablation.explain_test false switches the "
          "test off)");
  Require(explain_below_ncc >= -1 && explain_below_ncc <= 1,
          "mvs.mpgc.explain_below_ncc = ", explain_below_ncc,
          " must be in [-1, 1]");
  Require(std::isfinite(bilateral_sigma_color) && bilateral_sigma_color > 0,
          "mvs.mpgc.bilateral_sigma_color = ", bilateral_sigma_color,
          " must be > 0 (ablation.bilateral_window false: the plain "
          "window)");
  Require(std::isfinite(bilateral_sigma_space) && bilateral_sigma_space > 0,
          "mvs.mpgc.bilateral_sigma_space = ", bilateral_sigma_space,
          " must be > 0");
  Require(std::isfinite(bilateral_min_weight) && bilateral_min_weight > 0 &&
              bilateral_min_weight <= 1,
          "mvs.mpgc.bilateral_min_weight = ", bilateral_min_weight,
          " must be in (0, 1]");
  Require(min_active_views >= 1 && min_active_views <= kMaxActive,
          "mvs.mpgc.min_active_views = ", min_active_views, " must be in [1, ",
          kMaxActive, "]");
}

PatchMatcher::PatchMatcher(const PatchContext& context, const MpgcOptions& mpgc,
                           const LocalViewSelectionOptions& local,
                           const MpgcSchedule& schedule)
    : ctx_(context), mpgc_(mpgc), local_(local), schedule_(schedule) {
  mpgc_.Check();
  local_.Check();
  Require(mpgc_.window == ctx_.window, "PatchMatcher: window ", mpgc_.window,
          " differs from the context's ", ctx_.window);
  Require(mpgc_.min_active_views <= local_.num_active,
          "mvs.mpgc.min_active_views = ", mpgc_.min_active_views,
          " must not exceed mvs.local.num_active = ", local_.num_active);
  n_ = mpgc_.window;
  step_ = AutoWindowStep(mpgc_.window_step, ctx_.ref_image.width,
                         ctx_.ref_image.height);
  half_ = n_ / 2;
  reach_ = half_ * step_;
  npix_ = n_ * n_;
  channels_ = ctx_.ref_image.channels;
  Require(channels_ == 1 || channels_ == 3, "PatchMatcher: ", channels_,
          " channels (1 or 3 expected)");
  for (const PatchView& v : ctx_.views)
    Require(v.image.channels == channels_,
            "PatchMatcher: neighbour images must have the reference's ",
            channels_, " channels");
  static_assert(kMaxNeighbors <= EpipolarWeights::kMaxViews,
                "every neighbour must fit the epipolar weights");
  Require(ctx_.views.size() <= static_cast<size_t>(kMaxNeighbors),
          "PatchMatcher: too many neighbours");
  for (size_t v = 0; v < ctx_.views.size(); ++v) {
    global_scores_[v] = ctx_.views[v].global_score;
    by_global_score_[v] = static_cast<int>(v);
  }
  std::stable_sort(
      by_global_score_, by_global_score_ + ctx_.views.size(),
      [this](int a, int b) { return global_scores_[a] > global_scores_[b]; });
  // The kernels' constant per-lane tables; every unused lane stays zero.
  constexpr int nf = mpgc_kernels::kWindowFloats;
  std::fill(ref_, ref_ + nf, 0.0f);
  std::fill(ref_centered_, ref_centered_ + nf, 0.0f);
  std::fill(mask_, mask_ + nf, 0.0f);
  std::fill(wi_, wi_ + nf, 0.0f);
  std::fill(wj_, wj_ + nf, 0.0f);
  for (int k = 0; k < mpgc_kernels::kWindowPixels; ++k) {
    const int p = k < npix_ ? k : 0;  // padding repeats pixel 0
    oi_[k] = (p % n_ - half_) * step_;
    oj_[k] = (p / n_ - half_) * step_;
  }
  for (int k = 0; k < npix_; ++k) {
    const double di = oi_[k] / step_, dj = oj_[k] / step_;
    space_weight_[k] =
        std::exp(-(di * di + dj * dj) / (2 * mpgc_.bilateral_sigma_space *
                                         mpgc_.bilateral_sigma_space));
    space_weight_sum_ += space_weight_[k];
    weight_[k] = 1;
  }
  weight_sum_ = npix_;
  for (int k = 0; k < npix_; ++k)
    for (int c = 0; c < 4; ++c) {
      mask_[4 * k + c] = c < channels_ ? 1.0f : 0.0f;
      wi_[4 * k + c] = static_cast<float>(oi_[k]);
      wj_[4 * k + c] = static_cast<float>(oj_[k]);
    }
  for (SlotData& sl : slots_) {
    std::fill(sl.val, sl.val + nf, 0.0f);
    std::fill(sl.dval, sl.dval + nf, 0.0f);
  }
}

bool PatchMatcher::WindowInside(int s, int t) const {
  return s - reach_ >= 0 && t - reach_ >= 0 &&
         s + reach_ < ctx_.ref_image.width &&
         t + reach_ < ctx_.ref_image.height;
}

// Precomputes the window's rays mapped into view v.
bool PatchMatcher::PrepareView(int v, int slot_index) {
  SlotData& sl = slots_[slot_index];
  sl.view = v;
  const Eigen::Matrix3d& A = ctx_.views[v].A;
  const double u0 = s_ + 0.5 - reach_, v0 = t_ + 0.5 - reach_;
  const Eigen::Vector3d base = A * Eigen::Vector3d(u0, v0, 1.0);
  const Eigen::Vector3d cu = step_ * A.col(0), cv = step_ * A.col(1);
  mpgc_kernels::WindowRays& r = sl.rays;
  int idx = 0;
  for (int j = 0; j < n_; ++j) {
    const Eigen::Vector3d row = base + j * cv;
    for (int i = 0; i < n_; ++i, ++idx) {
      const double w = inv_norm_[idx];
      r.ax[idx] = (row.x() + i * cu.x()) * w;
      r.ay[idx] = (row.y() + i * cu.y()) * w;
      r.az[idx] = (row.z() + i * cu.z()) * w;
    }
  }
  for (int k = npix_; k < mpgc_kernels::PaddedPixels(npix_); ++k) {
    r.ax[k] = r.ax[0];
    r.ay[k] = r.ay[0];
    r.az[k] = r.az[0];
  }
  return true;
}

// Samples view slot at the current (h, hs, ht) (mpgc_kernels.h); false when
// any window pixel falls outside the image or behind the camera.
bool PatchMatcher::SampleSlot(int slot_index, bool with_gradient) {
  SlotData& sl = slots_[slot_index];
  const PatchView& pv = ctx_.views[sl.view];
  mpgc_kernels::SampleArgs a;
  a.data = pv.image.data;
  a.width = pv.image.width;
  a.height = pv.image.height;
  a.channels = pv.image.channels;
  a.b[0] = pv.b.x();
  a.b[1] = pv.b.y();
  a.b[2] = pv.b.z();
  a.rays = &sl.rays;
  a.oi = oi_;
  a.oj = oj_;
  a.npix = npix_;
  a.h = h_;
  a.hs = hs_;
  a.ht = ht_;
  sl.sums_kind = SlotData::Sums::kNone;
  return mpgc_kernels::SampleWindow(a, sl.val,
                                    with_gradient ? sl.dval : nullptr);
}

// NccChannels(ref_, val) with R's centred window and its sum of squares
// precomputed in SetupPixel: sab = sum (r - mean_r) * v needs no mean of v.
double PatchMatcher::SlotNcc(int slot_index) const {
  double sbb = 0, sab = 0;
  mpgc_kernels::NccSums(ref_centered_, slots_[slot_index].val, mask_, npix_,
                        &sbb, &sab);
  return NccOfSums(sbb, sab);
}

double PatchMatcher::NccOfSums(double sbb, double sab) const {
  const double m = weight_sum_ * channels_;
  if (ref_saa_ < kNccMinVariance * m || sbb < kNccMinVariance * m) return -1;
  return sab / std::sqrt(ref_saa_ * sbb);
}

double PatchMatcher::SlotNccAndSums(int slot_index, bool depth_only) {
  SlotData& sl = slots_[slot_index];
  double sbb = 0, sab = 0;
  mpgc_kernels::NormalAndNccSums(KernelInput(slot_index, depth_only), sl.sums,
                                 &sbb, &sab);
  sl.sums_kind =
      depth_only ? SlotData::Sums::kDepthOnly : SlotData::Sums::kFull;
  return NccOfSums(sbb, sab);
}

mpgc_kernels::SumsInput PatchMatcher::KernelInput(int slot_index,
                                                  bool depth_only) const {
  const SlotData& sl = slots_[slot_index];
  mpgc_kernels::SumsInput in;
  in.ref = ref_;
  in.ref_c = ref_centered_;
  in.val = sl.val;
  in.dval = sl.dval;
  in.scale = sl.scale;
  in.mask = mask_;
  in.wi = wi_;
  in.wj = wj_;
  in.npix = npix_;
  // With the photometric offset (I_R = c I_V + b) the offset b per view
  // and channel is eliminated at its optimum: every term is taken about
  // its window mean.
  in.center = ctx_.ablation.photometric_offset;
  in.depth_only = depth_only;
  return in;
}

void PatchMatcher::InitScales(int slot_index) {
  SlotData& sl = slots_[slot_index];
  for (int c = 0; c < 3; ++c) sl.scale[c] = 1.0f;
  if (!ctx_.ablation.optimize_color_scale) return;
  // Weighted (weight_) sums per channel; the channels' sums are independent
  // chains, run side by side.
  double sums[3] = {0, 0, 0}, squares[3] = {0, 0, 0};
  for (int i = 0; i < npix_; ++i)
    for (int c = 0; c < channels_; ++c) {
      const double p = sl.val[4 * i + c];
      sums[c] += weight_[i] * p;
      squares[c] += weight_[i] * p * p;
    }
  for (int c = 0; c < channels_; ++c) {
    const double sv = sums[c], svv = squares[c];
    if (ctx_.ablation.photometric_offset) {
      // Contrast ratio of the mean-free windows.
      const double saa = ref_saa_c_[c];
      const double sbb = svv - sv * sv / weight_sum_;
      if (sbb > 1e-12 && saa > 1e-12)
        sl.scale[c] = static_cast<float>(std::sqrt(saa / sbb));
    } else if (sv > 1e-6 && ref_wmean_[c] > 1e-6) {
      sl.scale[c] = static_cast<float>(ref_wmean_[c] * weight_sum_ / sv);
    }
  }
}

int PatchMatcher::FreeSlot() const {
  bool used[kMaxActive + 1] = {};
  for (int a = 0; a < num_active_; ++a) used[active_slot_[a]] = true;
  for (int s = 0; s <= kMaxActive; ++s)
    if (!used[s]) return s;
  return -1;  // unreachable: at most kMaxActive are active
}

// Local view selection (FillActiveSet, local_view_selection.h): fills A up
// to m views. Entering views are sampled (values only) and get their NCC and
// initial colour scales. Returns the number of views that entered.
int PatchMatcher::FillActive() {
  const int nv = static_cast<int>(ctx_.views.size());
  int slot = -1;
  return FillActiveSet(
      local_, ctx_.ablation.local_view_selection, nv, global_scores_,
      epi_weights_, state_, active_, &num_active_,
      [&](int v, double* ncc) {
        slot = FreeSlot();
        PrepareView(v, slot);
        // With the gradient: a view that enters is not sampled again at
        // this patch (SlotData::fresh).
        if (!SampleSlot(slot, true)) return false;
        *ncc = SlotNcc(slot);
        return true;
      },
      [&](int v, double ncc, int a) {
        SlotData& sl = slots_[slot];
        sl.ncc = ncc;
        sl.prev_ncc = std::numeric_limits<double>::quiet_NaN();
        sl.fresh = true;
        InitScales(slot);
        Note(iteration_, MatchTrace::Kind::kEntered, v);
        active_slot_[a] = slot;
      },
      [&](int v) { Note(iteration_, MatchTrace::Kind::kRefused, v); });
}

void PatchMatcher::RemoveActive(int a) {
  state_[active_[a]] = 2;
  for (int k = a + 1; k < num_active_; ++k) {
    active_[k - 1] = active_[k];
    active_slot_[k - 1] = active_slot_[k];
  }
  --num_active_;
}

bool PatchMatcher::SetupPixel(int s, int t, double depth,
                              const Eigen::Vector3d& normal) {
  if (!WindowInside(s, t) || !(depth > 0) || !std::isfinite(depth))
    return false;
  s_ = s;
  t_ = t;
  const Camera& cam = ctx_.ref_camera;
  const MatchImage& ri = ctx_.ref_image;
  int idx = 0;
  for (int c = 0; c < 3; ++c) ref_sum_[c] = 0;
  double var_total = 0;
  ref_saa_ = 0;
  for (int j = -reach_; j <= reach_; j += step_) {
    const float* row =
        ri.data +
        (static_cast<size_t>(t + j) * ri.width + (s - reach_)) * channels_;
    const double y = (t + j + 0.5 - cam.cy) / cam.fy;
    for (int i = 0; i < n_; ++i, ++idx) {
      const int di = i * step_;  // pixels right of the window's left edge
      const double x = (s - reach_ + di + 0.5 - cam.cx) / cam.fx;
      inv_norm_[idx] = 1.0 / std::sqrt(x * x + y * y + 1.0);
      for (int c = 0; c < channels_; ++c) {
        ref_[4 * idx + c] = row[di * channels_ + c];
        ref_sum_[c] += row[di * channels_ + c];
      }
    }
  }
  double mean[3], var_c[3] = {0, 0, 0};  // per channel, side by side
  for (int c = 0; c < channels_; ++c) mean[c] = ref_sum_[c] / npix_;
  for (int i = 0; i < npix_; ++i)
    for (int c = 0; c < channels_; ++c) {
      const double d = ref_[4 * i + c] - mean[c];
      var_c[c] += d * d;
    }
  for (int c = 0; c < channels_; ++c) var_total += var_c[c];
  // A textureless reference window cannot be matched (NCC undefined).
  if (var_total < kNccMinVariance * npix_ * channels_ * 100) return false;
  if (ctx_.ablation.bilateral_window) SetBilateralWeights();
  double sum[3] = {0, 0, 0};
  for (int i = 0; i < npix_; ++i)
    for (int c = 0; c < channels_; ++c) sum[c] += weight_[i] * ref_[4 * i + c];
  for (int c = 0; c < channels_; ++c) {
    ref_wmean_[c] = sum[c] / weight_sum_;
    ref_saa_c_[c] = 0;
  }
  for (int i = 0; i < npix_; ++i)
    for (int c = 0; c < channels_; ++c) {
      const double d = ref_[4 * i + c] - ref_wmean_[c];
      const float df = static_cast<float>(d);
      const double wdf = weight_[i] * df;
      ref_centered_[4 * i + c] = static_cast<float>(wdf);
      ref_saa_c_[c] += wdf * df;
    }
  for (int c = 0; c < channels_; ++c) ref_saa_ += ref_saa_c_[c];
  Eigen::Vector3d n = normal;
  if (!ctx_.ablation.optimize_normal || !(n.norm() > 0.5))
    n = Eigen::Vector3d(0, 0, -1);
  h_ = PlaneToPatch(cam, s, t, depth, n.normalized(), &hs_, &ht_);
  if (!std::isfinite(h_) || h_ <= 0) return false;
  const double u = s + 0.5, v = t + 0.5;
  const int nv = static_cast<int>(ctx_.views.size());
  for (int k = 0; k < nv; ++k) {
    epi_dir_[k] = EpipolarDirection(ctx_.views[k].epipole, u, v);
    state_[k] =
        (!ctx_.ablation.local_view_selection && k >= local_.num_active) ? 2 : 0;
  }
  epi_weights_.Reset(epi_dir_, nv);
  num_active_ = 0;
  for (SlotData& sl : slots_) sl.fresh = false;
  return true;
}

// Bilateral weights of R's window (MpgcOptions::bilateral_*):
// closeness to the centre sample in space and in gamma-2 encoded colour.
void PatchMatcher::SetBilateralWeights() {
  const int centre = npix_ / 2;
  double enc_centre[3];
  for (int c = 0; c < channels_; ++c)
    enc_centre[c] = 255.0 * std::sqrt(std::max(0.0f, ref_[4 * centre + c]));
  double dc2[kMaxWindowPixels];
  for (int i = 0; i < npix_; ++i) {
    dc2[i] = 0;
    for (int c = 0; c < channels_; ++c) {
      const double e =
          255.0 * std::sqrt(std::max(0.0f, ref_[4 * i + c])) - enc_centre[c];
      dc2[i] += e * e;
    }
  }
  // The colour sigma widens (x2, at most kMaxWidenings times) while the
  // window keeps less than bilateral_min_weight of its plain weight.
  constexpr int kMaxWidenings = 3;  // sigma_color up to 8x
  const double min_sum = mpgc_.bilateral_min_weight * space_weight_sum_;
  double sigma = mpgc_.bilateral_sigma_color;
  for (int widen = 0;; ++widen, sigma *= 2) {
    const double inv2s2 = 1.0 / (2.0 * sigma * sigma * channels_);
    weight_sum_ = 0;
    for (int i = 0; i < npix_; ++i) {
      weight_[i] = space_weight_[i] * std::exp(-dc2[i] * inv2s2);
      weight_sum_ += weight_[i];
    }
    if (widen == kMaxWidenings || weight_sum_ >= min_sum) break;
  }
  for (int i = 0; i < npix_; ++i) {
    const float r = static_cast<float>(std::sqrt(weight_[i]));
    for (int c = 0; c < channels_; ++c) mask_[4 * i + c] = r;
  }
}

double PatchMatcher::PlaneScore(int s, int t, double depth,
                                const Eigen::Vector3d& normal, int k,
                                int max_views) {
  if (!SetupPixel(s, t, depth, normal)) return -1;
  double best[kMaxNeighbors];
  int count = 0;
  const int slot = kMaxActive;
  const int nv = static_cast<int>(ctx_.views.size());
  const int m = max_views > 0 ? std::min(max_views, nv) : nv;
  for (int i = 0; i < m; ++i) {
    const int v = max_views > 0 ? by_global_score_[i] : i;
    PrepareView(v, slot);
    if (!SampleSlot(slot, false)) continue;
    best[count++] = SlotNcc(slot);
  }
  if (count < k || k <= 0) return -1;
  std::partial_sort(best, best + k, best + count, std::greater<double>());
  double sum = 0;
  for (int i = 0; i < k; ++i) sum += best[i];
  return sum / k;
}

int PatchMatcher::SampleActive(int first) {
  int left = 0;
  for (int a = first; a < num_active_;) {
    SlotData& sl = slots_[active_slot_[a]];
    if (sl.fresh) {  // sampled at this patch when it entered
      sl.fresh = false;
      ++a;
      continue;
    }
    if (SampleSlot(active_slot_[a], true)) {
      ++a;
      continue;
    }
    Note(iteration_, MatchTrace::Kind::kLeftImage, active_[a]);
    RemoveActive(a);
    ++left;
  }
  return left;
}

int PatchMatcher::TestActive(int it, const Update& next, bool* stable) {
  const bool baseline = it == schedule_.settle_iterations;
  const bool oscillation_check = schedule_.oscillation_iteration > 0 &&
                                 it == schedule_.oscillation_iteration;
  int dropped = 0;
  *stable = !baseline;
  for (int a = 0; a < num_active_;) {
    SlotData& sl = slots_[active_slot_[a]];
    sl.prev_ncc = baseline ? std::numeric_limits<double>::quiet_NaN() : sl.ncc;
    sl.ncc = SlotNccAndSums(active_slot_[a], next.depth_only());
    const bool moved = !(std::abs(sl.ncc - sl.prev_ncc) <=
                         schedule_.convergence_eps);  // NaN (new view) = moved
    if (baseline) Note(it, MatchTrace::Kind::kBaseline, active_[a]);
    MatchTrace::Kind why = MatchTrace::Kind::kConverged;  // = kept
    if (sl.ncc < mpgc_.drop_ncc) {
      why = MatchTrace::Kind::kDropLowNcc;
    } else if (oscillation_check && moved) {
      why = MatchTrace::Kind::kDropOscillation;
    }
    if (why != MatchTrace::Kind::kConverged) {
      Note(it, why, active_[a]);
      RemoveActive(a);
      ++dropped;
      continue;
    }
    if (moved) *stable = false;
    ++a;
  }
  return dropped;
}

int PatchMatcher::RefillActive() {
  const int first_new = num_active_;
  FillActive();
  const int entered = num_active_ - first_new;
  return entered - SampleActive(first_new);
}

PatchMatcher::Update PatchMatcher::NextUpdate(int it, bool changed) const {
  const bool full = changed || (it + 1) % schedule_.full_update_interval == 0;
  return Update{full && ctx_.ablation.optimize_normal,
                full && ctx_.ablation.optimize_color_scale};
}

const mpgc_kernels::ChannelSums* PatchMatcher::UpdateSums(int slot_index,
                                                          bool depth_only) {
  SlotData& sl = slots_[slot_index];
  const SlotData::Sums kind =
      depth_only ? SlotData::Sums::kDepthOnly : SlotData::Sums::kFull;
  if (sl.sums_kind != kind)
    mpgc_kernels::NormalSums(KernelInput(slot_index, depth_only), sl.sums);
  sl.sums_kind = SlotData::Sums::kNone;  // the update moves patch and scales
  return sl.sums;
}

// Depth only, normal and colour scales fixed: one unknown dh,
// H = sum q^2, g = sum q e with q = c dI/dh and e = I_R - c I_V.
bool PatchMatcher::DepthStep() {
  double q2 = 0, qe = 0;
  for (int a = 0; a < num_active_; ++a) {
    const mpgc_kernels::ChannelSums* cs =
        UpdateSums(active_slot_[a], /*depth_only=*/true);
    for (int c = 0; c < channels_; ++c) {
      q2 += cs[c].h[0];
      qe += cs[c].g[0];
    }
  }
  if (!(q2 > 1e-20)) return false;
  const double dh = qe / q2;
  if (!std::isfinite(dh)) return false;
  h_ += dh;
  return h_ > 0 && std::isfinite(h_);
}

// The linearised least squares of equation 10: residual e = I_R - c * I_V,
// unknowns d = (dh, dhs, dht) and dc per (view, channel); the colour scales
// are eliminated by the Schur complement, leaving a 3x3 (or 1x1) system.
bool PatchMatcher::FullStep(bool fit_normal, bool fit_scale) {
  Eigen::Matrix3d H = Eigen::Matrix3d::Zero();
  Eigen::Vector3d g = Eigen::Vector3d::Zero();
  double sii[kMaxActive][3], sie[kMaxActive][3];
  Eigen::Vector3d sij[kMaxActive][3];
  for (int a = 0; a < num_active_; ++a) {
    const mpgc_kernels::ChannelSums* cs =
        UpdateSums(active_slot_[a], /*depth_only=*/false);
    for (int c = 0; c < channels_; ++c) {
      const double* h = cs[c].h;
      H(0, 0) += h[0];
      H(0, 1) += h[1];
      H(0, 2) += h[2];
      H(1, 1) += h[3];
      H(1, 2) += h[4];
      H(2, 2) += h[5];
      g += Eigen::Vector3d(cs[c].g[0], cs[c].g[1], cs[c].g[2]);
      sii[a][c] = cs[c].ii;
      sie[a][c] = cs[c].ie;
      sij[a][c] = Eigen::Vector3d(cs[c].ic[0], cs[c].ic[1], cs[c].ic[2]);
    }
  }
  H(1, 0) = H(0, 1);
  H(2, 0) = H(0, 2);
  H(2, 1) = H(1, 2);
  if (fit_scale) {
    for (int a = 0; a < num_active_; ++a)
      for (int c = 0; c < channels_; ++c) {
        if (!(sii[a][c] > 1e-12)) continue;
        H -= sij[a][c] * sij[a][c].transpose() / sii[a][c];
        g -= sij[a][c] * (sie[a][c] / sii[a][c]);
      }
  }
  Eigen::Vector3d d = Eigen::Vector3d::Zero();
  if (fit_normal) {
    Eigen::Matrix3d Hd = H;
    const double damp = 1e-9 * (H.trace() + 1e-30);
    Hd.diagonal().array() += damp;
    Eigen::LDLT<Eigen::Matrix3d> ldlt(Hd);
    if (ldlt.info() != Eigen::Success) return false;
    d = ldlt.solve(g);
  } else {
    if (!(H(0, 0) > 1e-20)) return false;
    d.x() = g.x() / H(0, 0);
  }
  if (!d.allFinite()) return false;
  if (fit_scale) {
    for (int a = 0; a < num_active_; ++a) {
      SlotData& sl = slots_[active_slot_[a]];
      for (int c = 0; c < channels_; ++c) {
        if (!(sii[a][c] > 1e-12)) continue;
        const double dc = (sie[a][c] - sij[a][c].dot(d)) / sii[a][c];
        const double nc = sl.scale[c] + dc;
        if (nc > 1e-3 && nc < 1e3) sl.scale[c] = static_cast<float>(nc);
      }
    }
  }
  h_ += d.x();
  if (!(h_ > 0) || !std::isfinite(h_)) return false;
  if (fit_normal) {
    hs_ += d.y();
    ht_ += d.z();
  }
  return true;
}

bool PatchMatcher::MakeResult(int iterations, PatchResult* out) const {
  const Camera& cam = ctx_.ref_camera;
  const Eigen::Vector3d ray = RayAt(cam, s_ + 0.5, t_ + 0.5);
  const Eigen::Vector3d n = PatchNormal(cam, s_, t_, h_, hs_, ht_);
  if (!(n.dot(-ray) > kMinFacing)) return false;
  double sum = 0;
  for (int a = 0; a < num_active_; ++a) sum += slots_[active_slot_[a]].ncc;
  const double mean_ncc = sum / num_active_;
  double pair_ncc = std::numeric_limits<double>::quiet_NaN();
  bool explained = true;
  if (ctx_.ablation.explain_test && num_active_ >= 2 &&
      mean_ncc < mpgc_.explain_below_ncc) {
    // Not even the best view explains R's window as well as the views
    // explain each other's. Every NCC is corrected for what the two
    // windows' noise takes from it (image_noise.h): R's window, sampled at
    // pixel centres, and a dark or overcast view's windows are noisier than
    // the others, which lowers their NCCs whatever they see.
    double w2 = 0;
    for (int i = 0; i < npix_; ++i) w2 += weight_[i] * weight_[i];
    double ref_mean = 0;
    for (int c = 0; c < channels_; ++c) ref_mean += ref_wmean_[c];
    const double ref_sigma = ctx_.ref_noise.Sigma(ref_mean / channels_);
    const double r_ref = WindowReliability(ref_saa_, ref_sigma * ref_sigma,
                                           channels_, weight_sum_, w2);
    double reliability[kMaxActive];
    pair_ncc = MeanPairwiseNcc(w2, reliability);
    double best = -1;
    for (int a = 0; a < num_active_; ++a)
      best =
          std::max(best, std::min(1.0, slots_[active_slot_[a]].ncc /
                                           std::sqrt(r_ref * reliability[a])));
    explained = best >= pair_ncc - mpgc_.explain_margin;
  }
  if (!out) return true;
  out->pair_ncc = pair_ncc;
  out->explained = explained;
  out->depth = h_ * ray.z();
  out->normal = ctx_.ablation.optimize_normal ? n : Eigen::Vector3d(0, 0, -1);
  out->confidence = std::clamp((mean_ncc + 1.0) * 0.5, 0.0, 1.0);
  out->iterations = iterations;
  out->num_active = num_active_;
  for (int a = 0; a < num_active_; ++a) {
    const SlotData& sl = slots_[active_slot_[a]];
    out->active[a] = active_[a];
    out->ncc[a] = sl.ncc;
    for (int c = 0; c < 3; ++c)
      out->color_scale[a][c] = sl.scale[channels_ == 1 ? 0 : c];
  }
  return true;
}

double PatchMatcher::MeanPairwiseNcc(double w2, double* reliability) const {
  if (num_active_ < 2) return 1;
  // Mean-free copies of the active windows (per channel).
  float c[kMaxActive][mpgc_kernels::kWindowFloats];
  double ss[kMaxActive];
  for (int a = 0; a < num_active_; ++a) {
    const SlotData& sl = slots_[active_slot_[a]];
    const float* v = sl.val;
    ss[a] = 0;
    double brightness = 0;
    double mean[3] = {0, 0, 0};  // per channel, side by side
    for (int i = 0; i < npix_; ++i)
      for (int ch = 0; ch < channels_; ++ch)
        mean[ch] += weight_[i] * v[4 * i + ch];
    for (int ch = 0; ch < channels_; ++ch) {
      const double m = mean[ch] / weight_sum_;
      brightness += m;
      for (int i = 0; i < npix_; ++i) {
        const float d = static_cast<float>(v[4 * i + ch] - m);
        c[a][4 * i + ch] = d;
        ss[a] += weight_[i] * d * d;
      }
    }
    // The neighbours' windows are bilinear samples.
    const double sigma =
        ctx_.views[sl.view].noise.Sigma(brightness / channels_);
    reliability[a] =
        WindowReliability(ss[a], kBilinearNoiseFactor * sigma * sigma,
                          channels_, weight_sum_, w2);
  }
  const double floor = kNccMinVariance * weight_sum_ * channels_;
  double sum = 0;
  int pairs = 0;
  for (int a = 0; a < num_active_; ++a)
    for (int b = a + 1; b < num_active_; ++b) {
      double sab = 0;
      for (int ch = 0; ch < channels_; ++ch)
        for (int i = 0; i < npix_; ++i)
          sab += weight_[i] * c[a][4 * i + ch] * c[b][4 * i + ch];
      sum +=
          (ss[a] < floor || ss[b] < floor)
              ? -1
              : std::min(1.0, sab / std::sqrt(ss[a] * ss[b] * reliability[a] *
                                              reliability[b]));
      ++pairs;
    }
  return sum / pairs;
}

// The paper's schedule (section 6.2). Iteration k = the k-th update; the
// tests after iteration k run at the top of loop pass `it` = k, on the
// patch that update produced:
//  - it < settle: no test (the system settles);
//  - it = settle: every active view's NCC is recorded, views below kappa
//    leave;
//  - it > settle: views below kappa leave; converged when none left or was
//    dropped and every NCC changed by at most eps since iteration it - 1;
//  - it = oscillation_iteration (once): views whose NCC still moves leave;
//  - whenever A shrank, local view selection refills it;
//  - fail with fewer than min_active_views views or when iteration
//    max_iterations has not converged.
// The update of pass `it` (iteration it + 1) fits the normal and colour
// scales when it + 1 is a multiple of full_update_interval or A changed
// since the last full update, else the depth alone.
bool PatchMatcher::Match(int s, int t, double depth,
                         const Eigen::Vector3d& normal, PatchResult* out,
                         MatchTrace* trace) {
  trace_ = trace;
  iteration_ = 0;
  struct Done {  // clears the trace pointer on every return
    MatchTrace*& t;
    ~Done() { t = nullptr; }
  } done{trace_};
  if (!SetupPixel(s, t, depth, normal)) return false;
  FillActive();
  bool changed = true;  // a new active set: the first update is full
  for (int it = 0;; ++it) {
    iteration_ = it;
    const int left = SampleActive(0);
    int dropped = 0;
    bool stable = false;
    if (it >= schedule_.settle_iterations)
      dropped = TestActive(it, NextUpdate(it, changed || left > 0), &stable);
    if (left + dropped == 0 && stable && !changed &&
        num_active_ >= mpgc_.min_active_views) {
      Note(it, MatchTrace::Kind::kConverged, -1);
      return MakeResult(it, out);
    }
    if (left + dropped > 0) {
      changed = true;
      RefillActive();
    }
    if (num_active_ < mpgc_.min_active_views ||
        it == schedule_.max_iterations) {
      Note(it, MatchTrace::Kind::kFailed, -1);
      return false;
    }
    const Update update = NextUpdate(it, changed);
    Note(it,
         update.depth_only() ? MatchTrace::Kind::kDepthUpdate
                             : MatchTrace::Kind::kFullUpdate,
         -1);
    const bool ok = update.depth_only()
                        ? DepthStep()
                        : FullStep(update.fit_normal, update.fit_scale);
    if (!ok) {
      Note(it, MatchTrace::Kind::kFailed, -1);
      return false;
    }
    changed = false;
  }
}

int MatchTrace::Count(Kind k) const {
  int n = 0;
  for (const Event& e : events) n += e.kind == k;
  return n;
}

bool MatchTrace::Has(int iteration, Kind k) const {
  for (const Event& e : events)
    if (e.iteration == iteration && e.kind == k) return true;
  return false;
}

void RegisterOptions(OptionRegistry* registry, const std::string& prefix,
                     MpgcOptions* o) {
  auto key = [&prefix](const char* name) {
    return OptionRegistry::Join(prefix, name);
  };
  registry
      ->Add(key("window"), &o->window,
            "matching window side n of n x n (paper: 5)")
      .Min(3)
      .Max(kMaxWindow)
      .Odd();
  registry
      ->Add(key("drop_ncc"), &o->drop_ncc,
            "drop active views whose NCC falls below (paper: 0.4)")
      .Min(-1)
      .Max(1);
  registry
      ->Add(key("wide_drop_ncc"), &o->wide_drop_ncc,
            "drop_ncc where the window is wide (window step >= 2)")
      .Min(-1)
      .Max(1);
  registry
      ->Add(key("min_active_views"), &o->min_active_views,
            "fail when fewer active views remain")
      .Min(1)
      .Max(kMaxActive)
      .Note("<= local.num_active");
  registry
      ->Add(key("explain_margin"), &o->explain_margin,
            "explain test (ablation.explain_test): region growing does not "
            "expand from a match whose best view's NCC with R is more than "
            "this below the views' mean NCC with each other (R sees "
            "something they do not: a one-view occluder)")
      .Min(0)
      .Max(2);
  registry
      ->Add(key("explain_below_ncc"), &o->explain_below_ncc,
            "the explain test checks only matches whose mean NCC with R is "
            "below this")
      .Min(-1)
      .Max(1);
  registry
      ->Add(key("bilateral_sigma_color"), &o->bilateral_sigma_color,
            "bilateral window (ablation.bilateral_window): weight window "
            "samples by their colour difference from the centre (sigma in "
            "8-bit gamma-2 levels) and distance")
      .Above(0);
  registry
      ->Add(key("bilateral_sigma_space"), &o->bilateral_sigma_space,
            "spatial sigma of the bilateral weights, in window samples")
      .Above(0);
  registry
      ->Add(key("bilateral_min_weight"), &o->bilateral_min_weight,
            "least fraction of the plain window weight the colour weights "
            "keep (sigma_color doubles, up to 8x, until they do)")
      .Above(0)
      .Max(1);
}

}  // namespace wild_mvs
