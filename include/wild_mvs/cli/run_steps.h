// Copyright wild_mvs authors. The stages of `wild_mvs reconstruct`, shared
// with `sparse`, `fuse` and `mesh`: sparse tracks, per-view depth maps
// (resumable), fusion, meshing, and the run record OUT/run.yaml that lets
// `fuse OUT` / `mesh OUT` find the dataset and the options again.
#pragma once

#include <ostream>
#include <string>
#include <vector>

#include "wild_mvs/cli/option_set.h"
#include "wild_mvs/cli/reconstruct_config.h"
#include "wild_mvs/core/geometric_consistency.h"
#include "wild_mvs/core/image.h"
#include "wild_mvs/core/point_cloud.h"
#include "wild_mvs/core/reconstruct_view.h"
#include "wild_mvs/core/scene.h"
#include "wild_mvs/core/stats.h"
#include "wild_mvs/core/thread_pool.h"
#include "wild_mvs/pipeline/file_workspace.h"  // ViewOutputsComplete

namespace wild_mvs {
namespace cli {

// CpuSeconds() and PeakRssMb(): wild_mvs/core/stats.h.

struct SparseSummary {
  size_t points = 0, observations = 0;
  double median_track_length = 0, median_error = 0;
  double seconds = 0;
};
// Replaces scene->points with tracks computed from the known poses
// (ComputeSparseTracks) and logs what happened.
SparseSummary ComputeSceneTracks(Scene* scene, const ReconstructConfig& config,
                                 ThreadPool* pool, std::ostream& log);

struct DepthStageResult {
  int computed = 0, skipped = 0;
  long long samples = 0;  // valid depth samples over all selected views
  // The geometric-consistency filter of the views computed in this run:
  // samples before and kept.
  long long consistency_samples = 0, consistency_kept = 0;
  // Views whose MVS map is in OUT/raw, to be filtered later (filter_now
  // false: a --shard process; `wild_mvs fuse` filters them). They count in
  // computed / skipped, and samples are then before the filter.
  int unfiltered = 0;
  double seconds = 0;
  std::vector<std::string> failures;  // "view: problem"
};
// Depth maps of `views` (in order): skips complete views unless `force`,
// writes depth/normal/confidence/cameras/preview files and log/S.json. A
// view that fails (bad image, ...) is reported in `failures` and the others
// go on; output write errors abort (Error). With the consistency filter
// (ablation.consistency) the MVS maps go to OUT/raw and, when
// `filter_now`, are filtered into OUT at the end; otherwise (a shard, which
// lacks its neighbours' maps) they stay in OUT/raw for FilterPendingViews.
DepthStageResult RunDepthStage(
    const Scene& scene, const std::vector<int>& views, ImageCache& images,
    const ReconstructConfig& config, ThreadPool* pool, const std::string& out,
    bool force, std::ostream& log, bool filter_now = true);

struct FilterStageResult {
  int filtered = 0;
  long long samples = 0, kept = 0;
  std::vector<std::string> failures;
};
// The views of `scene` with a complete raw map in OUT/raw but no complete
// final map in OUT (left by --shard runs), filtered (DepthController) into
// OUT; nothing when the filter is off (AblationOptions::consistency). Throws
// Error listing the views that failed.
FilterStageResult FilterPendingViews(const Scene& scene, const MvsOptions& mvs,
                                     const std::string& out, ThreadPool* pool,
                                     std::ostream& log);

// The sparse tracks of a dataset without sparse points, shared by the runs
// on one OUT: OUT/sparse/tracks.txt (io/sparse_tracks_file.h; the COLMAP
// text model beside it). `fingerprint`: "KEY VALUE" of the options the
// tracks depend on (TracksFingerprint).
std::string SparseTracksPath(const std::string& out);
std::vector<std::string> TracksFingerprint(const OptionSet& options,
                                           const std::string& mask_dir);
// Loads the tracks of an earlier run on `out` into scene->points when they
// were computed for these views and options; returns false (saying why on
// `log` when a file was there) otherwise.
bool LoadSceneTracks(Scene* scene, const std::string& out,
                     const std::vector<std::string>& fingerprint,
                     std::ostream& log);
// ComputeSceneTracks, then writes OUT/sparse (COLMAP text) and the exact
// record OUT/sparse/tracks.txt, each atomically.
SparseSummary ComputeAndSaveSceneTracks(
    Scene* scene, const ReconstructConfig& config, ThreadPool* pool,
    const std::string& out, const std::vector<std::string>& fingerprint,
    std::ostream& log);

struct FuseResult {
  int views = 0;
  size_t points = 0;
  double seconds = 0;
};
// Fuses the depth maps found in `out` for the views of `scene` (scene
// order), streaming them from disk; writes `ply` atomically. `cloud`
// (optional) receives the cloud; without it the cloud is written in chunks
// straight from the fusion (no copy of it is held).
FuseResult RunFuseStage(const Scene& scene, ImageCache* images,
                        const ReconstructConfig& config, ThreadPool* pool,
                        const std::string& out, const std::string& ply,
                        std::ostream& log, PointCloud* cloud = nullptr);

struct MeshResult {
  size_t vertices = 0, faces = 0;
  double seconds = 0;
};
// Reads a fused cloud (binary PLY).
PointCloud LoadFusedCloud(const std::string& path);

// Poisson mesh of `cloud`, trimmed, written to `ply` atomically.
MeshResult RunMeshStage(const PointCloud& cloud,
                        const ReconstructConfig& config, const std::string& ply,
                        std::ostream& log);

// What `reconstruct` ran on, stored in OUT/run.yaml with all options.
struct DatasetRecord {
  std::string path, model, images, format = "auto", mask_dir;
};
void RegisterDatasetRecord(DatasetRecord* record, OptionRegistry* registry);
std::string RunRecordPath(const std::string& out);

}  // namespace cli
}  // namespace wild_mvs
