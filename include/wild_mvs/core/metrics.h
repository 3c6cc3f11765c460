// Copyright wild_mvs authors. Scores against ground truth: depth maps and
// point clouds (no file I/O; `wild_mvs eval` reads the files).
//
// Depth maps: CV_32F, z along the optical axis, 0 (or NaN / negative) =
// unknown. An estimate may have a different resolution from the ground truth
// (e.g. MVS at half resolution): the ground truth is then resampled to the
// estimate's camera with ResampleDepth before comparing, so every number is
// per pixel of the estimate.
//
// Clouds, as the Middlebury (Seitz et al. 2006) and ETH3D (Schoeps et al.
// 2017) benchmarks define them, with d(p, S) = distance from p to the
// nearest point of S:
//   accuracy      = the distance a such that `accuracy_fraction` (90 %) of
//                   the reconstructed points p have d(p, GT) <= a;
//   completeness  = fraction of GT points g with d(g, R) <= tau (= recall);
//   precision(tau)= fraction of reconstructed points with d(p, GT) <= tau;
//   recall(tau)   = fraction of GT points with d(g, R) <= tau;
//   F(tau)        = 2 P R / (P + R) (0 when P + R = 0).
// Nearest neighbours come from a kd-tree (PCL KdTreeFLANN).
#pragma once

#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "wild_mvs/core/camera.h"
#include "wild_mvs/core/depth_map.h"
#include "wild_mvs/core/point_cloud.h"

namespace wild_mvs {

// ------------------------------------------------------------ depth maps

struct DepthMetricsOptions {
  // Relative thresholds on |d - d_gt| / d_gt.
  std::vector<double> relative_thresholds = {0.01, 0.02, 0.05};
  // Absolute thresholds on |d - d_gt| in scene units (metres for the real
  // datasets: 1, 2, 5 cm).
  std::vector<double> absolute_thresholds = {0.01, 0.02, 0.05};
  // Throws Error naming the option when a threshold is not finite and > 0.
  void Check() const;
};

struct DepthMetrics {
  long gt_valid = 0;    // pixels with a ground-truth depth
  long estimated = 0;   // pixels with an estimated depth
  long evaluated = 0;   // pixels with both
  long outside_gt = 0;  // estimated pixels without ground truth (not scored)
  // evaluated / gt_valid: how much of the ground truth has an estimate.
  double completeness = 0;
  // Over the evaluated pixels (0 when none).
  double median_abs_error = 0;
  double median_rel_error = 0;
  double mean_abs_error = 0;
  double rmse = 0;
  // Per threshold (same order as the options):
  //   *_accuracy[k]: fraction of evaluated pixels within the threshold;
  //   *_completeness[k]: fraction of ground-truth-valid pixels that have an
  //   estimate within the threshold.
  std::vector<double> relative_thresholds, relative_accuracy,
      relative_completeness;
  std::vector<double> absolute_thresholds, absolute_accuracy,
      absolute_completeness;

  // One human-readable line per quantity.
  std::string ToString() const;
  // (JSON: io/metrics_json.h.)
};

// Scores `depth` against `gt`; both of the same size (throws Error naming the
// sizes otherwise).
DepthMetrics EvaluateDepth(const cv::Mat& depth, const cv::Mat& gt,
                           const DepthMetricsOptions& options = {});

// Scores `depth` (seen by `camera`) against `gt` (seen by `gt_camera`), which
// must be the same view (same pose; any resolution and intrinsics): the
// ground truth is first resampled with ResampleDepth.
DepthMetrics EvaluateDepth(const cv::Mat& depth, const Camera& camera,
                           const cv::Mat& gt, const Camera& gt_camera,
                           const DepthMetricsOptions& options = {});

// The multi-view agreement of the "correct sample" rule (bench/run_bench.sh,
// the real-image MVS test): world point X projects inside `map`, which
// holds a depth there (pixel containing the projection) within
// rel_tolerance * z of X's depth z in that view.
bool AgreesWithDepthMap(const Eigen::Vector3d& X, const DepthMap& map,
                        double rel_tolerance);

// Resamples the depth map `depth` of camera `from` to camera `to` of the same
// pose (throws Error when the poses differ by more than 1e-6): each pixel
// centre of `to` is mapped through the intrinsics to `from`'s pixel
// coordinates and sampled by bilinear interpolation of inverse depth (exact
// for planes) when the four neighbours are valid and agree within 1 %,
// otherwise by the nearest pixel (no blending across depth edges). Pixels
// mapping outside `from` get 0.
cv::Mat ResampleDepth(const cv::Mat& depth, const Camera& from,
                      const Camera& to);

// ------------------------------------------------------------ clouds

struct CloudMetricsOptions {
  // Distance thresholds tau for precision, recall and F-score, in scene
  // units. ETH3D uses 1, 2, 5, 10, 20, 50 cm; docs/METHODS.md uses 1, 2, 5 cm.
  std::vector<double> taus = {0.01, 0.02, 0.05};
  // Middlebury accuracy: the distance within which this fraction of the
  // reconstructed points lies (0.9).
  double accuracy_fraction = 0.9;
  // When > 0, both clouds are first thinned to one point per voxel of this
  // size (ETH3D evaluates on voxel-subsampled clouds so that dense regions
  // do not dominate). 0 = use every point.
  double voxel_size = 0;
  // Worker threads for the nearest-neighbour queries (<= 0: all cores).
  int num_threads = 0;
  void Check() const;
};

struct CloudMetrics {
  long reconstruction_points = 0;  // after voxel thinning
  long gt_points = 0;
  double accuracy = 0;  // accuracy_fraction quantile of d(p, GT)
  double accuracy_fraction = 0.9;
  double completeness_distance = 0;               // same quantile of d(g, R)
  double mean_accuracy = 0, median_accuracy = 0;  // of d(p, GT)
  double mean_completeness = 0, median_completeness = 0;  // of d(g, R)
  std::vector<double> taus;
  std::vector<double> precision;  // per tau
  std::vector<double> recall;     // per tau (= completeness at tau)
  std::vector<double> fscore;     // per tau
  const std::vector<double>& completeness() const { return recall; }

  std::string ToString() const;  // (JSON: io/metrics_json.h)
};

// Scores a reconstructed cloud against a ground-truth cloud. Throws Error
// when the ground truth is empty; an empty reconstruction scores precision,
// recall and F = 0 and infinite accuracy (reported as "inf" / null in JSON).
CloudMetrics EvaluateCloud(const PointCloud& reconstruction,
                           const PointCloud& gt,
                           const CloudMetricsOptions& options = {});

// Distance from every query point to the nearest point of `reference`
// (kd-tree; +inf when `reference` is empty).
std::vector<double> NearestDistances(const PointCloud& query,
                                     const PointCloud& reference,
                                     int num_threads = 0);

// One point per occupied voxel of size `voxel` (the first one in input
// order; attributes kept). voxel <= 0 returns the input.
PointCloud VoxelThin(const PointCloud& cloud, double voxel);

}  // namespace wild_mvs
