// Copyright wild_mvs authors. Writes a synthetic community photo collection
// of the courtyard (courtyard.h) as a COLMAP dataset (not a test): N views
// from random positions in front of the scene, each with its own resolution,
// focal length, exposure, white balance, gamma, vignetting, sun direction
// and (one view in three) a transient occluder, written as JPEG, and sparse
// points with SfM-like tracks. Used by bench/run_scale.sh.
//
//   make_collection OUT_DIR [--views N] [--seed S] [--min-size 320]
//                   [--max-size 1600] [--points-per-view 600]
//                   [--track-length 16] [--quality 92]
//
// Layout: OUT_DIR/sparse/{cameras,images,points3D}.txt (COLMAP text, PINHOLE
// cameras, pixel centres at +0.5), OUT_DIR/images/img_NNNN.jpg.
// Deterministic from the seed: the same arguments write the same model and
// the same images. Images that exist already are kept (a rerun after an
// interruption finishes the collection; every file is written atomically).
//
// Sparse points: about points-per-view / track-length points are anchored in
// each view (random pixels of persistent surfaces); a point's track holds the
// anchor and up to track-length - 1 other views that see it unoccluded (a
// depth test against a low-resolution render of each view) from within 30
// degrees of the anchor's direction and at a similar scale (SfM tracks join
// similar viewpoints), observations with 0.3 px noise. So the track length and
// the points per view stay the same when N grows.
#include <sys/stat.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <opencv2/imgcodecs.hpp>
#include <random>
#include <string>
#include <vector>

#include "courtyard.h"
#include "synthetic_scene.h"
#include "wild_mvs/core/error.h"
#include "wild_mvs/core/image.h"
#include "wild_mvs/io/atomic_file.h"
#include "wild_mvs/io/colmap.h"

using namespace wild_mvs;  // NOLINT
using testing::SyntheticObject;
using testing::SyntheticSpec;
using testing::ViewLighting;

