// Copyright wild_mvs authors. Sparse tracks from known poses.
//
// Many inputs have calibrated cameras but no structure-from-motion points
// (Middlebury, Strecha, robot logs); global view selection and region growing
// need them. The tracker detects SIFT features per view, picks a bounded set
// of candidate neighbour views from frustum overlap and baseline, matches
// features along the known epipolar geometry (distance to the epipolar line,
// ratio test among the epipolar-compatible candidates, mutual best match),
// links pairwise matches into multi-view tracks (union-find; a track with two
// features in one view is rejected), triangulates each track (DLT, then
// Gauss-Newton on the reprojection error), and keeps points that reproject
// within a pixel threshold, are seen under a minimum triangulation angle and
// lie in front of every camera that sees them.
//
// Incremental: AddView matches the new view against its candidate
// neighbours among the views already added and extends, merges or creates
// tracks; only the tracks it touched are re-triangulated. The streaming ROS
// node adds one keyframe at a time; the batch ComputeSparseTracks adds the
// views of a Scene in index order (so batch == incremental in that order).
#pragma once

#include <cstddef>
#include <memory>
#include <optional>
#include <unordered_map>
#include <vector>

#include "wild_mvs/core/camera.h"
#include "wild_mvs/core/features.h"
#include "wild_mvs/core/image.h"
#include "wild_mvs/core/option_registry.h"
#include "wild_mvs/core/scene.h"
#include "wild_mvs/core/thread_pool.h"

namespace wild_mvs {

struct TrackerOptions {
  FeatureOptions features;

  // --- Candidate neighbour views ---
  // Each new view is matched against at most this many earlier views, the
  // ones with the best frustum overlap (weighted by triangulation angle).
  int max_neighbors = 8;
  // Typical depth of the scene in scene units, used for the overlap test,
  // > 0. Unset = automatic: median depth of the points already triangulated
  // in the new view's frustum, else the convergence of the optical axes,
  // else a baseline-relative depth sweep.
  std::optional<double> scene_depth;

  // --- Triangulation and filtering ---
  // Observations reprojecting farther than this (pixels) are removed
  // (worst first, a few per track, never below min_track_length); a track
  // that still fails is rejected.
  double max_reprojection_error = 2.0;
  // Largest pairwise angle between the lines of sight must reach this.
  double min_triangulation_angle_deg = 2.0;
  // Tracks shorter than this (views) produce no point.
  int min_track_length = 2;

  // --- Memory ---
  // RemoveView compacts the union-find and the view records once removed
  // features (or views) make up more than half of them, so memory follows
  // the views currently held. The results are identical either way; false
  // only to test that (memory then grows with every view ever added).
  bool compact = true;

  void Check() const;
};
// Registers the fields under `prefix` (option_registry.h), e.g. "tracker".
void RegisterOptions(OptionRegistry* registry, const std::string& prefix,
                     TrackerOptions* options);

// Counters for logs and diagnostics.
struct TrackerStats {
  int views = 0;
  int pairs_matched = 0;
  long long matches = 0;
  long long features = 0;
  int tracks = 0;  // components that received matches (once compacted,
                   // those with a feature in a view still held)
  int conflicting_tracks = 0;  // two distinct features in one view
  int points = 0;              // tracks that passed every filter
};

// Not thread-safe: call its methods from one thread at a time (the
// streaming node serialises AddView/RemoveView/Points with a mutex).
// Memory: descriptors (128 B per feature, capped by features.max_features)
// and union-find nodes (8 B per feature) of the views currently held, plus
// the tracks; with options.compact, removed views cost at most about as much
// again as the held ones (amortised compaction in RemoveView).
class SparseTracker {
 public:
  // `pool` (optional, not owned) parallelises matching inside AddView; call
  // AddView from a thread outside the pool (see ThreadPool::ParallelFor).
  explicit SparseTracker(const TrackerOptions& options,
                         ThreadPool* pool = nullptr);
  ~SparseTracker();
  SparseTracker(const SparseTracker&) = delete;
  SparseTracker& operator=(const SparseTracker&) = delete;

  // Adds a view with precomputed features (ExtractFeatures). `view_index`
  // is the caller's id for the view (its index in the Scene the output is
  // written to); it must be >= 0 and not added before. Matches the view
  // against its candidate neighbours among the views already added and
  // updates the tracks. Throws Error on a bad camera or a reused index.
  void AddView(int view_index, const Camera& camera, Features features);
  // Same, extracting the features from the view's image (core image type:
  // CV_32FC3 linear RGB, of the camera's size).
  void AddView(int view_index, const Camera& camera, const cv::Mat& image);

  // Forgets a view (e.g. a keyframe evicted from a bounded store): frees its
  // descriptors, drops its observations from the tracks and re-triangulates
  // them. No-op when the view is unknown.
  void RemoveView(int view_index);

  bool HasView(int view_index) const;
  // The views `view_index` was matched against when it was added.
  std::vector<int> MatchedNeighbors(int view_index) const;

  // The current points (tracks that pass every filter), in a deterministic
  // order. Observations carry the view index given to AddView, the feature
  // position and its SIFT scale; rgb is the mean sRGB colour of the
  // observations; error the mean reprojection error in pixels.
  std::vector<SparsePoint> Points() const;
  // Replaces scene->points with Points(). Views are referred to by the
  // indices given to AddView, which must be valid indices of scene->views.
  void FillScene(Scene* scene) const;

  TrackerStats Stats() const;
  // Memory held by features, union-find, view records and tracks, in bytes
  // (approximate).
  size_t bytes() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// Batch: sparse tracks for every view of `scene` (its existing points are
// ignored). Features are extracted in parallel over views (on `pool` when
// given, in bounded chunks so at most a few images are held at once), then
// the views are added to a SparseTracker in index order.
std::vector<SparsePoint> ComputeSparseTracks(const Scene& scene,
                                             ImageCache& images,
                                             const TrackerOptions& options,
                                             ThreadPool* pool = nullptr,
                                             TrackerStats* stats = nullptr);

}  // namespace wild_mvs
