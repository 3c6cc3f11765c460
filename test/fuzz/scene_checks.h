// Copyright wild_mvs authors. What a harness checks on a scene a reader
// accepted: it must pass Scene::Validate() (or be refused by it with an
// Error), and the derived tables must be buildable without touching memory
// out of bounds.
#pragma once

#include "wild_mvs/core/error.h"
#include "wild_mvs/core/scene.h"

namespace wild_mvs {
namespace fuzz {

inline void CheckAcceptedScene(const Scene& scene) {
  try {
    scene.Validate();
  } catch (const Error&) {
    return;  // refused with a message: fine
  }
  const auto per_view = scene.PointsPerView();
  if (per_view.size() != scene.views.size()) __builtin_trap();
  for (const SparsePoint& p : scene.points) {
    for (const Observation& o : p.track) {
      if (o.view < 0 || o.view >= static_cast<int>(scene.views.size()))
        __builtin_trap();  // Validate() accepted a dangling track
    }
  }
  for (const View& v : scene.views) {
    if (scene.FindView(v.name) < 0) __builtin_trap();
    (void)v.Stem();
  }
}

}  // namespace fuzz
}  // namespace wild_mvs
