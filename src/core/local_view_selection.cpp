// Copyright wild_mvs authors.
#include "wild_mvs/core/local_view_selection.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>

#include "wild_mvs/core/error.h"

namespace wild_mvs {

void LocalViewSelectionOptions::Check() const {
  Require(num_active >= 1 && num_active <= 8,
          "mvs.local.num_active = ", num_active, " must be in [1, 8]");
  Require(min_ncc >= -1 && min_ncc <= 1, "mvs.local.min_ncc = ", min_ncc,
          " must be in [-1, 1]");
  Require(wide_min_ncc >= -1 && wide_min_ncc <= 1,
          "mvs.local.wide_min_ncc = ", wide_min_ncc, " must be in [-1, 1]");
}

void RegisterOptions(OptionRegistry* registry, const std::string& prefix,
                     LocalViewSelectionOptions* o) {
  auto key = [&prefix](const char* name) {
    return OptionRegistry::Join(prefix, name);
  };
  registry
      ->Add(key("num_active"), &o->num_active,
            "active views per pixel |A| (paper: 4)")
      .Min(1)
      .Max(8)
      .Note(">= mpgc.min_active_views");
  registry
      ->Add(key("min_ncc"), &o->min_ncc,
            "NCC needed to enter the active set (paper: 0.3)")
      .Min(-1)
      .Max(1);
  registry
      ->Add(key("wide_min_ncc"), &o->wide_min_ncc,
            "min_ncc where the window is wide (window step >= 2)")
      .Min(-1)
      .Max(1);
}

Eigen::Vector2d EpipolarDirection(const Eigen::Vector3d& e, double x,
                                  double y) {
  // Line through (x, y, 1) and e: l = x cross e; its direction is (l1, -l0).
  const Eigen::Vector3d l = Eigen::Vector3d(x, y, 1.0).cross(e);
  Eigen::Vector2d d(l.y(), -l.x());
  const double n = d.norm();
  if (n < 1e-12) return Eigen::Vector2d(1, 0);
  return d / n;
}

double EpipolarWeight(const Eigen::Vector2d& d1, const Eigen::Vector2d& d2,
                      double max_angle_rad) {
  const double c = std::min(1.0, std::abs(d1.dot(d2)));
  const double g = std::acos(c);  // acute angle in [0, pi/2]
  return std::min(g / max_angle_rad, 1.0);
}

int PickNextView(int num_views, const double* global_scores,
                 EpipolarWeights& weights, const uint8_t* state,
                 const int* active, int num_active) {
  int best = -1;
  double best_score = -1;
  for (int v = 0; v < num_views; ++v) {
    if (state[v] != 0) continue;
    double l = global_scores[v];
    for (int a = 0; a < num_active && l > best_score; ++a)
      l *= weights(v, active[a]);
    if (l > best_score) {
      best_score = l;
      best = v;
    }
  }
  return best;
}

}  // namespace wild_mvs
