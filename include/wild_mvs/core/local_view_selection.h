// Copyright wild_mvs authors. Local (per-pixel) view selection (paper section
// 5.2 / docs/ALGORITHM.md section 3): the active set A of up to m views used to
// match one pixel, favouring spread epipolar directions.
#pragma once

#include <Eigen/Core>
#include <cstdint>

#include "wild_mvs/core/option_registry.h"

namespace wild_mvs {

struct LocalViewSelectionOptions {
  // false = the paper's "no local view selection" ablation: the best m views
  // of the global selection, always the same, no refill.
  bool enabled = true;
  int num_active = 4;                  // m = |A| (paper: 4)
  double max_epipolar_angle_deg = 10;  // g_max (paper: 10)
  double min_ncc = 0.3;                // NCC to enter A (paper: 0.3)
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

// Picks the next view to try: the view not yet active or rejected
// (state[i] == 0) with the highest l_R(V) = g_R(V) * prod over active V' of
// w_e(V, V'). active lists indices into the candidate arrays. Returns -1
// when none is left.
int PickNextView(int num_views, const double* global_scores,
                 const Eigen::Vector2d* directions, const uint8_t* state,
                 const int* active, int num_active, double max_angle_rad);

}  // namespace wild_mvs
