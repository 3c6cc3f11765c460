// Copyright wild_mvs authors. MPGC stereo matching of one pixel (paper
// section 6.2 / docs/ALGORITHM.md section 4): depth along the ray plus the two
// per-pixel depth offsets (the normal) and one colour scale per active view
// and channel, by linearised least squares; NCC for confidence and
// convergence; the paper's schedule. Local view selection (section 3) runs
// inside, since views are dropped and refilled during the iteration.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <limits>
#include <vector>

#include "wild_mvs/core/local_view_selection.h"
#include "wild_mvs/core/mpgc_kernels.h"
#include "wild_mvs/core/option_registry.h"
#include "wild_mvs/core/patch.h"

namespace wild_mvs {

// Working images whose longer side reaches this use window_step 2 when
// MpgcOptions::window_step is 0 (auto).
constexpr int kWideWindowFromPx = 1200;

// The window step used for a reference image of width x height: `step` when
// it is > 0, else 1 or 2 by the longer side (kWideWindowFromPx).
int AutoWindowStep(int step, int width, int height);

struct MpgcOptions {
  int window = 5;  // n of the n x n window (paper: 5)
  // (beyond the paper, as OpenMVS samples its windows) Pixels between the
  // window's samples: the n x n samples cover (n - 1) * step + 1 pixels of
  // R, a wider footprint at the cost of n x n (paper: 1). 0 = by R's working
  // size (AutoWindowStep): 1 below kWideWindowFromPx on the longer side, 2
  // from there (measured, docs/EVALUATION.md: fountain-P11 at 1536 px
  // covers 3 points more with step 2; 640 px scenes lose 0.02 with it).
  int window_step = 0;
  int settle_iterations = 5;  // iterations before any test (paper: 5)
  double drop_ncc = 0.4;      // kappa: drop views below (paper: 0.4)
  // (beyond the paper) kappa where the window is wide (window step >= 2:
  // AutoWindowStep's choice from kWideWindowFromPx, or an explicit step);
  // < -1 = drop_ncc. With the bilateral window a lower kappa spends its
  // accuracy on coverage there (measured, docs/EVALUATION.md, "Bilateral
  // window": fountain-P11 at 1536 px, colour sigma 10, kappa 0.4 / 0.3 /
  // 0.25 / 0.2: 88.3 / 89.6 / 89.8 / 90.0 % coverage at 97.7 to 97.3 %
  // within 1 %; 0.22 with the defaults: 90.1 % at 97.2 %), while at 640 px
  // it costs speed and gross errors (templeSparseRing -17 % correct per
  // CPU-s, the rendered clutter scene 1.05 % off by more than 5 %).
  double wide_drop_ncc = 0.22;
  double convergence_eps = 1e-3;   // eps on every NCC change (paper: 0.001)
  int max_iterations = 20;         // fail after (paper: 20)
  int full_update_interval = 5;    // normal + colour scales at every k-th
                                   // iteration (k, 2k, ... counted from 1)
                                   // or after a change of A (paper: 5)
  int oscillation_iteration = 14;  // once, after this iteration, drop views
                                   // whose NCC changed by more than eps
                                   // (paper: 14); 0 = never
  double min_facing = 0.1;         // normal . (-ray) must exceed (paper: 0.1)
  // (choice: the paper says "the required number of views"; MVE: 4 = m)
  // Fail when fewer active views remain.
  int min_active_views = 3;
  // (beyond the paper; MVE's dmrecon: 0.6) Accept a converged match only
  // when the mean NCC over A reaches this; -1 = accept any (paper).
  double accept_ncc = -1;
  // (beyond the paper) The reference must be explained: a converged match
  // is unexplained when the best NCC of an active view with R falls more
  // than this below the active views' mean NCC with each other. There the
  // views agree about a surface that R's window does not show (R alone sees
  // a transient occluder in front of it, the neighbours the background
  // behind it; docs/EVALUATION.md, "One-view occluders"). -1 = off (paper).
  double explain_margin = 0;
  // Only matches whose mean NCC with R is below this are tested (a window
  // that R's views explain this well is not the wrong surface); > 1 = all.
  double explain_below_ncc = 0.8;
  // What an unexplained match does: false = it fails (no depth); true = it
  // keeps its depth but is marked unexplained (PatchResult::explained), and
  // region growing does not expand from it, so the background cannot
  // percolate through a one-view occluder while a weak but right match
  // still counts. Measured (docs/EVALUATION.md): clutter's gross errors
  // 1.94 -> 0.95 % at the same completeness; fountain-P11 -0.6 points of
  // coverage (failing the match instead: -1.2 to -2.5).
  bool explain_keeps_match = true;
  // (beyond the paper) A reference window whose intensity spread is below
  // this many 8-bit sRGB levels (standard deviation, mean over channels) is
  // not matched: sky, saturated or blank walls, where NCC is noise. 0 =
  // only the numerical floor (paper).
  double min_texture_levels = 0;
  // (beyond the paper, as COLMAP's patch-match stereo weights its NCC)
  // Bilateral window: each window sample is weighted by its closeness to
  // the centre in R, exp(-d^2 / 2 sigma_space^2) with d in window samples,
  // and in colour, exp(-dc^2 / 2 sigma_color^2) with dc the RMS over
  // channels of the difference from the centre pixel in 8-bit levels of a
  // gamma-2 encoding (255 sqrt(I) of the linear intensity I), so that
  // pixels of another surface across a depth edge count less. Every NCC,
  // mean and least-squares sum of MPGC is then weighted; the texture test
  // above stays unweighted. 0 = off: every sample weighs 1 (paper).
  // Measured (docs/EVALUATION.md, "Bilateral window"): fountain-P11 within
  // 1 % 96.97 -> 97.74 % at sigma 10; the rendered scenes' gross errors
  // more than halved.
  double bilateral_sigma_color = 12;
  double bilateral_sigma_space = 6;  // in window samples (flat-ish at 5x5)
  // (beyond COLMAP) The least fraction of the plain (space-only) window
  // weight the colour weights keep: where colour varies across the whole
  // window (fine texture, shading, low resolution) rather than across an
  // edge, sigma_color doubles, up to 8x, until the window keeps this much.
  // An edge window keeps its own side's weight and is unchanged. 0 = a
  // fixed sigma_color. Measured (docs/EVALUATION.md, "Bilateral window at
  // low resolution"): the temple at 320 px 305 K -> 316 K samples, the ROS
  // demo's cloud 12.1 K -> 16.0 K points; fountain-P11 and the rendered
  // scenes within 0.1 points of the fixed sigma.
  double bilateral_min_weight = 0.5;
  // (beyond the paper) Step control: a full update that would turn the
  // patch away from the camera (facing <= min_facing) has its normal part
  // halved up to this many times, then dropped (depth only). 0 = off.
  int normal_step_halvings = 0;
  // (beyond the paper) Photometric model I_R = c I_V + b: a free offset b
  // per view and channel besides the colour scale c (eliminated at its
  // optimum: every window taken about its mean). Absorbs the local effect
  // of gamma and tone-curve changes that a scale alone cannot (measured,
  // docs/EVALUATION.md: under changing light completeness +0.005, median
  // error halved; neutral with constant light). false = the paper's
  // I_R = c I_V.
  bool photometric_offset = true;
  // (beyond the paper) Early failure: after this many updates, while the
  // system settles, a pixel fails at once when fewer than min_active_views
  // of its active views and its views not tried yet score at least
  // drop_ncc - forecast_margin at the current patch: at settling the views
  // below kappa leave and it would fail there (the NCCs barely move before
  // settling; on templeSparseRing such pixels were 5 % of the MPGC runs and
  // 3 % of the updates). -1 = off (paper).
  int forecast_iteration = -1;
  double forecast_margin = 0.1;      // NCC units below kappa still counted
  bool optimize_normal = true;       // false = fronto-parallel (ablation)
  bool optimize_color_scale = true;  // false = scales fixed to 1 (lab data)
  void Check() const;
};
// Registers the fields under `prefix` (option_registry.h), e.g. "mvs.mpgc".
void RegisterOptions(OptionRegistry* registry, const std::string& prefix,
                     MpgcOptions* options);

// The thresholds for a reference image of width x height: where its window
// is wide (AutoWindowStep >= 2) drop_ncc and local.min_ncc become
// wide_drop_ncc and local.wide_min_ncc (unless those are < -1).
void UseWideThresholds(int width, int height, MpgcOptions* mpgc,
                       LocalViewSelectionOptions* local);

// What happened in one Match call, iteration by iteration (tests and
// debugging; Match records it only when given one). `iteration` counts the
// updates done so far: events of iteration k happen after the k-th update.
struct MatchTrace {
  enum class Kind {
    kEntered,          // view entered A (local view selection)
    kRefused,          // view tried by local view selection, not admitted
    kLeftImage,        // view's window left its image (or behind camera)
    kBaseline,         // NCC recorded after settling (no test yet)
    kDropLowNcc,       // NCC < kappa
    kDropOscillation,  // NCC changed by more than eps at the oscillation check
    kFullUpdate,       // depth, normal and colour scales updated
    kDepthUpdate,      // depth only
    kConverged,
    kFailed,
    kForecastFailed  // failed early: too few views can pass kappa at settling
  };
  struct Event {
    int iteration;
    Kind kind;
    int view;  // index into PatchContext::views, -1 = none
  };
  std::vector<Event> events;
  int Count(Kind k) const;
  bool Has(int iteration, Kind k) const;
};

struct PatchResult {
  double depth = 0;                  // z of the pixel centre
  Eigen::Vector3d normal{0, 0, -1};  // camera frame, facing the camera
  double confidence = 0;             // mean NCC over A mapped to [0, 1]
  // Mean NCC of A's views with each other (computed when explain_margin is
  // on, else NaN).
  double pair_ncc = std::numeric_limits<double>::quiet_NaN();
  // False when the explain test failed and explain_keeps_match kept the
  // match: growth does not expand from it.
  bool explained = true;
  int iterations = 0;
  int num_active = 0;
  int active[kMaxActive] = {};  // indices into PatchContext::views
  double ncc[kMaxActive] = {};
  float color_scale[kMaxActive][3] = {};  // I_R = c * I_V per channel
};

// Matches pixels of one reference view. Not thread-safe (it owns its
// scratch space): use one per thread. Allocation-free per call.
class PatchMatcher {
 public:
  PatchMatcher(const PatchContext& context, const MpgcOptions& mpgc,
               const LocalViewSelectionOptions& local);

