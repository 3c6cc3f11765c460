// Copyright wild_mvs authors. A random sparse "photo collection" (cameras and
// SfM tracks, no pixels) for the view-selection test and benchmark.
//
// N cameras on an arc of 120 degrees around a unit cube of points, at random
// distances 3..6 and focal lengths (so resolutions differ); each point's
// track holds `track_length` views chosen at random among those within
// +-15 degrees of a random anchor view (tracks connect similar viewpoints,
// like matched photos), so the track length and the points per view stay
// fixed when N grows: P = points_per_view * N / track_length.
#pragma once

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "wild_mvs/core/scene.h"

namespace wild_mvs {
namespace testing {

inline Camera RandomCollectionCamera(const Eigen::Vector3d& center,
                                     const Eigen::Vector3d& target,
                                     double focal, int width, int height) {
  const Eigen::Vector3d f = (target - center).normalized();
  const Eigen::Vector3d x = f.cross(Eigen::Vector3d::UnitZ()).normalized();
  const Eigen::Vector3d y = f.cross(x);
  Camera c;
  c.fx = c.fy = focal;
  c.cx = width / 2.0;
  c.cy = height / 2.0;
  c.width = width;
  c.height = height;
  c.R.row(0) = x.transpose();
  c.R.row(1) = y.transpose();
  c.R.row(2) = f.transpose();
  c.t = -c.R * center;
  return c;
}

inline Scene RandomCollection(int num_views, int points_per_view,
                              int track_length, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> U(0, 1);
  Scene scene;
  scene.source = "random collection";
  std::vector<double> azimuth(num_views);
  for (int i = 0; i < num_views; ++i) {
    azimuth[i] = (-60 + 120 * U(rng)) * M_PI / 180;
    const double r = 3 + 3 * U(rng);
    const Eigen::Vector3d C(r * std::sin(azimuth[i]), -r * std::cos(azimuth[i]),
                            0.5 * r * U(rng));
    const Eigen::Vector3d target(0.3 * (U(rng) - 0.5), 0.3 * (U(rng) - 0.5),
                                 0.3 * (U(rng) - 0.5));
    const int w = 320 + static_cast<int>(1280 * U(rng));
    View v;
    char name[32];
    std::snprintf(name, sizeof(name), "img_%04d.jpg", i);
    v.name = name;
    v.camera = RandomCollectionCamera(C, target, w * (0.8 + 0.6 * U(rng)), w,
                                      w * 3 / 4);
    scene.views.push_back(v);
  }
  const int num_points =
      std::max(1, points_per_view * num_views / std::max(1, track_length));
  std::vector<int> near;
  for (int p = 0; p < num_points; ++p) {
    SparsePoint sp;
    sp.xyz = Eigen::Vector3d(U(rng) - 0.5, U(rng) - 0.5, U(rng) - 0.5);
    const int anchor = static_cast<int>(U(rng) * num_views) % num_views;
    near.clear();
    for (int v = 0; v < num_views; ++v)
      if (std::abs(azimuth[v] - azimuth[anchor]) < 15 * M_PI / 180)
        near.push_back(v);
    std::shuffle(near.begin(), near.end(), rng);
    if (static_cast<int>(near.size()) > track_length) near.resize(track_length);
    std::sort(near.begin(), near.end());
    for (int v : near) {
      Observation o;
      o.view = v;
      if (!scene.views[v].camera.Project(sp.xyz, &o.xy)) continue;
      o.scale = 2;
      sp.track.push_back(o);
    }
    if (sp.track.size() >= 2) scene.points.push_back(sp);
  }
  return scene;
}

}  // namespace testing
}  // namespace wild_mvs
