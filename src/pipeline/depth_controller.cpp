// Copyright wild_mvs authors.
#include "wild_mvs/pipeline/depth_controller.h"

#include <algorithm>
#include <memory>
#include <opencv2/imgproc.hpp>

#include "wild_mvs/core/coarse_fill.h"
#include "wild_mvs/core/error.h"
#include "wild_mvs/core/geometric_consistency.h"
#include "wild_mvs/core/stats.h"

namespace wild_mvs {

using Stage = DepthWorkspace::Stage;

// The smallest coarse map (pixels, longest side): a coarse pass runs while
// half the map's size is at least this (at 640 px: 320 and 160 px).
constexpr int kMinCoarseSize = 160;
// Its four samples around a pixel lie on one surface when their planes agree
// within this (relative depth along the pixel's ray).
constexpr double kCoarseSpread = 0.01;
using Step = DepthRunObserver::Step;

DepthController::DepthController(const MvsOptions& options, ThreadPool* pool,
                                 const std::atomic<bool>* cancel)
    : options_(options), pool_(pool), cancel_(cancel) {}

ViewResult DepthController::Match(const ViewProblem& problem) const {
  Require(problem.scene && problem.images, "a view problem needs a scene",
          " and its images");
  ViewResult r;
  r.map = MatchAtScales(problem, options_, &r.report);
  return r;
}

DepthMap DepthController::MatchAtScales(const ViewProblem& problem,
                                        const MvsOptions& options,
                                        ViewReport* report) const {
  DepthMap map = ReconstructView(*problem.scene, problem.ref, *problem.images,
                                 options, pool_, report, problem.mask,
                                 problem.points_per_view, cancel_);
  const int size = std::max(map.width(), map.height());
  if (!options.ablation.coarse_fill || size / 2 < kMinCoarseSize) return map;
  // Where the full-size window cannot match at all, and the half-size one
  // has texture on its side of any edge.
  std::shared_ptr<const cv::Mat> image =
      problem.images->GetResized(problem.ref, map.width(), map.height());
  CoarseFillMasks masks =
      PlanCoarseFill(*image, map, options.mpgc.window, options.mpgc.drop_ncc);
  if (!problem.mask.empty()) {
    cv::Mat allowed;
    cv::resize(problem.mask, allowed, masks.fillable.size(), 0, 0,
               cv::INTER_NEAREST);
    masks.fillable &= allowed;
    masks.count = cv::countNonZero(masks.fillable);
  }
  if (masks.count == 0) return map;
  // The half-size map, matched only within reach of a fillable pixel (one
  // sample plus the window's half width): the fill reads nothing farther.
  MvsOptions coarse = options;
  coarse.max_image_size = size / 2;
  const int reach = 2 * (1 + options.mpgc.window / 2);
  cv::Mat near;
  cv::dilate(masks.fillable, near,
             cv::getStructuringElement(cv::MORPH_RECT,
                                       cv::Size(2 * reach + 1, 2 * reach + 1)));
  ViewProblem coarse_problem = problem;
  const Camera& full = problem.scene->views[problem.ref].camera;
  cv::resize(near, coarse_problem.mask, cv::Size(full.width, full.height), 0, 0,
             cv::INTER_NEAREST);
  if (!problem.mask.empty()) coarse_problem.mask &= problem.mask;
  ViewReport coarse_report;
  const DepthMap c = MatchAtScales(coarse_problem, coarse, &coarse_report);
  cv::Mat usable = masks.usable;
  if (usable.size() != cv::Size(c.width(), c.height()))
    cv::resize(masks.usable, usable, cv::Size(c.width(), c.height()), 0, 0,
               cv::INTER_NEAREST);
  report->coarse_samples = FillFromCoarse(
      c, usable, kCoarseSpread, options.mpgc.window / 2, masks.fillable, &map);
  report->samples += report->coarse_samples;
  report->pixel_visits += coarse_report.pixel_visits;
  report->cpu_seconds += coarse_report.cpu_seconds;
  return map;
}

ViewResult DepthController::Filter(const DepthMap& raw,
                                   const DepthWorkspace& workspace) const {
  ViewResult r;
  r.map = raw;  // the arrays may be shared with the workspace: copied
  r.map.depth = raw.depth.clone();
  r.map.normal = raw.normal.clone();
  r.map.confidence = raw.confidence.clone();
  std::vector<std::shared_ptr<const DepthMap>> held;
  for (int n : raw.neighbors) {
    if (n != raw.view && workspace.Has(Stage::kRaw, n))
      held.push_back(workspace.Read(Stage::kRaw, n));
  }
  std::vector<const DepthMap*> neighbors;
  for (const auto& m : held) neighbors.push_back(m.get());
  FilterByConsistency(&r.map, neighbors, options_.consistency, &r.consistency);
  r.filtered = true;
  r.neighbor_maps = static_cast<int>(neighbors.size());
  return r;
}

DepthRunSummary DepthController::Run(const DepthRun& run,
                                     DepthWorkspace* workspace,
                                     DepthRunObserver* observer) const {
  Require(run.scene && run.images && workspace, "a depth run needs a scene,",
          " its images and a workspace");
  DepthRunObserver quiet;
  DepthRunObserver& obs = observer ? *observer : quiet;
  const Scene& scene = *run.scene;
  const bool filter = filters();
  DepthRunSummary s;
  std::vector<int> to_filter;
  // Once for the run, not per view (it grows with the collection).
  const std::vector<std::vector<int>> points_per_view = scene.PointsPerView();
  const int total = static_cast<int>(run.views.size());
  obs.StepBegins(Step::kMatch, total);
  for (int k = 0; k < total; ++k) {
    const int v = run.views[k];
    if (!run.force && workspace->Has(Stage::kFinal, v)) {
      const long long samples = workspace->Samples(Stage::kFinal, v);
      if (samples > 0) s.samples += samples;
      ++s.skipped;
      obs.Skipped(k, v, Stage::kFinal, samples);
      continue;
    }
    if (filter && !run.force && workspace->Has(Stage::kRaw, v)) {
      to_filter.push_back(v);
      long long samples = -1;
      if (!run.filter_now) {  // a shard: resumed, its raw samples counted
        samples = workspace->Samples(Stage::kRaw, v);
        if (samples > 0) s.samples += samples;
        ++s.skipped;
      }
      obs.Skipped(k, v, Stage::kRaw, samples);
      continue;
    }
    obs.Begins(Step::kMatch, k, v);
    ViewResult result;
    try {
      ViewProblem problem;
      problem.scene = &scene;
      problem.ref = v;
      problem.images = run.images;
      if (run.mask) problem.mask = run.mask(v);
      problem.points_per_view = &points_per_view;
      result = Match(problem);
    } catch (const Error& e) {
      s.failures.push_back(Msg(scene.views[v].name, ": ", e.what()));
      obs.Failed(Step::kMatch, k, v, e.what());
      continue;
    }
    // Output errors (unwritable folder, full disk) abort the run; every
    // write is complete or absent, so a view is either done or redone.
    workspace->Write(Stage::kRaw, v, result);
    ++s.matched;
    if (filter) to_filter.push_back(v);
    if (!filter || !run.filter_now) s.samples += result.map.CountValid();
    obs.Done(Step::kMatch, k, v, result);
  }
  obs.StepEnds(Step::kMatch);
  ReleaseFreeMemory();  // the steps' peaks do not add up
  if (!filter) return s;
  if (!run.filter_now) {
    s.unfiltered = static_cast<int>(to_filter.size());
    return s;
  }
  if (to_filter.empty()) return s;
  DepthRun filter_run = run;
  filter_run.views = to_filter;
  const DepthRunSummary f = FilterViews(filter_run, workspace, observer);
  ReleaseFreeMemory();
  s.filtered = f.filtered;
  s.samples += f.samples;
  s.filter_samples = f.filter_samples;
  s.filter_kept = f.filter_kept;
  for (const std::string& e : f.failures) s.failures.push_back(e);
  return s;
}

DepthRunSummary DepthController::FilterViews(const DepthRun& run,
                                             DepthWorkspace* workspace,
                                             DepthRunObserver* observer) const {
  Require(run.scene && workspace, "a filter run needs a scene and a workspace");
  options_.consistency.Check();
  DepthRunObserver quiet;
  DepthRunObserver& obs = observer ? *observer : quiet;
  DepthRunSummary s;
  const int total = static_cast<int>(run.views.size());
  struct Job {
    ViewResult result;
    std::string error;
  };
  std::vector<Job> jobs(run.views.size());
  obs.StepBegins(Step::kFilter, total);
  // One view per task, as many tasks at once as threads: each reads its raw
  // map and its neighbours', through a cache of as many raw maps as the
  // tasks in flight hold at most (chunk x (neighbours + 1)): views in order
  // share most neighbours.
  const int chunk = pool_ ? std::max(1, pool_->size()) : 1;
  CachedDepthWorkspace raw_maps(workspace,
                                chunk * (options_.global.num_neighbors + 1));
  auto filter_one = [&](int k) {
    Job& job = jobs[k];
    try {
      const auto raw = raw_maps.Read(Stage::kRaw, run.views[k]);
      job.result = Filter(*raw, raw_maps);
    } catch (const Error& e) {
      job.error = e.what();
    }
  };
  for (int k0 = 0; k0 < total; k0 += chunk) {
    const int n = std::min(chunk, total - k0);
    if (pool_ && n > 1) {
      pool_->ParallelFor(n, [&](int i) { filter_one(k0 + i); });
    } else {
      for (int i = 0; i < n; ++i) filter_one(k0 + i);
    }
    // Written in order by this thread.
    for (int k = k0; k < k0 + n; ++k) {
      const int v = run.views[k];
      Job& job = jobs[k];
      obs.Begins(Step::kFilter, k, v);
      if (!job.error.empty()) {
        s.failures.push_back(Msg(run.scene->views[v].name, ": ", job.error));
        obs.Failed(Step::kFilter, k, v, job.error);
        continue;
      }
      workspace->Write(Stage::kFinal, v, job.result);
      ++s.filtered;
      s.samples += job.result.consistency.kept;
      s.filter_samples += job.result.consistency.samples;
      s.filter_kept += job.result.consistency.kept;
      obs.Done(Step::kFilter, k, v, job.result);
      job = Job();
    }
  }
  obs.StepEnds(Step::kFilter);
  return s;
}

int DepthController::Fuse(
    const DepthRun& run, const FusionOptions& options,
    const DepthWorkspace& workspace, DepthRunObserver* observer,
    const std::function<void(const StreamingFusion&)>& done) const {
  Require(run.scene, "a fusion run needs a scene");
  DepthRunObserver quiet;
  DepthRunObserver& obs = observer ? *observer : quiet;
  std::vector<int> views;
  for (int v : run.views)
    if (workspace.Has(Stage::kFinal, v)) views.push_back(v);
  Require(!views.empty(), "no depth map of this dataset's views");
  DepthMapProvider depth = [&workspace](int v) {
    return workspace.Read(Stage::kFinal, v);
  };
  // Fusion reads each view's image once (its samples' colours), so the
  // images cached for the earlier steps go and the fusion's own are not
  // cached: its memory depends neither on the cache's budget nor on how
  // much of the collection that cache held.
  ImageProvider image;
  if (run.images) {
    run.images->Clear();
    ReleaseFreeMemory();
    ImageCache* images = run.images;
    image = [images](int v) { return images->Load(v); };
  }
  MaskProvider mask;
  if (run.mask) mask = run.mask;
  StreamingFusion fusion(options, depth, image, mask, pool_);
  const int total = static_cast<int>(views.size());
  obs.StepBegins(Step::kFuse, total);
  for (int k = 0; k < total; ++k) {
    obs.Begins(Step::kFuse, k, views[k]);
    fusion.AddView(views[k]);
    obs.Done(Step::kFuse, k, views[k], ViewResult());
  }
  obs.StepEnds(Step::kFuse);
  // Only the cloud is left to use: the maps and pending samples go first.
  fusion.Finish();
  if (done) done(fusion);
  return total;
}

}  // namespace wild_mvs
