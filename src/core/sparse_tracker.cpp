// Copyright wild_mvs authors. Sparse tracks from known poses.
#include "wild_mvs/core/sparse_tracker.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <mutex>
#include <numeric>
#include <set>
#include <utility>

#include "wild_mvs/core/error.h"
#include "wild_mvs/core/triangulation.h"

namespace wild_mvs {

void TrackerOptions::Check() const {
  features.Check();
  Require(max_neighbors >= 1, "tracker.max_neighbors = ", max_neighbors,
          " must be >= 1");
  Require(min_overlap >= 0 && min_overlap <= 1,
          "tracker.min_overlap = ", min_overlap, " must be in [0, 1]");
  Require(max_pair_angle_deg > 0 && max_pair_angle_deg <= 180,
          "tracker.max_pair_angle_deg = ", max_pair_angle_deg,
          " must be in (0, 180]");
  Require(scene_depth >= 0 && std::isfinite(scene_depth),
          "tracker.scene_depth = ", scene_depth, " must be >= 0 (0 = auto)");
  Require(max_epipolar_distance > 0,
          "tracker.max_epipolar_distance = ", max_epipolar_distance,
          " must be > 0");
  Require(ratio > 0 && ratio <= 1, "tracker.ratio = ", ratio,
          " must be in (0, 1]");
  Require(max_descriptor_distance > 0 && max_descriptor_distance <= 2,
          "tracker.max_descriptor_distance = ", max_descriptor_distance,
          " must be in (0, 2]");
  Require(max_reprojection_error > 0,
          "tracker.max_reprojection_error = ", max_reprojection_error,
          " must be > 0");
  Require(max_outlier_removals >= 0,
          "tracker.max_outlier_removals = ", max_outlier_removals,
          " must be >= 0");
  Require(min_triangulation_angle_deg >= 0 && min_triangulation_angle_deg < 90,
          "tracker.min_triangulation_angle_deg = ", min_triangulation_angle_deg,
          " must be in [0, 90)");
  Require(min_track_length >= 2,
          "tracker.min_track_length = ", min_track_length, " must be >= 2");
  Require(max_scale_ratio == 0 || max_scale_ratio >= 1,
          "tracker.max_scale_ratio = ", max_scale_ratio,
          " must be 0 (off) or >= 1");
  Require(refine_iterations >= 0,
          "tracker.refine_iterations = ", refine_iterations, " must be >= 0");
}

void RegisterOptions(OptionRegistry* registry, const std::string& prefix,
                     TrackerOptions* o) {
  auto key = [&prefix](const char* name) {
    return OptionRegistry::Join(prefix, name);
  };
  RegisterOptions(registry, key("features"), &o->features);
  registry
      ->Add(key("max_neighbors"), &o->max_neighbors,
            "match each view against at most this many earlier views")
      .Min(1);
  registry
      ->Add(key("min_overlap"), &o->min_overlap,
            "minimum frustum overlap fraction of a candidate pair")
      .Min(0)
      .Max(1);
  registry
      ->Add(key("max_pair_angle_deg"), &o->max_pair_angle_deg,
            "do not match pairs whose optical axes differ by more (degrees)")
      .Above(0)
      .Max(180);
  registry
      ->Add(key("scene_depth"), &o->scene_depth,
            "typical scene depth for the overlap test, 0 = automatic")
      .Min(0);
  registry
      ->Add(key("max_epipolar_distance"), &o->max_epipolar_distance,
            "accept matches within this distance of the epipolar line (px)")
      .Above(0);
  registry->Add(key("ratio"), &o->ratio, "Lowe's ratio test threshold")
      .Above(0)
      .Max(1);
  registry
      ->Add(key("max_descriptor_distance"), &o->max_descriptor_distance,
            "bound on the L2 distance of unit-normalised descriptors")
      .Above(0)
      .Max(2);
  registry->Add(key("mutual"), &o->mutual,
                "keep a match only when best in both directions");
  registry
      ->Add(key("max_reprojection_error"), &o->max_reprojection_error,
            "remove observations reprojecting farther (px)")
      .Above(0);
  registry
      ->Add(key("max_outlier_removals"), &o->max_outlier_removals,
            "at most this many observations removed per track")
      .Min(0);
  registry
      ->Add(key("min_triangulation_angle_deg"), &o->min_triangulation_angle_deg,
            "a point's largest pairwise viewing angle must reach this (deg)")
      .Min(0)
      .Below(90);
  registry
      ->Add(key("max_scale_ratio"), &o->max_scale_ratio,
            "feature scales of a track may differ by at most this factor, "
            "0 = off")
      .Min(1)
      .OrZero();
  registry->Add(key("resolve_conflicts"), &o->resolve_conflicts,
                "keep the best feature of a view with two in one track (else "
                "reject the track)");
  registry
      ->Add(key("min_track_length"), &o->min_track_length,
            "tracks seen in fewer views produce no point")
      .Min(2);
  registry
      ->Add(key("refine_iterations"), &o->refine_iterations,
            "Gauss-Newton iterations of the triangulation refinement")
      .Min(0);
  // `compact` is a test switch (the results are the same), not an option.
}

namespace {

constexpr double kDeg = M_PI / 180.0;
// SIFT reports one keypoint per dominant orientation, at the same position
// and size: such twins in one view are the same point. (Distinct features
// merely close to each other are not twins.)
bool IsTwin(const Features& f, int a, int b) {
  return (f.xy[a] - f.xy[b]).squaredNorm() <= 1e-4f &&
         std::abs(f.scale[a] - f.scale[b]) <= 0.01f * f.scale[a];
}

struct ViewData {
  int id = -1;
  Camera camera;
  Features features;
  int offset = 0;  // first union-find node of this view (when count > 0)
  int count = 0;   // number of features (nodes)
  bool removed = false;
  std::vector<int> neighbors;  // ids matched against when added
};

struct PointData {
  bool valid = false;
  bool conflict = false;
  SparsePoint point;
};

using Match = std::pair<int, int>;  // (feature in new view, feature in old)

// Matches features of view a to view b along the epipolar geometry.
std::vector<Match> MatchPair(const ViewData& a, const ViewData& b,
                             const TrackerOptions& opt) {
  const Features& fa = a.features;
  const Features& fb = b.features;
  const int na = fa.size(), nb = fb.size();
  std::vector<Match> out;
  if (na == 0 || nb == 0) return out;
  // x_b^T F x_a = 0.
  const Eigen::Matrix3f F = FundamentalMatrix(a.camera, b.camera).cast<float>();
  const float thr = static_cast<float>(opt.max_epipolar_distance);
  std::vector<float> bx(nb), by(nb);
  for (int j = 0; j < nb; ++j) {
    bx[j] = fb.xy[j].x();
    by[j] = fb.xy[j].y();
  }
  // Epipolar lines of b's features in a (F^T x_b), normalised.
  std::vector<Eigen::Vector3f> lines_in_a(nb);
  for (int j = 0; j < nb; ++j) {
    Eigen::Vector3f l = F.transpose() * Eigen::Vector3f(bx[j], by[j], 1.0f);
    const float n = l.head<2>().norm();
    lines_in_a[j] = n > 0 ? Eigen::Vector3f(l / n) : Eigen::Vector3f::Zero();
  }
  // Epipolar-compatible candidates (both directions) with their squared
  // descriptor distances.
  struct Cand {
    int i, j, d;
  };
  std::vector<Cand> cands;
  std::vector<int> band;
  band.reserve(256);
  for (int i = 0; i < na; ++i) {
    const Eigen::Vector2f& p = fa.xy[i];
    Eigen::Vector3f l = F * Eigen::Vector3f(p.x(), p.y(), 1.0f);
    const float n = l.head<2>().norm();
    if (!(n > 0)) continue;
    l /= n;
    const float la = l.x(), lb = l.y(), lc = l.z();
    band.clear();
    for (int j = 0; j < nb; ++j) {
      if (std::abs(la * bx[j] + lb * by[j] + lc) <= thr) band.push_back(j);
    }
    const uint8_t* da = fa.descriptors.ptr<uint8_t>(i);
    for (int j : band) {
      const Eigen::Vector3f& m = lines_in_a[j];
      if (!(std::abs(m.x() * p.x() + m.y() * p.y() + m.z()) <= thr)) continue;
      cands.push_back(
          {i, j,
           DescriptorDistanceSquared(da, fb.descriptors.ptr<uint8_t>(j))});
    }
  }
  // Best and second-best per feature. SIFT reports one keypoint per dominant
  // orientation, so a feature may appear twice at the same position: such a
  // twin of the best candidate is the same physical point and must not fail
  // the ratio test, so the second best is taken among the candidates that
  // are not twins of the best.
  const int kInf = std::numeric_limits<int>::max();
  struct Best {
    int idx = -1, d1 = std::numeric_limits<int>::max(),
        d2 = std::numeric_limits<int>::max();
  };
  std::vector<Best> best_a(na), best_b(nb);
  for (const Cand& c : cands) {
    if (c.d < best_a[c.i].d1) best_a[c.i].d1 = c.d, best_a[c.i].idx = c.j;
    if (c.d < best_b[c.j].d1) best_b[c.j].d1 = c.d, best_b[c.j].idx = c.i;
  }
  for (const Cand& c : cands) {
    Best& ba = best_a[c.i];
    if (c.j != ba.idx && !IsTwin(fb, c.j, ba.idx)) {
      ba.d2 = std::min(ba.d2, c.d);
    }
    Best& bb = best_b[c.j];
    if (c.i != bb.idx && !IsTwin(fa, c.i, bb.idx)) {
      bb.d2 = std::min(bb.d2, c.d);
    }
  }
  const double max_d = opt.max_descriptor_distance * Features::kDescriptorScale;
  const double max_d2 = max_d * max_d;
  const double r2 = opt.ratio * opt.ratio;
  auto passes = [&](const Best& b) {
    if (b.idx < 0 || b.d1 > max_d2) return false;
    return b.d2 == kInf || static_cast<double>(b.d1) < r2 * b.d2;
  };
  for (int i = 0; i < na; ++i) {
    const int j = best_a[i].idx;
    if (!passes(best_a[i])) continue;
    if (opt.mutual && (best_b[j].idx != i || !passes(best_b[j]))) continue;
    out.emplace_back(i, j);
  }
  return out;
}

double Median(std::vector<double> v) {
  if (v.empty()) return 0;
  const size_t m = v.size() / 2;
  std::nth_element(v.begin(), v.begin() + m, v.end());
  return v[m];
}

}  // namespace

struct SparseTracker::Impl {
  TrackerOptions opt;
  ThreadPool* pool = nullptr;
  std::vector<ViewData> views;              // in the order added
  std::map<int, int> slot_of_id;            // view id -> index into views
  std::vector<int> parent;                  // union-find over features
  std::vector<int> node_slot;               // view slot of each node, -1 for
                                            // a kept root of a removed view
  std::map<int, std::vector<int>> members;  // root -> nodes (size >= 2)
  // root -> nodes of removed views dropped from members by Compact(): they
  // still count in the component's size (union by size), so that compaction
  // changes no later union and no result.
  std::map<int, int> dropped;
  std::map<int, PointData> points;  // root -> triangulated track
  int pairs_matched = 0;
  long long matches = 0;
  // Since the last Compact(): nodes and records of removed views.
  long long removed_nodes = 0;
  int removed_views = 0;

