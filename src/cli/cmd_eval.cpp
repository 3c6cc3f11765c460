// Copyright wild_mvs authors. `wild_mvs eval`: depth maps and point clouds
// against ground truth, and ground-truth clouds from ground-truth depth.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <opencv2/core.hpp>

#include "wild_mvs/cli/commands.h"
#include "wild_mvs/cli/scene_setup.h"
#include "wild_mvs/cli/specs.h"
#include "wild_mvs/core/metrics.h"
#include "wild_mvs/io/atomic_file.h"
#include "wild_mvs/io/dataset.h"
#include "wild_mvs/io/depth_map_io.h"
#include "wild_mvs/io/ground_truth.h"
#include "wild_mvs/io/metrics_json.h"
#include "wild_mvs/io/ply.h"

namespace wild_mvs {
namespace cli {
namespace {

namespace fs = std::filesystem;

std::vector<double> ParseList(const Args& args, const std::string& flag,
                              const std::vector<double>& fallback) {
  if (!args.Has(flag)) return fallback;
  std::vector<double> out;
  for (const std::string& item : SplitList(args.Get(flag))) {
    double v = 0;
    try {
      v = ParseDouble(item, "option --" + flag);
    } catch (const Error& e) {
      throw UsageError(e.what());
    }
    if (!(v > 0)) {
      throw UsageError(Msg("option --", flag, ": ", item, " must be > 0"));
    }
    out.push_back(v);
  }
  if (out.empty()) throw UsageError(Msg("option --", flag, " is empty"));
  return out;
}

void WriteJson(const Args& args, const std::string& json) {
  if (!args.Has("json")) return;
  WriteFileAtomically(args.Get("json"),
                      [&](std::ostream& os) { os << json << "\n"; });
}

// Ground-truth depth file DIR/<stem>.pfm or .exr, or "".
std::string FindGtFile(const std::string& dir, const std::string& stem) {
  std::error_code ec;
  for (const char* ext : {".pfm", ".exr", ".PFM", ".EXR"}) {
    const std::string p = dir + "/" + stem + ext;
    if (fs::is_regular_file(p, ec)) return p;
  }
  return "";
}

Scene LoadEvalDataset(const Args& args) {
  DatasetOptions d;
  d.path = args.Get("dataset");
  d.check_images = false;  // cameras only
  d.Check();
  return LoadDataset(d);
}

// The cameras of a reconstruct folder's depth maps: stems, sorted.
std::vector<std::string> DepthMapStems(const std::string& out) {
  std::vector<std::string> stems;
  std::error_code ec;
  Require(fs::is_directory(out + "/cameras", ec), out,
          ": no cameras/ folder (not written by 'wild_mvs reconstruct'?)");
  for (const auto& e : fs::directory_iterator(out + "/cameras")) {
    if (e.path().extension() == ".txt") {
      stems.push_back(e.path().stem().string());
    }
  }
  std::sort(stems.begin(), stems.end());
  Require(!stems.empty(), out, "/cameras: no depth maps");
  return stems;
}

PointCloud ReadCloudOrMeshVertices(const std::string& path) {
  // A mesh's vertices are scored like a cloud.
  return ReadPlyCloud(path);
}

int EvalDepth(const Args& args) {
  Require(args.Has("est"), "eval depth needs --est OUT (a reconstruct folder)");
  Require(args.Has("gt-dir") || args.Has("dataset"),
          "eval depth needs --gt-dir DIR and/or --dataset DATASET");
  const std::string out = args.Get("est");
  DepthMetricsOptions opt;
  opt.relative_thresholds =
      ParseList(args, "rel-thresholds", opt.relative_thresholds);
  opt.absolute_thresholds =
      ParseList(args, "abs-thresholds", opt.absolute_thresholds);
  opt.Check();
  Scene scene;
  const bool has_dataset = args.Has("dataset");
  if (has_dataset) scene = LoadEvalDataset(args);
  const std::string gt_dir = args.Get("gt-dir");
  // fountain-P11's renders need the principal-point adapter.
  const bool fountain_dir =
      !gt_dir.empty() &&
      fs::path(gt_dir).lexically_normal().filename() == "gt_depth_blender_exr";

  // Pool every evaluated pixel (one row) so that the medians are over all
  // views, and score each view too.
  std::vector<cv::Mat> all_est, all_gt;
  int views = 0, missing = 0;
  // --cloud: how many of the correct depth samples the cloud represents.
  const bool with_cloud = args.Has("cloud");
  PointCloud correct;
  std::vector<double> footprint;
  std::printf("%-20s %8s %10s %10s %12s\n", "view", "complete", "rel<1st",
              "abs<1st", "median abs");
  for (const std::string& stem : DepthMapStems(out)) {
    const DepthMapFiles files = ReadDepthMapFiles(out, stem);
    const DepthMap& m = files.map;
    int vi = -1;
    if (has_dataset) {
      for (size_t i = 0; i < scene.views.size(); ++i) {
        if (scene.views[i].Stem() == stem) vi = static_cast<int>(i);
      }
      Require(vi >= 0, out, "/cameras/", stem, ".txt: no view with stem '",
              stem, "' in ", args.Get("dataset"));
    }
    cv::Mat gt;
    if (!gt_dir.empty()) {
      const std::string path = FindGtFile(gt_dir, stem);
      if (path.empty()) {
        ++missing;
        continue;
      }
      if (fountain_dir) {
        gt = FountainGroundTruthDepth(path, m.camera);
      } else {
        // Rendered with the view's own camera at the file's resolution.
        const cv::Mat raw = ReadGroundTruthDepth(path);
        const Camera& base = vi >= 0 ? scene.views[vi].camera : m.camera;
        gt = ResampleDepth(raw, base.Resized(raw.cols, raw.rows), m.camera);
      }
    } else {
      gt = LoadGroundTruthDepthForView(args.Get("dataset"), scene.views[vi],
                                       m.camera);
      if (gt.empty()) {
        ++missing;
        continue;
      }
    }
    if (with_cloud) {
      // The samples within the first relative threshold of the truth, as
      // points with their pixel footprint.
      for (int r = 0; r < m.depth.rows; ++r) {
        for (int c = 0; c < m.depth.cols; ++c) {
          const float z = m.depth.at<float>(r, c), g = gt.at<float>(r, c);
          if (!(z > 0) || !(g > 0) ||
              std::abs(z - g) > opt.relative_thresholds[0] * g)
            continue;
          correct.xyz.push_back(
              m.camera.Backproject(Eigen::Vector2d(c + 0.5, r + 0.5), z)
                  .cast<float>());
          footprint.push_back(z / m.camera.fx);
        }
      }
    }
    const DepthMetrics dm = EvaluateDepth(m.depth, gt, opt);
    std::printf("%-20s %7.1f%% %9.1f%% %9.1f%% %12.5g\n", stem.c_str(),
                100 * dm.completeness, 100 * dm.relative_accuracy[0],
                100 * dm.absolute_accuracy[0], dm.median_abs_error);
    all_est.push_back(m.depth.reshape(1, 1));
    all_gt.push_back(gt.reshape(1, 1));
    ++views;
  }
  Require(views > 0, "no ground truth found for any depth map in ", out,
          gt_dir.empty() ? "" : " (looked for " + gt_dir + "/<stem>.pfm|exr)");
  cv::Mat est, gt;
  cv::hconcat(all_est, est);
  cv::hconcat(all_gt, gt);
  const DepthMetrics total = EvaluateDepth(est, gt, opt);
  std::cout << "\nall " << views << " views"
            << (missing ? Msg(" (", missing, " without ground truth skipped)")
                        : std::string())
            << ":\n"
            << total.ToString();
  std::string json = DepthMetricsJson(total);
  if (with_cloud) {
    const PointCloud cloud = ReadCloudOrMeshVertices(args.Get("cloud"));
    Require(!cloud.empty(), args.Get("cloud"), ": the cloud is empty");
    const std::vector<double> d = NearestDistances(correct, cloud, 0);
    size_t represented = 0;
    for (size_t i = 0; i < d.size(); ++i)
      represented += d[i] <= 2.0 * footprint[i];
    const double frac =
        d.empty() ? 0.0 : static_cast<double>(represented) / d.size();
    std::cout << "cloud " << args.Get("cloud") << ": represents " << represented
              << " of the " << d.size() << " depth samples within "
              << opt.relative_thresholds[0] * 100
              << " % of the truth (a point within 2 pixel footprints): "
              << frac * 100 << " %\n";
    json.pop_back();  // '}'
    json += Msg(", \"cloud_represented\": ", frac,
                ", \"correct_samples\": ", d.size(), "}");
  }
  WriteJson(args, json);
  return 0;
}

int EvalCloud(const Args& args) {
  Require(args.positionals().size() == 3,
          "eval cloud needs EST.ply GT.ply (usage: wild_mvs eval cloud "
          "EST.ply GT.ply [--tau LIST])");
  CloudMetricsOptions opt;
  opt.taus = ParseList(args, "tau", opt.taus);
  if (args.Has("voxel")) opt.voxel_size = args.GetDouble("voxel", 0);
  opt.Check();
  const PointCloud est = ReadCloudOrMeshVertices(args.positional(1));
  const PointCloud gt = ReadCloudOrMeshVertices(args.positional(2));
  Require(!gt.empty(), args.positional(2), ": the ground-truth cloud is empty");
  const CloudMetrics cm = EvaluateCloud(est, gt, opt);
  std::cout << cm.ToString();
  WriteJson(args, CloudMetricsJson(cm));
  return 0;
}

int MakeGtCloud(const Args& args) {
  Require(args.positionals().size() == 2,
          "eval make-gt-cloud needs OUT.ply (usage: wild_mvs eval "
          "make-gt-cloud --dataset DATASET [--gt-dir DIR] OUT.ply)");
  Require(args.Has("dataset"), "eval make-gt-cloud needs --dataset DATASET");
  const int stride = args.GetInt("stride", 2, 1, 1 << 20);
  const Scene scene = LoadEvalDataset(args);
  const std::string gt_dir = args.Get("gt-dir");
  const bool fountain_dir =
      !gt_dir.empty() &&
      fs::path(gt_dir).lexically_normal().filename() == "gt_depth_blender_exr";
  PointCloud cloud;
  int views = 0;
  for (const View& v : scene.views) {
    // Sample every stride-th pixel: the camera at 1/stride resolution.
    const Camera target = v.camera.Scaled(1.0 / stride);
    cv::Mat gt;
    if (!gt_dir.empty()) {
      const std::string path = FindGtFile(gt_dir, v.Stem());
      if (path.empty()) continue;
      if (fountain_dir) {
        gt = FountainGroundTruthDepth(path, target);
      } else {
        const cv::Mat raw = ReadGroundTruthDepth(path);
        gt = ResampleDepth(raw, v.camera.Resized(raw.cols, raw.rows), target);
      }
    } else {
      gt = LoadGroundTruthDepthForView(args.Get("dataset"), v, target);
    }
    if (gt.empty()) continue;
    ++views;
    for (int r = 0; r < gt.rows; ++r) {
      for (int c = 0; c < gt.cols; ++c) {
        const float z = gt.at<float>(r, c);
        if (!(z > 0)) continue;
        const Eigen::Vector3d X =
            target.Backproject(Eigen::Vector2d(c + 0.5, r + 0.5), z);
        cloud.xyz.push_back(X.cast<float>());
      }
    }
  }
  Require(views > 0, "no ground-truth depth found for any view of ",
          args.Get("dataset"));
  if (args.Has("voxel")) {
    cloud = VoxelThin(cloud, args.GetDouble("voxel", 0));
  }
  WritePly(args.positional(1), cloud);
  std::cout << "ground-truth cloud from " << views << " views: " << cloud.size()
            << " points -> " << args.positional(1) << "\n";
  return 0;
}

}  // namespace

int RunEval(const CommandArgs& argv) {
  const CommandSpec spec = EvalSpec();
  Args args(spec, argv);
  if (args.help()) {
    PrintCommandHelp(spec, nullptr, std::cout);
    return 0;
  }
  const std::string mode = args.positional(0);
  if (mode == "depth") {
    if (args.positionals().size() != 1) {
      throw UsageError(Msg("eval depth takes no file arguments (got '",
                           args.positional(1), "'); use --est and --gt-dir"));
    }
    return EvalDepth(args);
  }
  if (mode == "cloud") return EvalCloud(args);
  if (mode == "make-gt-cloud") return MakeGtCloud(args);
  throw UsageError(
      Msg("unknown mode '", mode, "' (modes: depth, cloud, make-gt-cloud)"));
}

}  // namespace cli
}  // namespace wild_mvs