  // Local view selection + MPGC at pixel (s, t) (integer column and row;
  // centre (s + .5, t + .5)) from depth z and camera-frame normal `normal`.
  // True on success (converged, facing, enough views, accept_ncc reached);
  // fills *out. trace (may be null) records the schedule.
  bool Match(int s, int t, double depth, const Eigen::Vector3d& normal,
             PatchResult* out, MatchTrace* trace = nullptr);
  // Mean of the best `k` NCC scores over N of the window at pixel (s, t) on
  // the plane (depth, normal), without optimisation (for the depth sweep).
  // max_views > 0: only over the max_views views of the highest global
  // score (ties: lower index first). Returns -1 when fewer than k views see
  // the window.
  double PlaneScore(int s, int t, double depth, const Eigen::Vector3d& normal,
                    int k, int max_views = 0);

  // Whether the window around (s, t) lies inside R's image.
  bool WindowInside(int s, int t) const;

 private:
  bool SetupPixel(int s, int t, double depth, const Eigen::Vector3d& normal);
  bool PrepareView(int v, int slot_index);
  bool SampleSlot(int slot_index, bool with_gradient);
  double SlotNcc(int slot_index) const;
  void InitScales(int slot_index);
  int FreeSlot() const;
  int FillActive();
  void RemoveActive(int a);
  // The steps of one MPGC iteration (docs/ALGORITHM.md section 4).
  // Samples A[first..] (values + derivatives) at the current patch; views
  // whose window left their image leave A. Returns how many left.
  int SampleActive(int first);
  // NCC of every active view after `it` updates: the baseline right after
  // settling, later the kappa test, the one oscillation check and the
  // convergence test. Returns how many views were dropped; *stable = every
  // NCC changed by at most eps since the previous iteration.
  int TestActive(int it, bool* stable);
  // Refills A by local view selection after views left; returns the number
  // that entered (sampled, with derivatives).
  int RefillActive();
  // The forecast_iteration test: true when fewer than min_active_views of
  // the active views and the views not tried yet (sampled in a free slot at
  // the current patch) score >= drop_ncc - forecast_margin.
  bool SettlingHopeless();
  bool DepthStep();
  bool FullStep(bool fit_normal, bool fit_scale);
  bool MakeResult(int iterations, PatchResult* out) const;
  // Mean NCC of the active views' windows with each other (pairs of A; the
  // channels pooled as in SlotNcc). 1 with fewer than two views.
  double MeanPairwiseNcc() const;
  void SetBilateralWeights();
  void Note(int iteration, MatchTrace::Kind kind, int view) {
    if (trace_) trace_->events.push_back({iteration, kind, view});
  }