  int Find(int x) {
    while (parent[x] != x) {
      parent[x] = parent[parent[x]];
      x = parent[x];
    }
    return x;
  }

  // Unites the components of a and b; returns the new root.
  int Union(int a, int b) {
    int ra = Find(a), rb = Find(b);
    if (ra == rb) return ra;
    auto size_of = [this](int r) {
      auto it = members.find(r);
      auto dt = dropped.find(r);
      return (it == members.end() ? size_t{1} : it->second.size()) +
             (dt == dropped.end() ? size_t{0} : size_t(dt->second));
    };
    // Larger component stays root; ties to the smaller index.
    const size_t sa = size_of(ra), sb = size_of(rb);
    if (sa < sb || (sa == sb && rb < ra)) std::swap(ra, rb);
    std::vector<int>& into = members[ra];
    if (into.empty()) into.push_back(ra);
    auto it = members.find(rb);
    if (it == members.end()) {
      into.push_back(rb);
    } else {
      into.insert(into.end(), it->second.begin(), it->second.end());
      members.erase(it);
    }
    auto dt = dropped.find(rb);
    if (dt != dropped.end()) {
      dropped[ra] += dt->second;
      dropped.erase(dt);
    }
    points.erase(rb);
    parent[rb] = ra;
    return ra;
  }

