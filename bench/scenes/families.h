// Copyright wild_mvs authors. Rendered scene families of the benchmark
// (bench/run_families.sh, docs/METHODS.md), each built apart from the
// others: its own layout, objects, textures, camera path and lighting, all
// drawn from one seed.
//   relief   curved and relief geometry under a sun that moves per view
//            (family_relief.cpp);
//   weak     an indoor-like room with weakly textured walls and floor
//            (family_weak.cpp);
//   courtyard the older scenes of make_scene (constant, light, clutter,
//            scale).
#pragma once

#include <string>

#include "synthetic_scene.h"

namespace wild_mvs {
namespace families {

struct FamilyOptions {
  int views = 14;
  int width = 640, height = 480;
  unsigned seed = 1;
  // Sparse points sampled with exact visibility (0.3 px noise); 0 = none.
  int points = 1500;
  // Multiplies every object's texture contrast (albedo variation), (0, 1]:
  // below 1 the shading of the sun carries more of each window's variation.
  double texture_contrast = 1.0;
  // Gaussian image noise, standard deviation in image units after the
  // camera response (SyntheticSpec::noise_sigma), [0, 0.1]. 0.01 (2.55 of
  // 255 levels) is a typical camera's read and shot noise at low ISO.
  double noise = 0.01;
};

testing::SyntheticSpec ReliefScene(const FamilyOptions& options);
testing::SyntheticSpec WeakTextureScene(const FamilyOptions& options);

}  // namespace families
}  // namespace wild_mvs
