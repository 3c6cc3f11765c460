// Copyright wild_mvs authors. Fusion of per-view depth maps into one point
// cloud with a multi-view geometric consistency check, streaming with
// bounded memory.
//
// Algorithm (docs/ALGORITHM.md section 6; the check COLMAP and OpenMVS use):
//  - A depth sample of view v (pixel with depth > 0 and a finite
//    confidence, not masked, inside the bounding box) is back-projected
//    to a world point X with world normal N. It is checked against every
//    related view u (below): X is projected into u; u's depth d_u at that
//    pixel must agree with X's depth z_u in u (|d_u - z_u| <= depth_tolerance
//    * z_u), the point u sees there must re-project into v within
//    reprojection_tolerance_px of the sample, and u's normal must be within
//    normal_tolerance_deg of N. support = 1 + number of agreeing views.
//  - A sample with support >= min_support is accepted and merged into the
//    cloud through a scale-adaptive spatial hash: cells of size
//    kCellScale * (pixel footprint at the sample's depth), on power-of-two
//    levels; a sample joins an existing point of its level or the two
//    adjacent levels when it lies within that radius and the normals agree,
//    else it starts a new point. Points hold the confidence-weighted mean of
//    position, normal and (linear) colour of their samples, the mean
//    confidence, and support = the largest support of their samples.
//
// Related views of v: the views in v's DepthMap::neighbors plus the views
// that list v as a neighbour, among the views added so far; when a map has
// no neighbours, the views whose cameras see most of v's samples (overlap,
// up to kMaxRelatedViews).
//
// Streaming and incremental (AddView): depth maps come from a provider
// callback and are held in an LRU bounded by map_cache_mb, so memory does not
// grow with views x image size. A view is checked against the related views
// added *before* it. Choice for earlier samples that gain support from a
// later view: samples with too little support are kept as compact *pending*
// samples (world position, normal, colour; 64 bytes each, not the map) in a
// structure bounded by pending_mb (the oldest views' pending samples are
// dropped first). When view v is added, the pending samples of v's related
// views are re-checked against v and promoted into the cloud when they reach
// min_support. Already accepted points are not revisited: the new view's own
// agreeing samples merge into them through the hash. Peak memory is therefore
// map cache + pending bound + the cloud (points and hash).
//
// Determinism: the work inside AddView is parallel over rows / pending
// samples (when a ThreadPool is given) but results are committed in a fixed
// order, so a run is bit-identical with or without a pool. The result depends
// on the order in which views are added (which views exist when a sample is
// checked); FuseDepthMaps(views) equals adding the views in that order.
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <limits>
#include <list>
#include <map>
#include <memory>
#include <opencv2/core.hpp>
#include <optional>
#include <unordered_map>
#include <vector>

#include "wild_mvs/core/block_vector.h"
#include "wild_mvs/core/depth_map.h"
#include "wild_mvs/core/lru_cache.h"
#include "wild_mvs/core/option_registry.h"
#include "wild_mvs/core/point_cloud.h"
#include "wild_mvs/core/thread_pool.h"

namespace wild_mvs {

// Merge radius / hash cell size as a multiple of the pixel footprint at the
// sample's depth.
constexpr double kCellScale = 1.0;
// Related views per view when they come from camera overlap (maps without
// neighbours) and the cap on related views in general.
constexpr int kMaxRelatedViews = 12;

struct FusionOptions {
  // Minimum number of views (the sample's own view included) whose depth
  // maps agree with a sample for it to be kept (COLMAP's min_num_pixels
  // counts the same way).
  int min_support = 3;
  // Relative depth tolerance of the consistency check |d_u - z_u| / z_u
  // (COLMAP max_depth_error = 0.01).
  double depth_tolerance = 0.01;
  // Maximum re-projection error in pixels of the supporting view's point
  // back into the sample's view (COLMAP max_reproj_error = 2).
  double reprojection_tolerance_px = 2.0;
  // Maximum angle between the sample's and the supporter's normals, degrees
  // (COLMAP max_normal_error = 10; MVS normals are noisier, hence 20). Also
  // used when merging samples into one point.
  double normal_tolerance_deg = 20.0;
  // Bounding box in world units (x, y, z); samples outside are ignored.
  // Finite, min <= max where both are set; unset = no bound on that side
  // (the default: no box).
  std::array<std::optional<double>, 3> bbox_min, bbox_max;
  // Budget of the depth-map LRU in megabytes (prepared maps: 20 bytes per
  // pixel). The maps in use by one AddView are held regardless.
  double map_cache_mb = 512;
  // Budget of the pending (not yet supported) samples in megabytes; the
  // oldest views' pending samples are dropped beyond it. 0 = no pending
  // samples (a sample is only checked against views added before it).
  double pending_mb = 256;
  // Joint budget in megabytes of the fusion's own memory: cached maps +
  // pending samples + the cloud (points and spatial hash). When > 0, cached
  // maps are evicted (and read again through the provider when needed) so
  // that the three stay within it: the cloud takes the maps' room as it
  // grows, and the fusion's memory stops growing once the budget is full.
  // Only maps are given up for it (pending samples keep pending_mb, the
  // cloud is the output), so results do not change; beyond it the account
  // is pending + cloud + the maps in use. 0 = no joint budget (the maps have
  // map_cache_mb of their own).
  double memory_mb = 0;

