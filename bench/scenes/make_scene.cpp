// Copyright wild_mvs authors. Writes a rendered evaluation scene with exact
// ground truth as a dataset folder (not a test): COLMAP text model with
// sparse points in sparse/, 8-bit sRGB PNGs in images/, ground-truth depth
// in gt_depth/ (see testing::WriteDataset), and gt_surface.ply: points on
// every surface some view sees (one per 2 pixels, thinned to 5 mm voxels;
// one-view occluders excluded), the reference of `wild_mvs eval cloud`. Used by
// bench/run_families.sh and bench/run_accuracy.sh.
//
//   make_scene KIND OUT_DIR [--views N] [--width W] [--height H] [--seed S]
//              [--points P] [--contrast C]
//              [--noise SIGMA]
//
// --views: 14 for the relief and weak families, 12 for the courtyard.
//
// --points P: sparse points sampled on the surfaces with their exact
// visibility (1500; 0.3 px noise); 0 = none, so that `wild_mvs reconstruct`
// computes tracks from the images (SIFT under the scene's light changes, as
// a user's SfM would).
//
// --contrast C: the relief family's texture contrast times C, (0, 1] (1):
// weaker texture, so the moving sun's shading weighs more in each window.
//
// --noise SIGMA: Gaussian image noise of the relief and weak families, in
// image units after the camera response, [0, 0.1] (0.01: a camera's noise).
//
// KIND relief or weak: the families of families.h, everything drawn from
// the seed (family_relief.cpp, family_weak.cpp).
//
// Other KINDs (one courtyard: a textured ground, a back wall, boxes, spheres
// and a pillar under a sky, cameras on a 100-degree arc; the seed draws the
// light of `light` and the occluders of `clutter`):
//   constant  the same exposure, white balance and light in every view;
//   light     per view exposure 0.35..2.6, white balance +-30 %, gamma
//             1..2.2, vignetting up to 0.5 and a sun from another side
//             (shading and cast shadows differ between views);
//   exposure, gamma, vignetting, sun: one of the changes of `light` alone;
//   clutter   constant light; every other view has its own transient
//             occluder (a box or a sphere between camera and scene);
//   scale     constant light; camera distances 1.6..6.0 (a 3.75x range of
//             image scales).
#include <cmath>
#include <cstdio>
#include <iostream>
#include <random>
#include <string>

#include "courtyard.h"
#include "families.h"
#include "synthetic_scene.h"
#include "wild_mvs/core/error.h"
#include "wild_mvs/core/metrics.h"
#include "wild_mvs/io/ply.h"

using namespace wild_mvs;
using courtyard::Box;
using courtyard::Sphere;
using testing::SyntheticObject;
using testing::SyntheticSpec;

