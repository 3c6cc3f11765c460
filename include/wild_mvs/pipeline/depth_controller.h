// Copyright wild_mvs authors. The depth pipeline, one for the offline tool
// and the live nodes (as COLMAP's PatchMatchController over its Workspace):
//
//   1. Match: R's depth, normal and confidence map by the paper's MVS
//      (ReconstructView: view selection, rescaling, seeding, region growing
//      with MPGC) -> the workspace's raw map of R.
//   2. Filter: R's raw map checked against its neighbours' raw maps
//      (FilterByConsistency, docs/ALGORITHM.md 5.3) -> R's final map.
//   3. Fuse: the final maps merged into one cloud (StreamingFusion, the
//      class the live fusion node runs too).
//
// Offline (`wild_mvs reconstruct`) runs both steps stage by stage over the
// views of a dataset: Run (resumable; --shard processes only match, and
// FilterPending finishes their views later). Live (StreamReconstructor)
// runs the same steps one keyframe at a time as neighbours arrive: Match
// as soon as a keyframe has neighbours, Match again with neighbours on both
// sides, then Filter once those are matched again (docs/ARCHITECTURE.md).
// The controller holds no file path: where maps live is the workspace's.
#pragma once

#include <atomic>
#include <functional>
#include <string>
#include <vector>

#include "wild_mvs/core/fusion.h"
#include "wild_mvs/core/image.h"
#include "wild_mvs/core/reconstruct_view.h"
#include "wild_mvs/core/scene.h"
#include "wild_mvs/core/thread_pool.h"
#include "wild_mvs/pipeline/depth_workspace.h"

namespace wild_mvs {

// One view to match.
struct ViewProblem {
  const Scene* scene = nullptr;
  int ref = -1;                  // scene index of R
  ImageCache* images = nullptr;  // serves the scene's full-size images
  cv::Mat mask;                  // CV_8U, 0 = ignore the pixel; empty = none
  // scene->PointsPerView(), computed once by a caller matching many views
  // of one scene; null = computed per view.
  const std::vector<std::vector<int>>* points_per_view = nullptr;
};

// An offline run over the views of a dataset.
struct DepthRun {
  const Scene* scene = nullptr;
  std::vector<int> views;        // scene indices, in order
  ImageCache* images = nullptr;  // serves the scene's full-size images
  // Mask of a view (CV_8U, 0 = ignore the pixel; empty = none); unset =
  // no masks. May throw Error (the view fails).
  std::function<cv::Mat(int)> mask;
  bool force = false;      // redo views whose output exists
  bool filter_now = true;  // false: match only (a --shard process)
};

// Hears about an offline run, view by view (progress and logs). Called on
// the thread that called Run / FilterViews, in view order.
class DepthRunObserver {
 public:
  virtual ~DepthRunObserver() = default;
  enum class Step { kMatch, kFilter, kFuse };
  // A step over `total` views starts / ends.
  virtual void StepBegins(Step, int /*total*/) {}
  virtual void StepEnds(Step) {}
  // View `key` (the `index`-th of the matching step) needs no matching:
  // its map at stage `done` exists (kFinal: finished; kRaw: matched, to be
  // filtered); `samples` from its log, -1 = unknown.
  virtual void Skipped(int /*index*/, int /*key*/,
                       DepthWorkspace::Stage /*done*/, long long /*samples*/) {}
  virtual void Begins(Step, int /*index*/, int /*key*/) {}
  virtual void Done(Step, int /*index*/, int /*key*/, const ViewResult&) {}
  virtual void Failed(Step, int /*index*/, int /*key*/,
                      const std::string& /*error*/) {}
};

// What an offline run did.
struct DepthRunSummary {
  int matched = 0;        // views matched in this run
  int filtered = 0;       // views filtered in this run
  int skipped = 0;        // views complete before
  int unfiltered = 0;     // matched (now or before), not yet filtered
  long long samples = 0;  // samples of the views' newest maps (filtered
                          // when filtered)
  long long filter_samples = 0, filter_kept = 0;  // the filter's counts
  std::vector<std::string> failures;              // "view: problem"
};

class DepthController {
 public:
  // options.ablation.consistency switches step 2 (off: raw = final).
  // pool may be null; cancel (may be null) stops a running match (Cancelled).
  DepthController(const MvsOptions& options, ThreadPool* pool,
                  const std::atomic<bool>* cancel = nullptr);

  bool filters() const { return options_.ablation.consistency; }

  // Step 1 for one view. Throws Error on bad input, Cancelled.
  ViewResult Match(const ViewProblem& problem) const;
  // Step 2 for one raw map (neighbours as keys of `workspace`): checked
  // against the raw maps the workspace holds of its neighbours (those it
  // lacks are left out). Safe to call from several threads at once.
  ViewResult Filter(const DepthMap& raw, const DepthWorkspace& workspace) const;

  // Offline: Match every view of run.views whose output is not complete
  // (all when run.force), writing raw maps; then, when run.filter_now,
  // Filter every one matched and not yet filtered. A view that fails is
  // reported and the others go on; a workspace write error throws.
  DepthRunSummary Run(const DepthRun& run, DepthWorkspace* workspace,
                      DepthRunObserver* observer) const;
  // Offline: Filter run.views (their raw maps in the workspace), in
  // parallel on the pool, writing final maps in view order.
  DepthRunSummary FilterViews(const DepthRun& run, DepthWorkspace* workspace,
                              DepthRunObserver* observer) const;
  // Offline: fuses the final maps the workspace holds of run.views (in
  // order; views without one are left out: Error when none has one), the
  // colours from run.images (released first: the fusion reads each image
  // once, uncached; null = no colours), masks from run.mask; then hands
  // the finished fusion to `done` (its cloud read whole or in chunks).
  // Returns the number of views fused.
  int Fuse(const DepthRun& run, const FusionOptions& options,
           const DepthWorkspace& workspace, DepthRunObserver* observer,
           const std::function<void(const StreamingFusion&)>& done) const;

 private:
  // ReconstructView at the options' size; with the coarse fill, the empty
  // pixels filled from the map matched at half that size, itself filled the
  // same way down to kMinCoarseSize.
  DepthMap MatchAtScales(const ViewProblem& problem, const MvsOptions& options,
                         ViewReport* report) const;

  MvsOptions options_;
  ThreadPool* pool_;
  const std::atomic<bool>* cancel_;
};

}  // namespace wild_mvs
