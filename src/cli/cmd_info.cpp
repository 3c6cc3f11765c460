// Copyright wild_mvs authors. `wild_mvs info DATASET`: what a dataset holds
// and whether it is fit for multi-view stereo.
#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <iomanip>
#include <iostream>
#include <map>
#include <numeric>
#include <set>
#include <sstream>

#include "wild_mvs/cli/commands.h"
#include "wild_mvs/cli/scene_setup.h"
#include "wild_mvs/cli/specs.h"
#include "wild_mvs/core/stats.h"

namespace wild_mvs {
namespace cli {
namespace {

constexpr double kRadToDeg = 180.0 / M_PI;

// A point the cameras look at: the median of the sparse points, else the
// least-squares intersection of the optical axes.
bool SceneCentre(const Scene& s, Eigen::Vector3d* c) {
  if (!s.points.empty()) {
    for (int k = 0; k < 3; ++k) {
      std::vector<double> v;
      for (const SparsePoint& p : s.points) v.push_back(p.xyz[k]);
      (*c)[k] = Median(v);
    }
    return true;
  }
  Eigen::Matrix3d A = Eigen::Matrix3d::Zero();
  Eigen::Vector3d b = Eigen::Vector3d::Zero();
  for (const View& v : s.views) {
    const Eigen::Vector3d d = v.camera.ViewDirection();
    const Eigen::Matrix3d P = Eigen::Matrix3d::Identity() - d * d.transpose();
    A += P;
    b += P * v.camera.Center();
  }
  Eigen::FullPivLU<Eigen::Matrix3d> lu(A);
  if (s.views.size() < 2 || lu.rank() < 3) return false;
  *c = lu.solve(b);
  return c->allFinite();
}

std::string Fixed(double v, int digits) {
  std::ostringstream os;
  os << std::fixed << std::setprecision(digits) << v;
  return os.str();
}

}  // namespace

int RunInfo(const CommandArgs& argv) {
  CommandSpec spec = InfoSpec();
  Args args(spec, argv);
  if (args.help()) {
    PrintCommandHelp(spec, nullptr, std::cout);
    return 0;
  }
  DatasetOptions dopt = MakeDatasetOptions(args.positional(0), args);
  dopt.check_images = !args.Has("no-check-images");
  const DatasetLayout layout = DetectDatasetLayout(dopt);
  const Scene scene = LoadDataset(dopt);
  std::ostream& os = std::cout;
  const int n = static_cast<int>(scene.views.size());

  os << "dataset:      " << dopt.path << "\n"
     << "format:       " << DatasetFormatName(layout.format) << " (model "
     << layout.model << ")\n"
     << "source:       " << scene.source << "\n"
     << "views:        " << n
     << (dopt.check_images ? " (images present, sizes match the cameras)"
                           : " (images not checked)")
     << "\n";
  std::map<std::pair<int, int>, int> sizes;
  std::vector<double> focal;
  int distorted = 0;
  for (const View& v : scene.views) {
    ++sizes[{v.camera.width, v.camera.height}];
    focal.push_back(0.5 * (v.camera.fx + v.camera.fy));
    distorted += v.distortion.IsNone() ? 0 : 1;
  }
  os << "resolution:  ";
  for (const auto& kv : sizes) {
    os << " " << kv.first.first << "x" << kv.first.second << " (" << kv.second
       << (kv.second == 1 ? " view)" : " views)");
  }
  os << "\n";
  if (!focal.empty()) {
    os << "focal (px):   "
       << Fixed(*std::min_element(focal.begin(), focal.end()), 1) << " .. "
       << Fixed(*std::max_element(focal.begin(), focal.end()), 1) << "\n";
  }
  if (distorted) {
    os << "distortion:   " << distorted
       << " views have lens distortion (undistorted at load)\n";
  }

  // Sparse structure.
  const auto per_view = scene.PointsPerView();
  std::vector<std::set<int>> covisible(n);
  if (scene.points.empty()) {
    os << "points:       none (wild_mvs sparse / reconstruct compute them "
          "from the known poses)\n";
  } else {
    std::vector<double> lengths, errors;
    for (const SparsePoint& p : scene.points) {
      lengths.push_back(static_cast<double>(p.track.size()));
      errors.push_back(p.error);
      for (const Observation& a : p.track) {
        for (const Observation& b : p.track) {
          if (a.view != b.view) covisible[a.view].insert(b.view);
        }
      }
    }
    const double mean_len =
        std::accumulate(lengths.begin(), lengths.end(), 0.0) / lengths.size();
    os << "points:       " << scene.points.size() << "\n"
       << "track length: min "
       << *std::min_element(lengths.begin(), lengths.end()) << ", median "
       << Median(lengths) << ", mean " << Fixed(mean_len, 2) << ", max "
       << *std::max_element(lengths.begin(), lengths.end()) << "\n"
       << "reprojection: median " << Fixed(Median(errors), 3)
       << " px (as stored in the model)\n";
  }

  // Geometry: distance to the scene, nearest camera (baseline angle).
  Eigen::Vector3d centre;
  const bool has_centre = SceneCentre(scene, &centre);
  std::vector<double> depth(n, 0), nearest_angle(n, 0);
  std::vector<int> nearest(n, -1);
  for (int i = 0; i < n; ++i) {
    const Camera& ci = scene.views[i].camera;
    if (has_centre) depth[i] = ci.Depth(centre);
    double best = 1e300;
    for (int j = 0; j < n; ++j) {
      if (j == i) continue;
      const double d = (ci.Center() - scene.views[j].camera.Center()).norm();
      if (d < best) {
        best = d;
        nearest[i] = j;
      }
    }
    if (nearest[i] >= 0 && has_centre) {
      const Eigen::Vector3d a = ci.Center() - centre;
      const Eigen::Vector3d b =
          scene.views[nearest[i]].camera.Center() - centre;
      nearest_angle[i] = std::atan2(a.cross(b).norm(), a.dot(b)) * kRadToDeg;
    }
  }

  os << "\nper view:\n"
     << "  #   name                      size        focal  points  "
        "covisible  depth      nearest (angle)\n";
  for (int i = 0; i < n; ++i) {
    const View& v = scene.views[i];
    char line[512];
    std::snprintf(
        line, sizeof(line), "  %-3d %-25s %4dx%-6d %6.0f  %6zu  %9zu  %-9s  %s",
        i, v.name.c_str(), v.camera.width, v.camera.height,
        0.5 * (v.camera.fx + v.camera.fy), per_view[i].size(),
        covisible[i].size(), has_centre ? Fixed(depth[i], 3).c_str() : "?",
        nearest[i] >= 0
            ? (scene.views[nearest[i]].name + " (" +
               (has_centre ? Fixed(nearest_angle[i], 1) + " deg" : "?") + ")")
                  .c_str()
            : "-");
    os << line << "\n";
  }

  // Sanity checks.
  std::vector<std::string> warnings;
  const double kTwinDeg = 1.0;
  int twins = 0;
  for (int i = 0; i < n; ++i) {
    for (int j = i + 1; j < n && has_centre; ++j) {
      const Eigen::Vector3d a = scene.views[i].camera.Center() - centre;
      const Eigen::Vector3d b = scene.views[j].camera.Center() - centre;
      const double ang = std::atan2(a.cross(b).norm(), a.dot(b)) * kRadToDeg;
      if (ang < kTwinDeg) {
        ++twins;
        warnings.push_back(
            Msg(scene.views[i].name, " and ", scene.views[j].name,
                " were taken from (almost) the same position (", Fixed(ang, 2),
                " deg apart): no parallax between them"));
      }
    }
  }
  if (has_centre && n >= 2 && twins == n * (n - 1) / 2) {
    warnings.push_back(
        "all views were taken from one position: no depth can be "
        "triangulated");
  }
  for (int i = 0; i < n; ++i) {
    if (has_centre && depth[i] <= 0) {
      warnings.push_back(
          Msg(scene.views[i].name, ": the scene centre is behind this camera"));
    }
    if (!scene.points.empty() && per_view[i].empty()) {
      warnings.push_back(Msg(scene.views[i].name,
                             ": observes no sparse point (MVS falls back to "
                             "overlap-based neighbours)"));
    } else if (!scene.points.empty() && covisible[i].empty()) {
      warnings.push_back(Msg(scene.views[i].name,
                             ": shares no sparse point with another view"));
    }
  }
  if (n < 2) warnings.push_back("fewer than two views: nothing to match");
  os << "\nchecks:       "
     << (warnings.empty() ? "ok (baselines, overlap, observations)"
                          : Msg(warnings.size(), " warning(s)"))
     << "\n";
  for (const std::string& w : warnings) os << "  warning: " << w << "\n";
  return 0;
}

}  // namespace cli
}  // namespace wild_mvs
