// Copyright wild_mvs authors. Local (per-pixel) view selection (paper section
// 5.2 / docs/ALGORITHM.md section 3): the active set A of up to m views used to
// match one pixel, favouring spread epipolar directions.
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstdint>

#include "wild_mvs/core/option_registry.h"

namespace wild_mvs {

// g_max, the epipolar-angle spread in degrees (paper: 10).
constexpr double kMaxEpipolarAngleDeg = 10;

struct LocalViewSelectionOptions {
  int num_active = 4;    // m = |A|, [1, 8] (paper: 4)
  double min_ncc = 0.3;  // NCC to enter A, [-1, 1] (paper: 0.3)
  // min_ncc where the window is wide (MpgcOptions::wide_drop_ncc), [-1, 1].
  double wide_min_ncc = 0.12;
  void Check() const;
};
// Registers the fields under `prefix` (option_registry.h), e.g. "mvs.local".
void RegisterOptions(OptionRegistry* registry, const std::string& prefix,
                     LocalViewSelectionOptions* options);

// Direction (unit 2-vector) of the epipolar line in R through pixel (x, y)
// induced by the view whose centre projects to the homogeneous epipole e
// (K_R (R_R C_V + t_R); e.z() may be 0 or negative).
Eigen::Vector2d EpipolarDirection(const Eigen::Vector3d& epipole, double x,
                                  double y);

// w_e = min(g / g_max, 1) with g the acute angle between two directions.
double EpipolarWeight(const Eigen::Vector2d& d1, const Eigen::Vector2d& d2,
                      double max_angle_rad);

// The epipolar weights w_e between the candidate views at one pixel. A
// pixel's active set is filled, thinned and refilled many times while it
// is matched, so each pair's weight is computed once (the same value as
// EpipolarWeight).
class EpipolarWeights {
 public:
  static constexpr int kMaxViews = 32;  // candidates per pixel
  explicit EpipolarWeights(double max_angle_rad)
      : max_angle_rad_(max_angle_rad) {}
  // Starts a pixel with the epipolar directions of its num_views
  // (<= kMaxViews) candidates (kept by the caller until the next Reset).
  void Reset(const Eigen::Vector2d* directions, int num_views) {
    directions_ = directions;
    for (int v = 0; v < num_views; ++v)
      for (int w = 0; w < num_views; ++w) weight_[v * kMaxViews + w] = -1;
  }
  // w_e of candidates v and w.
  double operator()(int v, int w) {
    double& out = weight_[v * kMaxViews + w];
    if (out < 0) {
      out = EpipolarWeight(directions_[v], directions_[w], max_angle_rad_);
      weight_[w * kMaxViews + v] = out;
    }
    return out;
  }

 private:
  double max_angle_rad_;
  const Eigen::Vector2d* directions_ = nullptr;
  std::array<double, kMaxViews * kMaxViews> weight_;  // < 0: not computed
};

// Picks the next view to try: the view not yet active or rejected
// (state[i] == 0) with the highest l_R(V) = g_R(V) * prod over active V' of
// w_e(V, V'). active lists indices into the candidate arrays. Returns -1
// when none is left.
int PickNextView(int num_views, const double* global_scores,
                 EpipolarWeights& weights, const uint8_t* state,
                 const int* active, int num_active);

// The admission test: a candidate whose patch NCC with R is below min_ncc
// does not enter A. Without local view selection (select = false, the
// ablation AblationOptions::local_view_selection) every view that could be
// sampled enters. A NaN NCC is not below min_ncc.
inline bool AdmitsView(const LocalViewSelectionOptions& options, bool select,
                       double ncc) {
  return !select || !(ncc < options.min_ncc);
}

// Candidate states in `state` (indices into the candidate arrays).
constexpr uint8_t kCandidateUntried = 0, kCandidateActive = 1,
                  kCandidateRejected = 2;

// The fill loop of local view selection: while A (active[0, *num_active))
// holds fewer than options.num_active views, picks the next candidate with
// PickNextView and tries it (select: AdmitsView). sample(v, &ncc) prepares
// candidate v, returns false when its patch cannot be sampled and else sets
// ncc, its NCC with R. A candidate that cannot be sampled or fails AdmitsView
// is rejected (state kCandidateRejected, then refuse(v)); one that passes gets
// enter(v, ncc, a) with a its index in A (before active[a] = v, state
// kCandidateActive and ++*num_active). Returns the number of views that
// entered.
template <typename Sample, typename Enter, typename Refuse>
int FillActiveSet(const LocalViewSelectionOptions& options, bool select,
                  int num_views, const double* global_scores,
                  EpipolarWeights& weights, uint8_t* state, int* active,
                  int* num_active, Sample&& sample, Enter&& enter,
                  Refuse&& refuse) {
  int entered = 0;
  while (*num_active < options.num_active) {
    const int v = PickNextView(num_views, global_scores, weights, state, active,
                               *num_active);
    if (v < 0) break;
    double ncc = 0;
    if (!sample(v, &ncc) || !AdmitsView(options, select, ncc)) {
      state[v] = kCandidateRejected;
      refuse(v);
      continue;
    }
    enter(v, ncc, *num_active);
    state[v] = kCandidateActive;
    active[*num_active] = v;
    ++*num_active;
    ++entered;
  }
  return entered;
}

}  // namespace wild_mvs
