// Copyright wild_mvs authors. MPGC stereo matching of one pixel (paper
// section 6.2 / docs/ALGORITHM.md section 4): depth along the ray plus the two
// per-pixel depth offsets (the normal) and one colour scale per active view
// and channel, by linearised least squares; NCC for confidence and
// convergence; the paper's schedule. Local view selection (section 3) runs
// inside, since views are dropped and refilled during the iteration.
#pragma once

#include <Eigen/Core>
#include <cmath>
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

// The paper's schedule (section 6.2), fixed: tests substitute other values
// to observe its rules one by one.
struct MpgcSchedule {
  int settle_iterations = 5;       // iterations before any test
  double convergence_eps = 1e-3;   // converged when every NCC moves less
  int max_iterations = 20;         // fail after
  int full_update_interval = 5;    // normal + colour scales every k-th
                                   // iteration (or after A changed)
  int oscillation_iteration = 14;  // once: drop views whose NCC still moves
                                   // (0 = never)
};
// normal . (-ray) must exceed this (paper: 0.1).
constexpr double kMinFacing = 0.1;

struct MpgcOptions {
  int window = 5;  // n of the n x n window, odd, [3, kMaxWindow] (paper: 5)
  // Pixels between the window's samples, [0, 4] (paper: 1); 0 = by R's
  // working size (AutoWindowStep). Not registered: the working size decides
  // (docs/METHODS.md, "Tried and rejected"); tests and --preset paper set it.
  int window_step = 0;
  double drop_ncc = 0.4;  // kappa: drop active views below, [-1, 1]
  // kappa where the window is wide (step >= 2), [-1, 1].
  double wide_drop_ncc = 0.22;
  int min_active_views = 3;  // fail with fewer active views, [1, kMaxActive]
  // The explain test (AblationOptions::explain_test): a converged match is
  // unexplained when the best NCC of an active view with R is more than
  // this below the active views' mean NCC with each other, both corrected
  // for the windows' noise (image_noise.h), [0, 2]. An unexplained match
  // keeps its depth but is not expanded from (PatchResult::explained).
  double explain_margin = 0;
  // Only matches whose mean NCC with R is below this are tested, [-1, 1].
  double explain_below_ncc = 0.8;
  // Bilateral window weights (AblationOptions::bilateral_window):
  // exp(-d^2 / 2 sigma_space^2), d in window samples, times
  // exp(-dc^2 / 2 sigma_color^2), dc the RMS colour difference from the
  // centre in 8-bit gamma-2 levels; sigma_color > 0, sigma_space > 0.
  double bilateral_sigma_color = 12;
  double bilateral_sigma_space = 6;
  // Least fraction, (0, 1], of the space-only weight the colour weights
  // keep (sigma_color doubles, up to 8x, until they do).
  double bilateral_min_weight = 0.5;
  void Check() const;
};
// Registers the fields under `prefix` (option_registry.h), e.g. "mvs.mpgc".
void RegisterOptions(OptionRegistry* registry, const std::string& prefix,
                     MpgcOptions* options);

// The thresholds for a reference image of width x height: where its window
// is wide (AutoWindowStep >= 2) drop_ncc and local.min_ncc become
// wide_drop_ncc and local.wide_min_ncc.
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
    kFailed
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
  // Mean NCC of A's views with each other, corrected for noise (computed
  // when the explain test ran, else NaN).
  double pair_ncc = std::numeric_limits<double>::quiet_NaN();
  // False when the explain test failed: the match keeps its depth, growth
  // does not expand from it.
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
               const LocalViewSelectionOptions& local,
               const MpgcSchedule& schedule = MpgcSchedule());

  // Local view selection + MPGC at pixel (s, t) (integer column and row;
  // centre (s + .5, t + .5)) from depth z and camera-frame normal `normal`.
  // True on success (converged, facing, enough views, explained);
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
  // What one update fits (the paper's schedule, Match).
  struct Update {
    bool fit_normal = false, fit_scale = false;
    bool depth_only() const { return !fit_normal && !fit_scale; }
  };
  bool SetupPixel(int s, int t, double depth, const Eigen::Vector3d& normal);
  bool PrepareView(int v, int slot_index);
  bool SampleSlot(int slot_index, bool with_gradient);
  double SlotNcc(int slot_index) const;
  // SlotNcc, with the sums of the next update (depth only or full) taken
  // from the same samples into the slot (SlotData::sums).
  double SlotNccAndSums(int slot_index, bool depth_only);
  // The NCC of R's window with a view's from the kernels' sums (-1 when
  // either window is flat).
  double NccOfSums(double sbb, double sab) const;
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
  // NCC changed by at most eps since the previous iteration. The sums of
  // the update that comes next (`next`, as far as known before the test)
  // are taken in the same pass over each window (SlotData::sums).
  int TestActive(int it, const Update& next, bool* stable);
  // Refills A by local view selection after views left; returns the number
  // that entered (sampled, with derivatives).
  int RefillActive();
  // Which unknowns the update after `it` updates fits: the normal and
  // colour scales when `changed` (A changed since the last full update) or
  // every full_update_interval-th iteration, else the depth alone.
  Update NextUpdate(int it, bool changed) const;
  // The least-squares sums (NormalSums) of a slot's samples at its colour
  // scales for an update of this kind: those TestActive took with the NCC
  // when they are of the kind, else computed. Either way used up.
  const mpgc_kernels::ChannelSums* UpdateSums(int slot_index, bool depth_only);
  // The kernels' input for a slot's least squares (and NCC).
  mpgc_kernels::SumsInput KernelInput(int slot_index, bool depth_only) const;
  bool DepthStep();
  bool FullStep(bool fit_normal, bool fit_scale);
  bool MakeResult(int iterations, PatchResult* out) const;
  // Mean NCC of the active views' windows with each other (pairs of A; the
  // channels pooled as in SlotNcc), each corrected for the two windows'
  // noise (image_noise.h) and capped at 1; 1 with fewer than two views.
  // w2: the sum of the squared window weights. reliability[a]: A[a]'s
  // window's reliability.
  double MeanPairwiseNcc(double w2, double* reliability) const;
  void SetBilateralWeights();
  void Note(int iteration, MatchTrace::Kind kind, int view) {
    if (trace_) trace_->events.push_back({iteration, kind, view});
  }

  const PatchContext& ctx_;
  MpgcOptions mpgc_;
  LocalViewSelectionOptions local_;
  MpgcSchedule schedule_;
  int n_ = 5, half_ = 2, npix_ = 25, channels_ = 3;
  int step_ = 1, reach_ = 2;  // sample spacing; half_ * step_ (pixels)
  EpipolarWeights epi_weights_{kMaxEpipolarAngleDeg * M_PI / 180.0};
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
    // NormalSums of val and dval at scale, taken by TestActive for the next
    // update (depth only or full); none once used or resampled.
    enum class Sums { kNone, kDepthOnly, kFull } sums_kind = Sums::kNone;
    mpgc_kernels::ChannelSums sums[4];
  };
  SlotData slots_[kMaxActive + 1];
};

}  // namespace wild_mvs