  // Typical depth of the scene seen by `cam` (0 = unknown).
  double EstimateDepth(const Camera& cam) const {
    if (opt.scene_depth > 0) return opt.scene_depth;
    std::vector<double> depths;
    for (const auto& kv : points) {
      if (!kv.second.valid) continue;
      Eigen::Vector2d px;
      const Eigen::Vector3d& X = kv.second.point.xyz;
      if (cam.Project(X, &px) && cam.InImage(px))
        depths.push_back(cam.Depth(X));
    }
    if (depths.size() >= 20) return Median(depths);
    // Convergence of the optical axes.
    depths.clear();
    const Eigen::Vector3d c0 = cam.Center(), d0 = cam.ViewDirection();
    for (const ViewData& v : views) {
      if (v.removed) continue;
      const Eigen::Vector3d c1 = v.camera.Center(),
                            d1 = v.camera.ViewDirection();
      const double b = d0.dot(d1);
      const double den = 1 - b * b;
      if (den < std::pow(std::sin(1.0 * kDeg), 2)) continue;  // ~parallel
      const Eigen::Vector3d w = c0 - c1;
      const double s = (b * d1.dot(w) - d0.dot(w)) / den;
      const double t = (d1.dot(w) - b * d0.dot(w)) / den;
      if (s > 0 && t > 0) depths.push_back(s);
    }
    return depths.empty() ? 0 : Median(depths);
  }