namespace {

SyntheticSpec Courtyard(const std::string& kind, int n, int w, int h,
                        unsigned seed, int points) {
  SyntheticSpec s;
  s.width = w;
  s.height = h;
  s.focal = 0.9 * w;
  s.sky = true;
  s.seed = seed;
  s.num_sparse_points = points;
  s.sparse_pixel_noise = 0.3;
  s.supersample = 2;
  const Eigen::Vector3d Z(0, 0, 1);
  s.objects = courtyard::Objects();
  s.look_at = courtyard::LookAt();

  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> U(0, 1);
  std::vector<double> radii(n, 3.0);
  if (kind == "scale") {
    for (int i = 0; i < n; ++i)  // 1.6 .. 6.0, interleaved
      radii[i] = 1.6 * std::pow(6.0 / 1.6, ((i * 5) % n) / double(n - 1));
  }
  for (int i = 0; i < n; ++i) {
    const double a = (-140 + 100.0 * i / (n - 1)) * M_PI / 180;  // arc
    const double r = radii[i];
    s.camera_centers.push_back(s.look_at + Eigen::Vector3d(r * std::cos(a),
                                                           r * std::sin(a),
                                                           0.45 * r + 0.2));
  }
  // The light kinds draw the same random values; the single-factor kinds
  // (exposure, gamma, vignetting, sun) keep only one of the changes, to
  // isolate what costs coverage.
  const bool light = kind == "light" || kind == "exposure" || kind == "gamma" ||
                     kind == "vignetting" || kind == "sun";
  if (light) {
    for (int i = 0; i < n; ++i) {
      testing::ViewLighting l, all;
      all.exposure = 0.35 * std::pow(2.6 / 0.35, U(rng));
      all.gamma = 1.0 + 1.2 * U(rng);
      for (int c = 0; c < 3; ++c) all.white_balance[c] = 0.7 + 0.6 * U(rng);
      all.vignetting = 0.5 * U(rng);
      const double az = 2 * M_PI * U(rng), el = (30 + 35 * U(rng)) * M_PI / 180;
      all.sun = Eigen::Vector3d(std::cos(az) * std::cos(el),
                                std::sin(az) * std::cos(el), std::sin(el));
      if (kind == "light") l = all;
      if (kind == "exposure") {
        l.exposure = all.exposure;
        l.white_balance = all.white_balance;
      }
      if (kind == "gamma") l.gamma = all.gamma;
      if (kind == "vignetting") l.vignetting = all.vignetting;
      if (kind == "sun") l.sun = all.sun;
      s.lighting.push_back(l);
    }
  } else if (kind == "clutter") {
    for (int i = 0; i < n; i += 2) {
      const Eigen::Vector3d c = s.camera_centers[i];
      const Eigen::Vector3d f = (s.look_at - c).normalized();
      const Eigen::Vector3d right = f.cross(Z).normalized();
      const double t = 0.3 + 0.3 * U(rng);
      const Eigen::Vector3d p =
          c + t * (s.look_at - c) + (U(rng) - 0.5) * 0.6 * right;
      SyntheticObject o =
          (i / 2) % 2 ? Sphere(p, 0.12 + 0.1 * U(rng), 60 + i, 0.03)
                      : Box(p, Eigen::Vector3d(0.1, 0.1, 0.18) * (1 + U(rng)),
                            90 * U(rng), 60 + i, 0.03);
      o.only_in_view = i;
      s.objects.push_back(o);
    }
  } else if (kind != "constant" && kind != "scale") {
    throw Error(Msg("make_scene: unknown kind '", kind,
                    "' (constant, light, exposure, gamma, vignetting, sun, "
                    "clutter, scale)"));
  }
  return s;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 3) {
    std::cerr << "usage: make_scene relief|weak|constant|light|exposure|gamma|"
                 "vignetting|sun|clutter|scale OUT_DIR "
                 "[--views N] [--width W] [--height H] [--seed S] [--points P] "
                 "[--contrast C] [--noise SIGMA]\n";
    return 2;
  }
  try {
    const std::string kind = argv[1];
    const bool family = kind == "relief" || kind == "weak";
    int n = family ? 14 : 12, w = 640, h = 480, points = 1500;
    unsigned seed = 5;
    double contrast = 1.0, noise = families::FamilyOptions().noise;
    for (int i = 3; i < argc; ++i) {
      const std::string a = argv[i];
      if (i + 1 >= argc) throw Error(Msg("make_scene: ", a, " needs a value"));
      const std::string v = argv[++i];
      if (a == "--views") {
        n = std::stoi(v);
      } else if (a == "--width") {
        w = std::stoi(v);
      } else if (a == "--height") {
        h = std::stoi(v);
      } else if (a == "--points") {
        points = std::stoi(v);
      } else if (a == "--contrast") {
        contrast = std::stod(v);
      } else if (a == "--noise") {
        noise = std::stod(v);
        Require(noise >= 0 && noise <= 0.1, "make_scene: --noise ", v,
                " is not in [0, 0.1]");
      } else if (a == "--seed") {
        seed = static_cast<unsigned>(std::stoul(v));
      } else {
        throw Error(Msg("make_scene: unknown option ", a));
      }
    }
    Require(n >= 3, "make_scene: --views must be >= 3");
    Require(w >= 16 && h >= 16, "make_scene: image size ", w, "x", h,
            " is too small");
    families::FamilyOptions fo;
    fo.views = n;
    fo.width = w;
    fo.height = h;
    fo.seed = seed;
    fo.points = points;
    fo.texture_contrast = contrast;
    fo.noise = noise;
    const testing::SyntheticSpec spec =
        kind == "relief" ? families::ReliefScene(fo)
        : kind == "weak" ? families::WeakTextureScene(fo)
                         : Courtyard(kind, n, w, h, seed, points);
    const testing::SyntheticScene s = testing::Render(spec);
    testing::WriteDataset(s, argv[2]);
    WritePly(std::string(argv[2]) + "/gt_surface.ply",
             VoxelThin(s.GroundTruthCloud(2), 0.005));
    std::printf("%s: %d views %dx%d, %zu sparse points -> %s\n", argv[1], n, w,
                h, s.scene.points.size(), argv[2]);
  } catch (const std::exception& e) {
    std::cerr << "make_scene: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
