// Copyright wild_mvs authors. Re-triangulation of the sparse tracker:
// the point of a track (conflicts, outlier removal, scale and angle tests).
#include <algorithm>
#include <limits>

#include "sparse_tracker_impl.h"
#include "wild_mvs/core/triangulation.h"

namespace wild_mvs {

using sparse_internal::AreOrientationTwins;
using sparse_internal::kDeg;
using sparse_internal::kMaxOutlierRemovals;
using sparse_internal::kMaxScaleRatio;
using sparse_internal::kRefineIterations;

namespace {

Eigen::Vector3f MeanColour(const Eigen::Vector3f& sum, size_t n) {
  return n ? Eigen::Vector3f(sum / (255.0f * n))
           : Eigen::Vector3f(0.5f, 0.5f, 0.5f);
}

}  // namespace

// Re-triangulates the component with this root.
void SparseTracker::Impl::Rebuild(int root) {
  auto mit = members.find(root);
  if (mit == members.end()) {
    points.erase(root);
    return;
  }
  PointData pd;
  // Per view, the distinct features of the component (SIFT orientation
  // twins at the same position count once).
  std::map<int, std::vector<int>> by_slot;
  std::vector<int> sorted = mit->second;
  std::sort(sorted.begin(), sorted.end());  // deterministic twin choice
  for (int n : sorted) {
    const int s = node_slot[n];
    if (s < 0 || views[s].removed) continue;
    const ViewData& v = views[s];
    std::vector<int>& list = by_slot[s];
    bool twin = false;
    for (int m : list) {
      twin =
          twin || AreOrientationTwins(v.features, n - v.offset, m - v.offset);
    }
    if (!twin) list.push_back(n);
  }
  std::vector<int> nodes;
  std::vector<int> conflicting;  // slots with several distinct features
  for (const auto& kv : by_slot) {
    if (kv.second.size() == 1) {
      nodes.push_back(kv.second[0]);
    } else {
      conflicting.push_back(kv.first);
    }
  }
  if (!conflicting.empty()) {  // a wrong match joined two points
    pd.conflict = true;
    points[root] = pd;
    return;
  }
  if (static_cast<int>(nodes.size()) < opt.min_track_length) {
    points[root] = pd;
    return;
  }
  std::sort(nodes.begin(), nodes.end(), [this](int x, int y) {
    return views[node_slot[x]].id < views[node_slot[y]].id;
  });
  std::vector<TriangulationInput> obs;
  for (int n : nodes) {
    const ViewData& v = views[node_slot[n]];
    obs.push_back({&v.camera, v.features.xy[n - v.offset].cast<double>()});
  }
  Eigen::Vector3d X;
  bool ok = Triangulate(obs, &X, kRefineIterations);
  std::vector<double> err(obs.size());
  for (int removal = 0; ok; ++removal) {
    size_t worst = 0;
    for (size_t k = 0; k < obs.size(); ++k) {
      err[k] = ReprojectionError(*obs[k].camera, X, obs[k].xy);
      if (!(err[k] <= err[worst])) worst = k;
    }
    if (err[worst] <= opt.max_reprojection_error) break;
    if (removal >= kMaxOutlierRemovals ||
        static_cast<int>(obs.size()) <= opt.min_track_length) {
      ok = false;
      break;
    }
    obs.erase(obs.begin() + worst);
    nodes.erase(nodes.begin() + worst);
    err.pop_back();
    ok = Triangulate(obs, &X, kRefineIterations);
  }
  if (ok) {
    for (const TriangulationInput& o : obs) {
      if (!(o.camera->Depth(X) > 0)) ok = false;
    }
  }
  if (ok) {
    // The feature's size in the world (SIFT scale x pixel footprint at its
    // depth) must agree between the views: a false match along the
    // epipolar line usually pairs blobs of different sizes.
    double lo = std::numeric_limits<double>::infinity(), hi = 0;
    for (size_t k = 0; k < nodes.size(); ++k) {
      const ViewData& v = views[node_slot[nodes[k]]];
      const double sc = v.features.scale[nodes[k] - v.offset];
      const double w = sc * v.camera.PixelFootprint(v.camera.Depth(X));
      lo = std::min(lo, w);
      hi = std::max(hi, w);
    }
    if (lo > 0 && hi > kMaxScaleRatio * lo) ok = false;
  }
  if (ok &&
      MaxTriangulationAngle(obs, X) < opt.min_triangulation_angle_deg * kDeg) {
    ok = false;
  }
  if (!ok) {
    points[root] = pd;
    return;
  }
  pd.valid = true;
  SparsePoint& p = pd.point;
  p.xyz = X;
  Eigen::Vector3f rgb = Eigen::Vector3f::Zero();
  double sum_err = 0;
  for (size_t k = 0; k < nodes.size(); ++k) {
    const ViewData& v = views[node_slot[nodes[k]]];
    const int f = nodes[k] - v.offset;
    Observation o;
    o.view = v.id;
    o.xy = obs[k].xy;
    o.scale = v.features.scale[f];
    p.track.push_back(o);
    if (!v.features.rgb.empty()) rgb += v.features.rgb[f].cast<float>();
    sum_err += err[k];
  }
  p.rgb = MeanColour(rgb, nodes.size());
  p.error = sum_err / nodes.size();
  points[root] = std::move(pd);
}

}  // namespace wild_mvs