  void Check() const;
};
// Registers the fields under `prefix` (option_registry.h), e.g. "fusion".
void RegisterOptions(OptionRegistry* registry, const std::string& prefix,
                     FusionOptions* options);

// view -> its depth map (may load from disk). For the view being added it
// must return a map (nullptr is an Error); for an earlier view it may return
// nullptr when that map is no longer available (a bounded store): the view
// then just gives no support. Exceptions propagate; AddView leaves the
// fusion unchanged when the provider throws.
using DepthMapProvider =
    std::function<std::shared_ptr<const DepthMap>(int view)>;
// view -> linear RGB CV_32FC3 image (any size; resized to the map when it
// differs). Empty function or empty Mat = no colour (points are grey 0.5).
using ImageProvider = std::function<cv::Mat(int view)>;
// view -> CV_8U mask (0 = ignore pixel; any size, nearest resize). Empty
// function or empty Mat = no mask.
using MaskProvider = std::function<cv::Mat(int view)>;

struct FusionStats {
  int views = 0;               // views added
  size_t samples = 0;          // valid samples seen (after filters)
  size_t accepted = 0;         // samples merged into the cloud
  size_t promoted = 0;         // of them accepted later from pending
  size_t pending = 0;          // samples currently pending
  size_t pending_dropped = 0;  // pending samples dropped by the bound
  size_t points = 0;           // points in the cloud
  size_t map_loads = 0;        // provider calls (cache misses)
  size_t held_map_bytes = 0;   // current bytes of cached maps
  size_t peak_held_map_bytes = 0;
  size_t pending_bytes = 0;  // current bytes of pending samples
  size_t cloud_bytes = 0;    // current bytes of points + spatial hash
  size_t peak_bytes = 0;     // peak of maps + pending + cloud structures
};

class StreamingFusion {
 public:
  // `pool` (optional, not owned) parallelises the work inside AddView.
  StreamingFusion(const FusionOptions& options, DepthMapProvider depth,
                  ImageProvider image = nullptr, MaskProvider mask = nullptr,
                  ThreadPool* pool = nullptr);
  ~StreamingFusion();
  StreamingFusion(const StreamingFusion&) = delete;
  StreamingFusion& operator=(const StreamingFusion&) = delete;

  // Adds one view's depth map: checks it against the related views added
  // before, re-checks their pending samples against it, and merges accepted
  // samples. Throws Error when the view was already added or its map is
  // malformed (sizes, types, camera, mask, image); the fusion is then
  // unchanged (all loading and checks happen before any update).
  void AddView(int view);
  bool HasView(int view) const;
  // No more views: releases the map cache and the pending samples (they can
  // no longer gain support), keeping only the cloud. AddView afterwards
  // throws. Call before taking or writing the cloud at the end of a run.
  void Finish();

  // The current cloud: xyz, unit normal, confidence (mean of the samples),
  // support; rgb (sRGB for display, converted from the linear mean) only
  // when an image provider was given. Point order = creation order
  // (deterministic).
  PointCloud Cloud() const;
  // Points [begin, end) of Cloud() (end <= num_points()): the cloud can be
  // written in chunks without a full copy (WritePlyChunked).
  PointCloud Cloud(size_t begin, size_t end) const;
  size_t num_points() const;
  size_t peak_bytes() const { return stats_.peak_bytes; }
  const FusionStats& stats() const { return stats_; }
  // Bytes currently held (maps + pending + cloud).
  size_t bytes() const;

 private:
  struct Prepared;
  struct Pending;
  struct Accum;
  struct Sample;
  std::shared_ptr<const Prepared> GetMap(int view, bool required);
  std::shared_ptr<const Prepared> Prepare(int view, const DepthMap& m);
  std::vector<int> RelatedViews(int view, const Prepared& map) const;
  void Insert(const Sample& s);
  void TrimPending();
  void UpdatePeak();
  // Bytes the map cache may hold now (map_cache_mb, and within memory_mb
  // what pending samples and the cloud leave).
  size_t MapCap() const;
  void EvictMaps();
  size_t PendingBytes() const;
  size_t CloudBytes() const;

  FusionOptions options_;
  DepthMapProvider depth_;
  ImageProvider image_;
  MaskProvider mask_;
  ThreadPool* pool_;
  double cos_normal_tol_;

  // Views added, in order, with their camera and neighbours.
  struct Added {
    int view;
    Camera camera;
    std::vector<int> neighbors;
  };
  std::vector<Added> added_;
  std::unordered_map<int, size_t> added_index_;
  // u -> the added views whose neighbours include u, in added order.
  std::unordered_map<int, std::vector<int>> listed_by_;

  // Prepared maps, least recently used dropped first (cost: bytes).
  LruCache<int, std::shared_ptr<const Prepared>> maps_;

  // Pending samples per view, in view-added order (oldest first).
  std::list<std::pair<int, std::vector<Pending>>> pending_;
  size_t pending_count_ = 0;

  bool finished_ = false;

  // The cloud: accumulated points (in blocks: no doubling, no copy when it
  // grows) and the spatial hash.
  BlockVector<Accum> points_;
  std::unordered_map<uint64_t, uint32_t> hash_;

  FusionStats stats_;
};

// Batch fusion of `views` in this order with `pool` (may be null): the same
// result as StreamingFusion::AddView over `views` in order.
PointCloud FuseDepthMaps(const std::vector<int>& views,
                         const FusionOptions& options,
                         const DepthMapProvider& depth,
                         const ImageProvider& image = nullptr,
                         const MaskProvider& mask = nullptr,
                         ThreadPool* pool = nullptr,
                         FusionStats* stats = nullptr);

}  // namespace wild_mvs
