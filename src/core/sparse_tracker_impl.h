// Copyright wild_mvs authors. Internal to the sparse tracker: the state
// shared by its parts (guided matching, pair selection, union-find tracks,
// re-triangulation, compaction), each in its own file:
//   guided_matching.cpp    GuidedMatches, AreOrientationTwins
//   pair_selection.cpp     Impl::EstimateDepth, Impl::SelectNeighbors
//   track_builder.cpp      Impl::Union, Impl::LinkTwins (Impl::Find inline)
//   retriangulation.cpp    Impl::Rebuild
//   track_compaction.cpp   Impl::Compact
//   sparse_tracker.cpp     options and the public SparseTracker driver
#pragma once

#include <cmath>
#include <map>
#include <utility>
#include <vector>

#include "wild_mvs/core/sparse_tracker.h"

namespace wild_mvs {
namespace sparse_internal {

constexpr double kDeg = M_PI / 180.0;
// Pair selection: a candidate pair needs at least this fraction of sample
// points of the new view's frustum to project into the other image, and
// optical axes at most kMaxPairAngleDeg apart (SIFT rarely matches beyond).
constexpr double kMinOverlap = 0.1;
constexpr double kMaxPairAngleDeg = 75;
// Matching: a match lies within kMaxEpipolarDistance px of the epipolar
// line of the known fundamental matrix in both images and passes Lowe's
// ratio test (best < kRatio * second best) among the compatible candidates;
// bound on the L2 distance of unit-normalised descriptors (0..2);
// a match must be the best in both directions.
constexpr double kMaxEpipolarDistance = 1.5;
constexpr double kRatio = 0.8;
constexpr double kMaxDescriptorDistance = 0.7;
// Re-triangulation: Gauss-Newton iterations; observations removed per track
// at most (worst first, never below min_track_length); the largest ratio of
// a track's feature sizes in the world (SIFT scale x pixel footprint).
constexpr int kRefineIterations = 10;
constexpr int kMaxOutlierRemovals = 3;
constexpr double kMaxScaleRatio = 1.8;

// SIFT reports one keypoint per dominant orientation, at the same position
// and size: such twins in one view are the same point. (Distinct features
// (Distinct features merely close to each other are not twins.)
inline bool AreOrientationTwins(const Features& f, int a, int b) {
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

// Matches the features fa of camera ca to the features fb of camera cb
// along the epipolar geometry (guided matching): candidates within
// kMaxEpipolarDistance of the epipolar line in both directions, Lowe's
// ratio test (orientation twins of the best do not count as second best),
// the descriptor-distance bound.
std::vector<Match> GuidedMatches(const Camera& ca, const Features& fa,
                                 const Camera& cb, const Features& fb);

}  // namespace sparse_internal

struct SparseTracker::Impl {
  using ViewData = sparse_internal::ViewData;
  using PointData = sparse_internal::PointData;

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

  // Union-find (track_builder.cpp).
  int Find(int x) {
    while (parent[x] != x) {
      parent[x] = parent[parent[x]];
      x = parent[x];
    }
    return x;
  }
  // Unites the components of a and b; returns the new root.
  int Union(int a, int b);
  // Links the SIFT orientation twins of the newest view (one point).
  void LinkTwins(const ViewData& v);

  // Pair selection (pair_selection.cpp).
  // Typical depth of the scene seen by `cam` (0 = unknown).
  double EstimateDepth(const Camera& cam) const;
  // Slots of the views to match a new view with camera `cam` against, best
  // first.
  std::vector<int> SelectNeighbors(const Camera& cam) const;

  // Re-triangulates the component with this root (retriangulation.cpp).
  void Rebuild(int root);

  // Forgets the nodes and records of removed views (track_compaction.cpp).
  void Compact();
};

}  // namespace wild_mvs
