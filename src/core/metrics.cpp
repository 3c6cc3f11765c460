// Copyright wild_mvs authors.
#include "wild_mvs/core/metrics.h"

#include <pcl/kdtree/kdtree_flann.h>
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <limits>
#include <unordered_set>

#include "wild_mvs/core/error.h"
#include "wild_mvs/core/thread_pool.h"

namespace wild_mvs {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

bool Valid(float d) { return std::isfinite(d) && d > 0; }

void CheckThresholds(const std::vector<double>& v, const char* name) {
  for (size_t k = 0; k < v.size(); ++k) {
    Require(std::isfinite(v[k]) && v[k] > 0, name, "[", k, "] = ", v[k],
            " must be finite and > 0");
  }
}

// Smallest a such that at least a fraction q of the values is <= a.
// Sorts `v`. 0 for an empty vector.
double Quantile(std::vector<double>* v, double q) {
  if (v->empty()) return 0;
  std::sort(v->begin(), v->end());
  const double pos = std::ceil(q * static_cast<double>(v->size()) - 1e-9);
  const size_t idx = static_cast<size_t>(
      std::clamp(pos - 1, 0.0, static_cast<double>(v->size() - 1)));
  return (*v)[idx];
}

// Median of a sorted vector (mean of the two middle values for even sizes).
double SortedMedian(const std::vector<double>& v) {
  if (v.empty()) return 0;
  const size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

double Mean(const std::vector<double>& v) {
  if (v.empty()) return 0;
  double s = 0;
  for (double x : v) s += x;
  return s / static_cast<double>(v.size());
}

std::string Text(double v) {
  if (!std::isfinite(v)) return v > 0 ? "inf" : "nan";
  char buf[40];
  std::snprintf(buf, sizeof(buf), "%.6g", v);
  return buf;
}

std::string Percent(double f) {
  char buf[40];
  std::snprintf(buf, sizeof(buf), "%.2f %%", 100.0 * f);
  return buf;
}

}  // namespace

// ------------------------------------------------------------ depth maps

void DepthMetricsOptions::Check() const {
  CheckThresholds(relative_thresholds, "eval.relative_thresholds");
  CheckThresholds(absolute_thresholds, "eval.absolute_thresholds");
}

DepthMetrics EvaluateDepth(const cv::Mat& depth, const cv::Mat& gt,
                           const DepthMetricsOptions& options) {
  options.Check();
  Require(depth.type() == CV_32F && gt.type() == CV_32F,
          "EvaluateDepth: depth maps must be CV_32F (got types ", depth.type(),
          " and ", gt.type(), ")");
  Require(depth.size() == gt.size(), "EvaluateDepth: estimate is ", depth.cols,
          "x", depth.rows, " but ground truth is ", gt.cols, "x", gt.rows,
          " (pass both cameras to resample)");
  DepthMetrics m;
  m.relative_thresholds = options.relative_thresholds;
  m.absolute_thresholds = options.absolute_thresholds;
  std::vector<double> abs_err, rel_err;
  for (int r = 0; r < depth.rows; ++r) {
    const float* dp = depth.ptr<float>(r);
    const float* gp = gt.ptr<float>(r);
    for (int c = 0; c < depth.cols; ++c) {
      const bool has_d = Valid(dp[c]), has_g = Valid(gp[c]);
      m.gt_valid += has_g;
      m.estimated += has_d;
      if (has_d && !has_g) ++m.outside_gt;
      if (!has_d || !has_g) continue;
      ++m.evaluated;
      const double e = std::abs(static_cast<double>(dp[c]) - gp[c]);
      abs_err.push_back(e);
      rel_err.push_back(e / gp[c]);
    }
  }
  auto fractions = [&](const std::vector<double>& err,
                       const std::vector<double>& thr, std::vector<double>* acc,
                       std::vector<double>* comp) {
    for (double t : thr) {
      long n = 0;
      for (double e : err) n += e <= t;
      acc->push_back(m.evaluated ? static_cast<double>(n) / m.evaluated : 0);
      comp->push_back(m.gt_valid ? static_cast<double>(n) / m.gt_valid : 0);
    }
  };
  fractions(rel_err, options.relative_thresholds, &m.relative_accuracy,
            &m.relative_completeness);
  fractions(abs_err, options.absolute_thresholds, &m.absolute_accuracy,
            &m.absolute_completeness);
  m.completeness =
      m.gt_valid ? static_cast<double>(m.evaluated) / m.gt_valid : 0;
  m.mean_abs_error = Mean(abs_err);
  double sq = 0;
  for (double e : abs_err) sq += e * e;
  m.rmse = abs_err.empty() ? 0 : std::sqrt(sq / abs_err.size());
  std::sort(abs_err.begin(), abs_err.end());
  std::sort(rel_err.begin(), rel_err.end());
  m.median_abs_error = SortedMedian(abs_err);
  m.median_rel_error = SortedMedian(rel_err);
  return m;
}

cv::Mat ResampleDepth(const cv::Mat& depth, const Camera& from,
                      const Camera& to) {
  Require(depth.type() == CV_32F, "ResampleDepth: depth must be CV_32F");
  Require(depth.cols == from.width && depth.rows == from.height,
          "ResampleDepth: depth is ", depth.cols, "x", depth.rows,
          " but its camera is ", from.width, "x", from.height);
  Require((from.R - to.R).norm() < 1e-6 && (from.t - to.t).norm() < 1e-6,
          "ResampleDepth: the cameras have different poses (not the same "
          "view)");
  Require(to.width > 0 && to.height > 0 && to.fx > 0 && to.fy > 0 &&
              from.fx > 0 && from.fy > 0,
          "ResampleDepth: invalid camera");
  cv::Mat out(to.height, to.width, CV_32F, cv::Scalar(0));
  for (int r = 0; r < to.height; ++r) {
    float* op = out.ptr<float>(r);
    const double y = ((r + 0.5) - to.cy) / to.fy * from.fy + from.cy;
    for (int c = 0; c < to.width; ++c) {
      const double x = ((c + 0.5) - to.cx) / to.fx * from.fx + from.cx;
      if (x < 0 || y < 0 || x >= from.width || y >= from.height) continue;
      // Bilinear in inverse depth over the 4 surrounding pixel centres.
      const double gx = x - 0.5, gy = y - 0.5;
      const int c0 = static_cast<int>(std::floor(gx)),
                r0 = static_cast<int>(std::floor(gy));
      bool ok =
          c0 >= 0 && r0 >= 0 && c0 + 1 < from.width && r0 + 1 < from.height;
      if (ok) {
        const double fx = gx - c0, fy = gy - r0;
        const float d00 = depth.at<float>(r0, c0),
                    d01 = depth.at<float>(r0, c0 + 1),
                    d10 = depth.at<float>(r0 + 1, c0),
                    d11 = depth.at<float>(r0 + 1, c0 + 1);
        ok = Valid(d00) && Valid(d01) && Valid(d10) && Valid(d11);
        if (ok) {
          const float lo = std::min({d00, d01, d10, d11});
          const float hi = std::max({d00, d01, d10, d11});
          ok = hi <= 1.01f * lo;
        }
        if (ok) {
          const double inv = (1 - fy) * ((1 - fx) / d00 + fx / d01) +
                             fy * ((1 - fx) / d10 + fx / d11);
          op[c] = static_cast<float>(1.0 / inv);
          continue;
        }
      }
      const int nc = std::min(from.width - 1, static_cast<int>(x));
      const int nr = std::min(from.height - 1, static_cast<int>(y));
      const float d = depth.at<float>(nr, nc);
      op[c] = Valid(d) ? d : 0.f;
    }
  }
  return out;
}

DepthMetrics EvaluateDepth(const cv::Mat& depth, const Camera& camera,
                           const cv::Mat& gt, const Camera& gt_camera,
                           const DepthMetricsOptions& options) {
  Require(depth.cols == camera.width && depth.rows == camera.height,
          "EvaluateDepth: estimate is ", depth.cols, "x", depth.rows,
          " but its camera is ", camera.width, "x", camera.height);
  if (depth.size() == gt.size() && (camera.K() - gt_camera.K()).norm() < 1e-9)
    return EvaluateDepth(depth, gt, options);
  return EvaluateDepth(depth, ResampleDepth(gt, gt_camera, camera), options);
}

std::string DepthMetrics::ToString() const {
  std::string s;
  s += "pixels: ground truth " + std::to_string(gt_valid) + ", estimated " +
       std::to_string(estimated) + ", both " + std::to_string(evaluated) +
       ", estimated without ground truth " + std::to_string(outside_gt) + "\n";
  s += "completeness: " + Percent(completeness) + "\n";
  s += "median abs error: " + Text(median_abs_error) +
       ", median rel error: " + Text(median_rel_error) +
       ", mean abs error: " + Text(mean_abs_error) + ", rmse: " + Text(rmse) +
       "\n";
  for (size_t k = 0; k < relative_thresholds.size(); ++k)
    s += "within " + Percent(relative_thresholds[k]) +
         " relative: " + Percent(relative_accuracy[k]) + " of estimated, " +
         Percent(relative_completeness[k]) + " of ground truth\n";
  for (size_t k = 0; k < absolute_thresholds.size(); ++k)
    s += "within " + Text(absolute_thresholds[k]) +
         " absolute: " + Percent(absolute_accuracy[k]) + " of estimated, " +
         Percent(absolute_completeness[k]) + " of ground truth\n";
  return s;
}

// ------------------------------------------------------------ clouds

void CloudMetricsOptions::Check() const {
  CheckThresholds(taus, "eval.taus");
  Require(accuracy_fraction > 0 && accuracy_fraction <= 1,
          "eval.accuracy_fraction = ", accuracy_fraction, " must be in (0, 1]");
  Require(std::isfinite(voxel_size) && voxel_size >= 0,
          "eval.voxel_size = ", voxel_size, " must be >= 0");
}

PointCloud VoxelThin(const PointCloud& cloud, double voxel) {
  if (!(voxel > 0)) return cloud;
  struct KeyHash {
    size_t operator()(const Eigen::Vector3i& k) const {
      return (static_cast<size_t>(static_cast<uint32_t>(k.x())) * 73856093u) ^
             (static_cast<size_t>(static_cast<uint32_t>(k.y())) * 19349663u) ^
             (static_cast<size_t>(static_cast<uint32_t>(k.z())) * 83492791u);
    }
  };
  struct KeyEq {
    bool operator()(const Eigen::Vector3i& a, const Eigen::Vector3i& b) const {
      return a == b;
    }
  };
  std::unordered_set<Eigen::Vector3i, KeyHash, KeyEq> seen;
  seen.reserve(cloud.size());
  PointCloud out;
  for (size_t i = 0; i < cloud.size(); ++i) {
    const Eigen::Vector3f& p = cloud.xyz[i];
    const Eigen::Vector3i key(static_cast<int>(std::floor(p.x() / voxel)),
                              static_cast<int>(std::floor(p.y() / voxel)),
                              static_cast<int>(std::floor(p.z() / voxel)));
    if (!seen.insert(key).second) continue;
    out.xyz.push_back(p);
    if (cloud.has_normal()) out.normal.push_back(cloud.normal[i]);
    if (cloud.has_rgb()) out.rgb.push_back(cloud.rgb[i]);
    if (cloud.has_confidence()) out.confidence.push_back(cloud.confidence[i]);
    if (cloud.has_support()) out.support.push_back(cloud.support[i]);
  }
  return out;
}

std::vector<double> NearestDistances(const PointCloud& query,
                                     const PointCloud& reference,
                                     int num_threads) {
  std::vector<double> dist(query.size(), kInf);
  if (reference.empty() || query.empty()) return dist;
  auto cloud = std::make_shared<pcl::PointCloud<pcl::PointXYZ>>();
  cloud->reserve(reference.size());
  for (size_t i = 0; i < reference.size(); ++i) {
    const Eigen::Vector3f& p = reference.xyz[i];
    Require(p.allFinite(), "NearestDistances: reference point ", i,
            " is not finite");
    cloud->push_back(pcl::PointXYZ(p.x(), p.y(), p.z()));
  }
  pcl::KdTreeFLANN<pcl::PointXYZ> tree;
  tree.setInputCloud(cloud);
  for (size_t i = 0; i < query.size(); ++i)
    Require(query.xyz[i].allFinite(), "NearestDistances: query point ", i,
            " is not finite");
  const int chunk = 4096;
  const int chunks = static_cast<int>((query.size() + chunk - 1) / chunk);
  ThreadPool pool(num_threads);
  pool.ParallelFor(chunks, [&](int b) {
    std::vector<int> idx(1);
    std::vector<float> sq(1);
    const size_t end =
        std::min(query.size(), static_cast<size_t>(b + 1) * chunk);
    for (size_t i = static_cast<size_t>(b) * chunk; i < end; ++i) {
      const Eigen::Vector3f& q = query.xyz[i];
      if (tree.nearestKSearch(pcl::PointXYZ(q.x(), q.y(), q.z()), 1, idx, sq) <
          1)
        continue;
      // Exact distance in double from the returned neighbour.
      dist[i] =
          (q.cast<double>() - reference.xyz[idx[0]].cast<double>()).norm();
    }
  });
  return dist;
}

CloudMetrics EvaluateCloud(const PointCloud& reconstruction,
                           const PointCloud& gt,
                           const CloudMetricsOptions& options) {
  options.Check();
  Require(!gt.empty(), "EvaluateCloud: the ground-truth cloud is empty");
  const PointCloud rec = VoxelThin(reconstruction, options.voxel_size);
  const PointCloud ref = VoxelThin(gt, options.voxel_size);
  CloudMetrics m;
  m.reconstruction_points = static_cast<long>(rec.size());
  m.gt_points = static_cast<long>(ref.size());
  m.accuracy_fraction = options.accuracy_fraction;
  m.taus = options.taus;
  std::vector<double> d_rec = NearestDistances(rec, ref, options.num_threads);
  std::vector<double> d_gt = NearestDistances(ref, rec, options.num_threads);
  for (double tau : options.taus) {
    long np = 0, nr = 0;
    for (double d : d_rec) np += d <= tau;
    for (double d : d_gt) nr += d <= tau;
    const double p = rec.empty() ? 0 : static_cast<double>(np) / rec.size();
    const double r = static_cast<double>(nr) / ref.size();
    m.precision.push_back(p);
    m.recall.push_back(r);
    m.fscore.push_back(p + r > 0 ? 2 * p * r / (p + r) : 0);
  }
  if (rec.empty()) {
    m.accuracy = m.mean_accuracy = m.median_accuracy = kInf;
    m.completeness_distance = m.mean_completeness = m.median_completeness =
        kInf;
    return m;
  }
  m.mean_accuracy = Mean(d_rec);
  m.mean_completeness = Mean(d_gt);
  m.accuracy = Quantile(&d_rec, options.accuracy_fraction);  // sorts
  m.median_accuracy = SortedMedian(d_rec);
  m.completeness_distance = Quantile(&d_gt, options.accuracy_fraction);
  m.median_completeness = SortedMedian(d_gt);
  return m;
}

std::string CloudMetrics::ToString() const {
  std::string s;
  s += "points: reconstruction " + std::to_string(reconstruction_points) +
       ", ground truth " + std::to_string(gt_points) + "\n";
  s += "accuracy (" + Percent(accuracy_fraction) +
       " of points within): " + Text(accuracy) + "  (mean " +
       Text(mean_accuracy) + ", median " + Text(median_accuracy) + ")\n";
  s += "completeness distance (" + Percent(accuracy_fraction) +
       " of ground truth within): " + Text(completeness_distance) + "  (mean " +
       Text(mean_completeness) + ", median " + Text(median_completeness) +
       ")\n";
  for (size_t k = 0; k < taus.size(); ++k)
    s += "tau " + Text(taus[k]) + ": precision " + Percent(precision[k]) +
         ", recall/completeness " + Percent(recall[k]) + ", F-score " +
         Percent(fscore[k]) + "\n";
  return s;
}

bool AgreesWithDepthMap(const Eigen::Vector3d& X, const DepthMap& map,
                        double rel_tolerance) {
  Eigen::Vector2d px;
  if (!map.camera.Project(X, &px) || !map.camera.InImage(px)) return false;
  const int x = static_cast<int>(px.x()), y = static_cast<int>(px.y());
  if (x < 0 || y < 0 || x >= map.width() || y >= map.height()) return false;
  const float d = map.depth.at<float>(y, x);
  const double z = map.camera.Depth(X);
  return d > 0 && std::abs(d - z) <= rel_tolerance * z;
}

}  // namespace wild_mvs