  // Fraction of sample points of cam's frustum (image grid x depths) that
  // project into other's image in front of it.
  static double Overlap(const Camera& cam, const Camera& other,
                        const std::vector<double>& depths) {
    constexpr int kGx = 8, kGy = 6;
    int in = 0, total = 0;
    for (double d : depths) {
      for (int gy = 0; gy < kGy; ++gy) {
        for (int gx = 0; gx < kGx; ++gx) {
          const Eigen::Vector2d px((gx + 0.5) * cam.width / kGx,
                                   (gy + 0.5) * cam.height / kGy);
          Eigen::Vector2d q;
          ++total;
          if (other.Project(cam.Backproject(px, d), &q) && other.InImage(q)) {
            ++in;
          }
        }
      }
    }
    return total ? static_cast<double>(in) / total : 0.0;
  }

  std::vector<int> SelectNeighbors(const Camera& cam) const {
    const double depth = EstimateDepth(cam);
    const Eigen::Vector3d c = cam.Center();
    const double min_angle = opt.min_triangulation_angle_deg * kDeg;
    std::vector<std::pair<double, int>> scored;  // (-score, slot)
    for (size_t s = 0; s < views.size(); ++s) {
      const ViewData& v = views[s];
      if (v.removed) continue;
      const double axis_angle = std::acos(std::min(
          1.0,
          std::max(-1.0, cam.ViewDirection().dot(v.camera.ViewDirection()))));
      if (axis_angle > opt.max_pair_angle_deg * kDeg) continue;
      const double b = (v.camera.Center() - c).norm();
      if (!(b > 0)) continue;
      double score = 0;
      if (depth > 0) {
        const double overlap =
            Overlap(cam, v.camera,
                    {0.5 * depth, std::sqrt(0.5) * depth, depth,
                     std::sqrt(2.0) * depth, 2 * depth});
        if (overlap < opt.min_overlap) continue;
        const Eigen::Vector3d X = cam.Backproject(
            Eigen::Vector2d(0.5 * cam.width, 0.5 * cam.height), depth);
        const double angle = TriangulationAngle(c, v.camera.Center(), X);
        // Too small an angle at the typical depth: only far-off structure
        // would pass the angle filter.
        if (angle < 0.5 * min_angle) continue;
        score = overlap * std::min(1.0, angle / (10 * kDeg));
      } else {
        // Unknown depth: sweep the depths at which the pair's triangulation
        // angle lies between ~60 degrees and the minimum angle.
        const double far = b / std::tan(std::max(min_angle, 0.5 * kDeg));
        std::vector<double> depths;
        for (double d = b; d <= far * 1.0001; d *= 2) depths.push_back(d);
        score = Overlap(cam, v.camera, depths);
        if (score < opt.min_overlap) continue;
      }
      scored.emplace_back(-score, static_cast<int>(s));
    }
    std::sort(scored.begin(), scored.end());
    std::vector<int> slots;
    for (size_t k = 0;
         k < scored.size() && static_cast<int>(k) < opt.max_neighbors; ++k) {
      slots.push_back(scored[k].second);
    }
    return slots;
  }