  const PatchContext& ctx_;
  MpgcOptions mpgc_;
  LocalViewSelectionOptions local_;
  int n_ = 5, half_ = 2, npix_ = 25, channels_ = 3;
  int step_ = 1, reach_ = 2;  // sample spacing; half_ * step_ (pixels)
  double max_angle_rad_ = 0;
  // Current pixel and window surface (h along the ray, per-pixel offsets).
  int s_ = 0, t_ = 0;
  double h_ = 0, hs_ = 0, ht_ = 0;
  double inv_norm_[kMaxWindowPixels];  // 1 / |K^-1 (u, v, 1)|
  // Window buffers in the kernels' layout (mpgc_kernels.h): pixel k,
  // channel c at 4 k + c; unused lanes zero.
  alignas(64) float ref_[mpgc_kernels::kWindowFloats];
  double ref_sum_[3];
  // R's deviations from its weighted mean, times the weight.
  alignas(64) float ref_centered_[mpgc_kernels::kWindowFloats];
  // Square roots of the weights per lane (mpgc_kernels.h): 1 (or the
  // bilateral weight's root) on pixels and channels, 0 elsewhere.
  alignas(64) float mask_[mpgc_kernels::kWindowFloats];
  alignas(64) float wi_[mpgc_kernels::kWindowFloats];   // column offset i
  alignas(64) float wj_[mpgc_kernels::kWindowFloats];   // row offset j
  alignas(64) double oi_[mpgc_kernels::kWindowPixels];  // i per pixel
  alignas(64) double oj_[mpgc_kernels::kWindowPixels];  // j per pixel
  double ref_saa_ = 0;   // sum of squares of the above
  double ref_saa_c_[3];  // the same per channel (InitScales)
  // The window's sample weights (bilateral_sigma_color; 1 when off), their
  // sum, R's weighted mean per channel, and the spatial factor per sample.
  double weight_[kMaxWindowPixels];
  double weight_sum_ = 0;
  double ref_wmean_[3];
  double space_weight_[kMaxWindowPixels];
  double space_weight_sum_ = 0;  // of space_weight_, fixed per matcher
  // Candidate state this visit: 0 free, 1 active, 2 rejected.
  uint8_t state_[kMaxNeighbors];
  Eigen::Vector2d epi_dir_[kMaxNeighbors];
  double global_scores_[kMaxNeighbors];
  int by_global_score_[kMaxNeighbors];  // view indices, best global first
  int active_[kMaxActive];              // view indices of A
  int active_slot_[kMaxActive];         // their scratch slots
  int num_active_ = 0;
  MatchTrace* trace_ = nullptr;  // this call's, or null
  int iteration_ = 0;            // updates done in this call
  struct SlotData {
    int view = -1;
    mpgc_kernels::WindowRays rays;  // A_V (u, v, 1) / |K^-1 (u, v, 1)|
    alignas(64) float val[mpgc_kernels::kWindowFloats];   // samples
    alignas(64) float dval[mpgc_kernels::kWindowFloats];  // d sample / d h
    float scale[3];
    double ncc, prev_ncc;
    // val and dval hold the samples at the current patch (taken when the
    // view entered A): the next SampleActive skips the slot once.
    bool fresh = false;
  };
  SlotData slots_[kMaxActive + 1];
};

}  // namespace wild_mvs