namespace {

struct Options {
  int views = 100;
  unsigned seed = 1;
  int min_size = 320, max_size = 1600;
  int points_per_view = 600;
  int track_length = 16;
  int quality = 92;
};

// One photo of the collection.
struct Shot {
  Eigen::Vector3d center, look_at;
  int width = 0, height = 0;
  double focal = 0;
  ViewLighting light;
  bool occluder = false;
  SyntheticObject occluder_object;
};

// The camera testing::Render makes for a shot at `scale` of its size
// (LookAtCamera in synthetic_scene.cpp).
Camera ShotCamera(const Shot& s, double scale) {
  const int w = std::max(8, static_cast<int>(std::lround(s.width * scale)));
  const int h = std::max(8, static_cast<int>(std::lround(s.height * scale)));
  const Eigen::Vector3d f = (s.look_at - s.center).normalized();
  Eigen::Vector3d up(0, 0, 1);
  if (std::abs(f.dot(up)) > 0.999) up = Eigen::Vector3d(0, 1, 0);
  const Eigen::Vector3d x = f.cross(up).normalized();
  const Eigen::Vector3d y = f.cross(x).normalized();
  Camera c;
  c.fx = c.fy = s.focal * w / s.width;
  c.cx = w / 2.0;
  c.cy = h / 2.0;
  c.width = w;
  c.height = h;
  c.R.row(0) = x.transpose();
  c.R.row(1) = y.transpose();
  c.R.row(2) = f.transpose();
  c.t = -c.R * s.center;
  return c;
}

std::vector<Shot> DrawShots(const Options& o) {
  std::mt19937 rng(o.seed);
  std::uniform_real_distribution<double> U(0, 1);
  std::vector<Shot> shots(o.views);
  const Eigen::Vector3d Z(0, 0, 1);
  for (int i = 0; i < o.views; ++i) {
    Shot& s = shots[i];
    const double az = (-150 + 120 * U(rng)) * M_PI / 180;
    const double r = 2.0 * std::pow(5.5 / 2.0, U(rng));
    s.look_at = courtyard::LookAt() + Eigen::Vector3d(0.5 * (U(rng) - 0.5),
                                                      0.5 * (U(rng) - 0.5),
                                                      0.3 * (U(rng) - 0.5));
    s.center = courtyard::LookAt() +
               Eigen::Vector3d(r * std::cos(az), r * std::sin(az),
                               (0.3 + 0.3 * U(rng)) * r + 0.1);
    const int longest =
        o.min_size + static_cast<int>((o.max_size - o.min_size) * U(rng));
    const double shape = U(rng);
    const double aspect =
        shape < 0.7 ? 0.75 : (shape < 0.9 ? 4.0 / 3 : 2.0 / 3);
    if (aspect <= 1) {
      s.width = longest;
      s.height = std::max(8, static_cast<int>(std::lround(longest * aspect)));
    } else {
      s.height = longest;
      s.width = std::max(8, static_cast<int>(std::lround(longest / aspect)));
    }
    s.focal = std::max(s.width, s.height) * (0.7 + 0.6 * U(rng));
    ViewLighting& l = s.light;
    l.exposure = 0.45 * std::pow(2.2 / 0.45, U(rng));
    l.gamma = 1.0 + 1.2 * U(rng);
    for (int c = 0; c < 3; ++c) l.white_balance[c] = 0.75 + 0.5 * U(rng);
    l.vignetting = 0.4 * U(rng);
    const double saz = 2 * M_PI * U(rng), sel = (30 + 35 * U(rng)) * M_PI / 180;
    l.sun = Eigen::Vector3d(std::cos(saz) * std::cos(sel),
                            std::sin(saz) * std::cos(sel), std::sin(sel));
    const double clutter = U(rng), t = 0.3 + 0.3 * U(rng), side = U(rng) - 0.5,
                 size = U(rng), yaw = U(rng);
    s.occluder = clutter < 1.0 / 3;
    if (s.occluder) {
      const Eigen::Vector3d f = (s.look_at - s.center).normalized();
      const Eigen::Vector3d right = f.cross(Z).normalized();
      const Eigen::Vector3d p =
          s.center + t * (s.look_at - s.center) + side * 0.6 * right;
      s.occluder_object =
          size < 0.5 ? courtyard::Sphere(p, 0.12 + 0.2 * size, 60 + i, 0.03)
                     : courtyard::Box(
                           p, Eigen::Vector3d(0.1, 0.1, 0.18) * (0.5 + size),
                           90 * yaw, 60 + i, 0.03);
      s.occluder_object.only_in_view = 0;  // the one camera of its render
    }
  }
  return shots;
}

// Renders shot `s` at `scale` of its size (one-camera spec).
testing::SyntheticScene RenderShot(const Shot& s, double scale, int supersample,
                                   unsigned seed) {
  SyntheticSpec spec;
  spec.objects = courtyard::Objects();
  if (s.occluder) spec.objects.push_back(s.occluder_object);
  const Camera cam = ShotCamera(s, scale);
  spec.width = cam.width;
  spec.height = cam.height;
  spec.focal = cam.fx;
  spec.sky = true;
  spec.camera_centers = {s.center};
  spec.look_at = s.look_at;
  spec.lighting = {s.light};
  spec.noise_sigma = 0.004;
  spec.supersample = supersample;
  spec.num_sparse_points = 0;
  spec.seed = seed;
  return testing::Render(spec);
}

// Low-resolution depth of every shot (persistent objects only where the
// pixel sees one; 0 elsewhere) for sampling and visibility.
struct DepthProbe {
  Camera camera;
  cv::Mat depth;       // CV_32F
  cv::Mat persistent;  // CV_8U, 1 where a persistent object is seen
};

bool Visible(const DepthProbe& p, const Eigen::Vector3d& X) {
  Eigen::Vector2d px;
  if (!p.camera.Project(X, &px) || !p.camera.InImage(px, 0.5)) return false;
  const int c = std::min(p.depth.cols - 1, static_cast<int>(px.x()));
  const int r = std::min(p.depth.rows - 1, static_cast<int>(px.y()));
  const float d = p.depth.at<float>(r, c);
  const double z = p.camera.Depth(X);
  return d > 0 && std::abs(d - z) <= 0.01 * z;
}

std::vector<SparsePoint> MakePoints(const Options& o,
                                    const std::vector<Shot>& shots,
                                    const std::vector<Camera>& cameras) {
  const int n = static_cast<int>(shots.size());
  std::vector<DepthProbe> probes(n);
  for (int i = 0; i < n; ++i) {
    const double scale = 160.0 / std::max(shots[i].width, shots[i].height);
    const testing::SyntheticScene s = RenderShot(shots[i], scale, 1, o.seed);
    probes[i].camera = s.scene.views[0].camera;
    probes[i].depth = s.depth[0];
    probes[i].persistent = cv::Mat(s.object_id[0].size(), CV_8U);
    const int persistent = static_cast<int>(courtyard::Objects().size());
    for (int r = 0; r < s.object_id[0].rows; ++r)
      for (int c = 0; c < s.object_id[0].cols; ++c) {
        const int id = s.object_id[0].at<int>(r, c);
        probes[i].persistent.at<uchar>(r, c) = id >= 0 && id < persistent;
      }
  }
  std::mt19937 rng(o.seed * 7919u + 17u);
  std::uniform_real_distribution<double> U(0, 1);
  std::normal_distribution<double> noise(0, 0.3);
  const int per_anchor =
      std::max(1, o.points_per_view / std::max(1, o.track_length));
  const double max_angle_cos = std::cos(30 * M_PI / 180);
  std::vector<SparsePoint> points;
  for (int a = 0; a < n; ++a) {
    const DepthProbe& pa = probes[a];
    for (int k = 0, tries = 0; k < per_anchor && tries < 50 * per_anchor;
         ++tries) {
      const double u = U(rng) * pa.camera.width, v = U(rng) * pa.camera.height;
      const int c = std::min(pa.camera.width - 1, static_cast<int>(u));
      const int r = std::min(pa.camera.height - 1, static_cast<int>(v));
      if (!pa.persistent.at<uchar>(r, c)) continue;
      const float d = pa.depth.at<float>(r, c);
      if (!(d > 0)) continue;
      const Eigen::Vector3d X =
          pa.camera.Backproject(Eigen::Vector2d(c + 0.5, r + 0.5), d);
      const Eigen::Vector3d da = (X - pa.camera.Center()).normalized();
      const double fa = cameras[a].PixelFootprint(cameras[a].Depth(X));
      std::vector<std::pair<double, int>> seen;  // -cos angle, view
      for (int j = 0; j < n; ++j) {
        if (j == a) continue;
        const Eigen::Vector3d dj = (X - cameras[j].Center()).normalized();
        const double cosang = da.dot(dj);
        if (cosang < max_angle_cos) continue;
        const double ratio =
            cameras[j].PixelFootprint(cameras[j].Depth(X)) / fa;
        if (ratio > 2.5 || ratio < 0.4) continue;
        if (!Visible(probes[j], X)) continue;
        seen.emplace_back(-cosang, j);
      }
      ++k;  // an attempt at a point of this anchor
      if (seen.empty()) continue;
      std::sort(seen.begin(), seen.end());
      if (static_cast<int>(seen.size()) > o.track_length - 1)
        seen.resize(o.track_length - 1);
      std::vector<int> track{a};
      for (const auto& s : seen) track.push_back(s.second);
      std::sort(track.begin(), track.end());
      SparsePoint sp;
      sp.xyz = X;
      for (int j : track) {
        Observation ob;
        ob.view = j;
        if (!cameras[j].Project(X, &ob.xy)) continue;
        ob.xy += Eigen::Vector2d(noise(rng), noise(rng));
        ob.scale = 2.0;
        sp.track.push_back(ob);
      }
      if (sp.track.size() < 2) continue;
      sp.rgb = Eigen::Vector3f::Constant(0.5f);
      points.push_back(sp);
    }
  }
  return points;
}

// Linear RGB -> 8-bit sRGB BGR for cv::imwrite.
cv::Mat ToSrgb8(const cv::Mat& linear) {
  cv::Mat out(linear.size(), CV_8UC3);
  for (int r = 0; r < out.rows; ++r) {
    const auto* ip = linear.ptr<cv::Vec3f>(r);
    auto* op = out.ptr<cv::Vec3b>(r);
    for (int c = 0; c < out.cols; ++c)
      for (int k = 0; k < 3; ++k)
        op[c][2 - k] = cv::saturate_cast<uchar>(
            std::round(LinearToSrgb(std::clamp(ip[c][k], 0.f, 1.f)) * 255.f));
  }
  return out;
}

bool FileExists(const std::string& path) {
  struct stat st;
  return stat(path.c_str(), &st) == 0 && S_ISREG(st.st_mode) && st.st_size > 0;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2 || argv[1][0] == '-') {
    std::cerr << "usage: make_collection OUT_DIR [--views N] [--seed S] "
                 "[--min-size 320] [--max-size 1600] [--points-per-view 600] "
                 "[--track-length 16] [--quality 92]\n";
    return 2;
  }
  try {
    const std::string out = argv[1];
    Options o;
    for (int i = 2; i < argc; ++i) {
      const std::string a = argv[i];
      if (i + 1 >= argc)
        throw Error(Msg("make_collection: ", a, " needs a value"));
      const std::string v = argv[++i];
      if (a == "--views") {
        o.views = std::stoi(v);
      } else if (a == "--seed") {
        o.seed = static_cast<unsigned>(std::stoul(v));
      } else if (a == "--min-size") {
        o.min_size = std::stoi(v);
      } else if (a == "--max-size") {
        o.max_size = std::stoi(v);
      } else if (a == "--points-per-view") {
        o.points_per_view = std::stoi(v);
      } else if (a == "--track-length") {
        o.track_length = std::stoi(v);
      } else if (a == "--quality") {
        o.quality = std::stoi(v);
      } else {
        throw Error(Msg("make_collection: unknown option ", a));
      }
    }
    Require(o.views >= 3, "make_collection: --views must be >= 3");
    Require(o.min_size >= 32 && o.max_size >= o.min_size,
            "make_collection: need 32 <= --min-size <= --max-size");
    Require(o.track_length >= 2,
            "make_collection: --track-length must be >= 2");
    Require(o.quality >= 1 && o.quality <= 100,
            "make_collection: --quality must be in [1, 100]");
    const std::vector<Shot> shots = DrawShots(o);
    Scene scene;
    scene.source = "synthetic collection";
    std::vector<Camera> cameras;
    for (int i = 0; i < o.views; ++i) {
      View v;
      char name[32];
      std::snprintf(name, sizeof(name), "img_%04d.jpg", i);
      v.name = name;
      v.camera = ShotCamera(shots[i], 1.0);
      cameras.push_back(v.camera);
      scene.views.push_back(v);
    }
    scene.points = MakePoints(o, shots, cameras);
    size_t obs = 0;
    for (const SparsePoint& p : scene.points) obs += p.track.size();
    WriteColmapText(scene, out + "/sparse");
    int rendered = 0;
    for (int i = 0; i < o.views; ++i) {
      const std::string path = out + "/images/" + scene.views[i].name;
      if (FileExists(path)) continue;
      const int longest = std::max(shots[i].width, shots[i].height);
      const testing::SyntheticScene s =
          RenderShot(shots[i], 1.0, longest <= 800 ? 2 : 1, o.seed * 131u + i);
      const Camera& rc = s.scene.views[0].camera;
      Require((rc.R - cameras[i].R).norm() < 1e-9 &&
                  (rc.t - cameras[i].t).norm() < 1e-9 &&
                  rc.width == cameras[i].width && rc.fx == cameras[i].fx,
              "make_collection: the rendered camera of view ", i,
              " differs from the model's");
      const cv::Mat bgr = ToSrgb8(s.images[0]);
      ProduceFileAtomically(path, [&](const std::string& tmp) {
        return cv::imwrite(tmp, bgr, {cv::IMWRITE_JPEG_QUALITY, o.quality});
      });
      ++rendered;
    }
    std::printf(
        "collection: %d views (%d rendered now), %d..%d px, %zu sparse "
        "points, mean track length %.1f, %.0f observations per view -> %s\n",
        o.views, rendered, o.min_size, o.max_size, scene.points.size(),
        scene.points.empty() ? 0.0 : double(obs) / scene.points.size(),
        double(obs) / o.views, out.c_str());
  } catch (const std::exception& e) {
    std::cerr << "make_collection: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