  // Re-triangulates the component with this root.
  void Rebuild(int root) {
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
        twin = twin || IsTwin(v.features, n - v.offset, m - v.offset);
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
    if (!conflicting.empty()) {
      pd.conflict = true;
      if (!opt.resolve_conflicts ||
          static_cast<int>(nodes.size()) < opt.min_track_length) {
        points[root] = pd;
        return;
      }
      // Point from the unambiguous views; in each conflicting view keep the
      // feature that reprojects best, if within the error bound.
      std::vector<TriangulationInput> clean;
      for (int n : nodes) {
        const ViewData& v = views[node_slot[n]];
        clean.push_back(
            {&v.camera, v.features.xy[n - v.offset].cast<double>()});
      }
      Eigen::Vector3d Xc;
      if (!Triangulate(clean, &Xc, opt.refine_iterations)) {
        points[root] = pd;
        return;
      }
      for (int s : conflicting) {
        const ViewData& v = views[s];
        int best = -1;
        double best_err = opt.max_reprojection_error;
        for (int n : by_slot[s]) {
          const double e = ReprojectionError(
              v.camera, Xc, v.features.xy[n - v.offset].cast<double>());
          if (e <= best_err) best_err = e, best = n;
        }
        if (best >= 0) nodes.push_back(best);
      }
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
    bool ok = Triangulate(obs, &X, opt.refine_iterations);
    std::vector<double> err(obs.size());
    for (int removal = 0; ok; ++removal) {
      size_t worst = 0;
      for (size_t k = 0; k < obs.size(); ++k) {
        err[k] = ReprojectionError(*obs[k].camera, X, obs[k].xy);
        if (!(err[k] <= err[worst])) worst = k;
      }
      if (err[worst] <= opt.max_reprojection_error) break;
      if (removal >= opt.max_outlier_removals ||
          static_cast<int>(obs.size()) <= opt.min_track_length) {
        ok = false;
        break;
      }
      obs.erase(obs.begin() + worst);
      nodes.erase(nodes.begin() + worst);
      err.pop_back();
      ok = Triangulate(obs, &X, opt.refine_iterations);
    }
    if (ok) {
      for (const TriangulationInput& o : obs) {
        if (!(o.camera->Depth(X) > 0)) ok = false;
      }
    }
    if (ok && opt.max_scale_ratio > 0) {
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
      if (lo > 0 && hi > opt.max_scale_ratio * lo) ok = false;
    }
    if (ok && MaxTriangulationAngle(obs, X) <
                  opt.min_triangulation_angle_deg * kDeg) {
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

  // Forgets the nodes and records of removed views. A node is kept when its
  // view is held or when it is the root of a component with a held node
  // (the root's index orders Points() and breaks union ties); kept nodes are
  // renumbered in their old order and every decision of the tracker depends
  // only on that order and on component sizes (kept in `dropped`), so the
  // results are those without compaction. Components without a held node
  // (their points are invalid) are dropped.
  void Compact() {
    const int n = static_cast<int>(parent.size());
    std::vector<int> root(n);
    for (int i = 0; i < n; ++i) root[i] = Find(i);
    auto held = [this](int i) {
      return node_slot[i] >= 0 && !views[node_slot[i]].removed;
    };
    std::vector<char> keep(n, 0);
    for (int i = 0; i < n; ++i) {
      if (held(i)) keep[i] = keep[root[i]] = 1;
    }
    std::vector<int> new_index(n, -1);
    int kept = 0;
    for (int i = 0; i < n; ++i) {
      if (keep[i]) new_index[i] = kept++;
    }
    std::vector<int> new_slot(views.size(), -1);
    std::vector<ViewData> new_views;
    new_views.reserve(views.size() - removed_views);
    for (size_t s = 0; s < views.size(); ++s) {
      if (views[s].removed) continue;
      new_slot[s] = static_cast<int>(new_views.size());
      new_views.push_back(std::move(views[s]));
      ViewData& v = new_views.back();
      v.offset = v.count > 0 ? new_index[v.offset] : 0;
    }
    std::vector<int> new_parent(kept), new_node_slot(kept);
    for (int i = 0; i < n; ++i) {
      if (!keep[i]) continue;
      new_parent[new_index[i]] = new_index[root[i]];
      new_node_slot[new_index[i]] = held(i) ? new_slot[node_slot[i]] : -1;
    }
    std::map<int, std::vector<int>> new_members;
    std::map<int, int> new_dropped;
    for (auto& kv : members) {
      if (!keep[kv.first]) continue;
      std::vector<int> list;
      for (int m : kv.second) {
        if (keep[m]) list.push_back(new_index[m]);
      }
      const int r = new_index[kv.first];
      auto dt = dropped.find(kv.first);
      const int d = static_cast<int>(kv.second.size() - list.size()) +
                    (dt == dropped.end() ? 0 : dt->second);
      if (d > 0) new_dropped[r] = d;
      new_members[r] = std::move(list);
    }
    std::map<int, PointData> new_points;
    for (auto& kv : points) {
      if (keep[kv.first]) {
        new_points[new_index[kv.first]] = std::move(kv.second);
      }
    }
    for (auto& kv : slot_of_id) kv.second = new_slot[kv.second];
    views = std::move(new_views);
    parent = std::move(new_parent);
    node_slot = std::move(new_node_slot);
    members = std::move(new_members);
    dropped = std::move(new_dropped);
    points = std::move(new_points);
    removed_nodes = 0;
    removed_views = 0;
  }

  static Eigen::Vector3f MeanColour(const Eigen::Vector3f& sum, size_t n) {
    return n ? Eigen::Vector3f(sum / (255.0f * n))
             : Eigen::Vector3f(0.5f, 0.5f, 0.5f);
  }
};

SparseTracker::SparseTracker(const TrackerOptions& options, ThreadPool* pool)
    : impl_(new Impl) {
  options.Check();
  impl_->opt = options;
  impl_->pool = pool;
}

SparseTracker::~SparseTracker() = default;

void SparseTracker::AddView(int view_index, const Camera& camera,
                            const cv::Mat& image) {
  Require(!image.empty(), "SparseTracker::AddView: view ", view_index,
          " has an empty image");
  Require(image.cols == camera.width && image.rows == camera.height,
          "SparseTracker::AddView: view ", view_index, " image is ", image.cols,
          "x", image.rows, " but its camera is ", camera.width, "x",
          camera.height);
  AddView(view_index, camera, ExtractFeatures(image, impl_->opt.features));
}

void SparseTracker::AddView(int view_index, const Camera& camera,
                            Features features) {
  Impl& m = *impl_;
  Require(view_index >= 0, "SparseTracker::AddView: view index ", view_index,
          " must be >= 0");
  Require(!m.slot_of_id.count(view_index), "SparseTracker::AddView: view ",
          view_index, " was already added");
  camera.Validate(Msg("SparseTracker::AddView view ", view_index));
  const int n = features.size();
  Require(static_cast<int>(features.scale.size()) == n &&
              (features.rgb.empty() ||
               static_cast<int>(features.rgb.size()) == n) &&
              (n == 0 || (features.descriptors.type() == CV_8U &&
                          features.descriptors.rows == n &&
                          features.descriptors.cols == 128)),
          "SparseTracker::AddView: view ", view_index,
          " has inconsistent features (", n, " positions, ",
          features.descriptors.rows, " descriptors)");
  if (m.opt.features.max_features > 0 && n > m.opt.features.max_features) {
    std::vector<int> keep(m.opt.features.max_features);
    std::iota(keep.begin(), keep.end(), 0);
    features.Select(keep);
  }

  ViewData v;
  v.id = view_index;
  v.camera = camera;
  v.features = std::move(features);
  v.count = v.features.size();
  v.offset = static_cast<int>(m.parent.size());

  const std::vector<int> nb = m.SelectNeighbors(camera);
  std::vector<std::vector<Match>> matches(nb.size());
  auto run = [&](int k) { matches[k] = MatchPair(v, m.views[nb[k]], m.opt); };
  if (m.pool && nb.size() > 1) {
    m.pool->ParallelFor(static_cast<int>(nb.size()), run);
  } else {
    for (size_t k = 0; k < nb.size(); ++k) run(static_cast<int>(k));
  }

  const int slot = static_cast<int>(m.views.size());
  for (int s : nb) v.neighbors.push_back(m.views[s].id);
  m.views.push_back(std::move(v));
  m.slot_of_id[view_index] = slot;
  const ViewData& nv = m.views.back();
  for (int i = 0; i < nv.count; ++i) {
    m.parent.push_back(nv.offset + i);
    m.node_slot.push_back(slot);
  }
  // SIFT orientation twins (features at the same position) are one point:
  // link them so that matches through either twin build one track.
  {
    std::vector<int> by_x(nv.count);
    std::iota(by_x.begin(), by_x.end(), 0);
    const auto& xy = nv.features.xy;
    std::sort(by_x.begin(), by_x.end(), [&xy](int a, int b) {
      return xy[a].x() < xy[b].x() || (xy[a].x() == xy[b].x() && a < b);
    });
    for (size_t a = 0; a < by_x.size(); ++a) {
      for (size_t b = a + 1;
           b < by_x.size() && xy[by_x[b]].x() - xy[by_x[a]].x() <= 0.01f; ++b) {
        if (IsTwin(nv.features, by_x[a], by_x[b])) {
          m.Union(nv.offset + by_x[a], nv.offset + by_x[b]);
        }
      }
    }
  }
  std::vector<int> touched;
  for (size_t k = 0; k < nb.size(); ++k) {
    const ViewData& old = m.views[nb[k]];
    if (!matches[k].empty()) ++m.pairs_matched;
    m.matches += static_cast<long long>(matches[k].size());
    for (const Match& mt : matches[k]) {
      touched.push_back(m.Union(nv.offset + mt.first, old.offset + mt.second));
    }
  }
  std::set<int> roots;
  for (int r : touched) roots.insert(m.Find(r));
  for (int r : roots) m.Rebuild(r);
}

void SparseTracker::RemoveView(int view_index) {
  Impl& m = *impl_;
  auto it = m.slot_of_id.find(view_index);
  if (it == m.slot_of_id.end()) return;
  ViewData& v = m.views[it->second];
  if (v.removed) return;
  v.removed = true;
  std::set<int> roots;
  for (int i = 0; i < v.count; ++i) {
    const int r = m.Find(v.offset + i);
    if (m.members.count(r)) roots.insert(r);
  }
  for (int r : roots) m.Rebuild(r);
  v.features = Features();  // free descriptors; positions no longer needed
  v.neighbors = std::vector<int>();
  m.slot_of_id.erase(it);
  m.removed_nodes += v.count;
  ++m.removed_views;
  // Amortised: compaction costs O(nodes + views) and runs once removed
  // nodes (or records) make up more than half of them.
  if (m.opt.compact &&
      (2 * m.removed_nodes > static_cast<long long>(m.parent.size()) ||
       2 * m.removed_views > static_cast<int>(m.views.size()))) {
    m.Compact();
  }
}

bool SparseTracker::HasView(int view_index) const {
  return impl_->slot_of_id.count(view_index) > 0;
}

std::vector<int> SparseTracker::MatchedNeighbors(int view_index) const {
  auto it = impl_->slot_of_id.find(view_index);
  if (it == impl_->slot_of_id.end()) return {};
  return impl_->views[it->second].neighbors;
}

std::vector<SparsePoint> SparseTracker::Points() const {
  std::vector<SparsePoint> out;
  for (const auto& kv : impl_->points) {
    if (kv.second.valid) out.push_back(kv.second.point);
  }
  return out;
}

void SparseTracker::FillScene(Scene* scene) const {
  std::vector<SparsePoint> pts = Points();
  for (const SparsePoint& p : pts) {
    for (const Observation& o : p.track) {
      Require(o.view >= 0 && o.view < static_cast<int>(scene->views.size()),
              "SparseTracker::FillScene: view index ", o.view,
              " is not a view of the scene (", scene->views.size(), " views)");
    }
  }
  scene->points = std::move(pts);
}

TrackerStats SparseTracker::Stats() const {
  const Impl& m = *impl_;
  TrackerStats s;
  for (const ViewData& v : m.views) {
    if (v.removed) continue;
    ++s.views;
    s.features += v.count;
  }
  s.pairs_matched = m.pairs_matched;
  s.matches = m.matches;
  s.tracks = static_cast<int>(m.points.size());
  for (const auto& kv : m.points) {
    if (kv.second.conflict) ++s.conflicting_tracks;
    if (kv.second.valid) ++s.points;
  }
  return s;
}

size_t SparseTracker::bytes() const {
  const Impl& m = *impl_;
  // Map nodes: key, value and ~32 B of tree links and allocator overhead.
  constexpr size_t kNode = 32;
  size_t b = (m.parent.capacity() + m.node_slot.capacity()) * sizeof(int);
  b += m.views.capacity() * sizeof(ViewData);
  for (const ViewData& v : m.views) {
    b += v.features.bytes() + v.neighbors.capacity() * sizeof(int);
  }
  b += m.slot_of_id.size() * (kNode + 2 * sizeof(int));
  b += m.dropped.size() * (kNode + 2 * sizeof(int));
  for (const auto& kv : m.members) {
    b += kNode + sizeof(kv) + kv.second.capacity() * sizeof(int);
  }
  for (const auto& kv : m.points) {
    b += kNode + sizeof(kv) +
         kv.second.point.track.capacity() * sizeof(Observation);
  }
  return b;
}

std::vector<SparsePoint> ComputeSparseTracks(const Scene& scene,
                                             ImageCache& images,
                                             const TrackerOptions& options,
                                             ThreadPool* pool,
                                             TrackerStats* stats) {
  options.Check();
  SparseTracker tracker(options, pool);
  const int n = static_cast<int>(scene.views.size());
  // Extract in chunks so only a few images / feature sets are held at once.
  const int chunk = pool ? std::max(2, 2 * (pool->size() + 1)) : 1;
  for (int start = 0; start < n; start += chunk) {
    const int count = std::min(chunk, n - start);
    std::vector<Features> feats(count);
    auto extract = [&](int k) {
      const int i = start + k;
      const View& view = scene.views[i];
      std::shared_ptr<const cv::Mat> img = images.Get(i);
      Require(img && !img->empty(), "ComputeSparseTracks: view ", i, " (",
              view.name, ") has no image");
      Require(img->cols == view.camera.width && img->rows == view.camera.height,
              "ComputeSparseTracks: view ", i, " (", view.name, ") image is ",
              img->cols, "x", img->rows, " but its camera is ",
              view.camera.width, "x", view.camera.height);
      feats[k] = ExtractFeatures(*img, options.features);
    };
    if (pool && count > 1) {
      pool->ParallelFor(count, extract);
    } else {
      for (int k = 0; k < count; ++k) extract(k);
    }
    for (int k = 0; k < count; ++k) {
      tracker.AddView(start + k, scene.views[start + k].camera,
                      std::move(feats[k]));
    }
  }
  if (stats) *stats = tracker.Stats();
  return tracker.Points();
}

}  // namespace wild_mvs
