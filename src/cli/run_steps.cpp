// Copyright wild_mvs authors.
#include "wild_mvs/cli/run_steps.h"

#include <chrono>
#include <filesystem>
#include <memory>

#include "wild_mvs/cli/progress.h"
#include "wild_mvs/cli/scene_setup.h"
#include "wild_mvs/core/reconstruct_view.h"
#include "wild_mvs/core/sparse_tracker.h"
#include "wild_mvs/core/stats.h"
#include "wild_mvs/io/colmap.h"
#include "wild_mvs/io/image_files.h"
#include "wild_mvs/io/sparse_tracks_file.h"
#include "wild_mvs/pipeline/depth_controller.h"
#include "wild_mvs/pipeline/file_workspace.h"

namespace wild_mvs {
namespace cli {
namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

double SecondsSince(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

}  // namespace

SparseSummary ComputeSceneTracks(Scene* scene, const ReconstructConfig& config,
                                 ThreadPool* pool, std::ostream& log) {
  const auto t0 = Clock::now();
  log << "sparse: computing tracks from the known poses of "
      << scene->views.size() << " views..." << std::endl;
  ImageCache images(MakeSceneLoader(*scene, config.LoaderOptions()),
                    config.image.cache_mb);
  TrackerStats stats;
  scene->points =
      ComputeSparseTracks(*scene, images, config.tracker, pool, &stats);
  SparseSummary s;
  std::vector<double> lengths, errors;
  for (const SparsePoint& p : scene->points) {
    s.observations += p.track.size();
    lengths.push_back(static_cast<double>(p.track.size()));
    errors.push_back(p.error);
  }
  s.points = scene->points.size();
  s.median_track_length = Median(lengths);
  s.median_error = Median(errors);
  s.seconds = SecondsSince(t0);
  log << "sparse: " << stats.features << " features, " << stats.pairs_matched
      << " pairs matched, " << stats.matches << " matches -> " << s.points
      << " points (median track length " << s.median_track_length
      << ", median reprojection error " << s.median_error << " px) in "
      << Progress::FormatDuration(s.seconds) << std::endl;
  if (s.points == 0) {
    log << "sparse: warning: no sparse points; depth maps will be seeded by "
           "the depth-sweep fallback"
        << std::endl;
  }
  return s;
}

namespace {

using Stage = DepthWorkspace::Stage;
using Step = DepthRunObserver::Step;

// The depth pipeline's progress on the command line: a bar on a terminal,
// a line per view in logs.
class ProgressObserver : public DepthRunObserver {
 public:
  ProgressObserver(const Scene& scene, const FileDepthWorkspace& workspace,
                   std::ostream& log)
      : scene_(scene), workspace_(workspace), log_(log) {}

  void StepBegins(Step step, int total) override {
    total_ = total;
    progress_ = std::make_unique<Progress>(
        step == Step::kMatch ? "depth" : "consistency", total, log_,
        StderrIsTerminal());
  }
  void StepEnds(Step) override {
    progress_->Finish();
    progress_.reset();
  }
  void Skipped(int index, int key, Stage done, long long samples) override {
    const std::string prefix = Prefix(Step::kMatch, index, key);
    progress_->Skip(done == Stage::kFinal
                        ? Msg(prefix, ": done earlier, skipped (",
                              samples >= 0 ? std::to_string(samples) : "?",
                              " samples; --force recomputes)")
                        : Msg(prefix, ": matched earlier, to be filtered"));
  }
  void Begins(Step, int, int key) override {
    progress_->Begin(scene_.views[key].Stem());
  }
  void Failed(Step step, int index, int key,
              const std::string& error) override {
    progress_->End(Msg(Prefix(step, index, key), ": FAILED: ", error));
  }
  void Done(Step step, int index, int key, const ViewResult& r) override {
    const std::string prefix = Prefix(step, index, key);
    if (step == Step::kFilter) {
      progress_->End(
          r.neighbor_maps == 0 && r.consistency.samples > 0
              ? Msg(prefix, ": no neighbour's map in ",
                    workspace_.Folder(Stage::kRaw),
                    " to check against (reconstruct its neighbours too): ",
                    r.consistency.samples, " samples kept unfiltered")
              : Msg(prefix, ": kept ", r.consistency.kept, " of ",
                    r.consistency.samples, " samples (", r.neighbor_maps,
                    " neighbour maps)"));
      return;
    }
    const DepthMap& map = r.map;
    const int valid = map.CountValid();
    const double fill =
        map.empty() ? 0.0 : 100.0 * valid / (map.width() * map.height());
    std::string note =
        Msg(prefix, ": ", valid, " samples (", map.width(), "x", map.height(),
            ", ", static_cast<int>(fill + 0.5), "% filled), ",
            r.report.seeds_accepted, "/", r.report.seeds_tried, " seeds, ",
            r.report.planar_samples, " from planes, ", r.report.coarse_samples,
            " from half size, ", Progress::FormatDuration(r.report.seconds));
    for (const std::string& f : r.report.fallbacks) note += "\n    " + f;
    progress_->End(note);
  }

 private:
  std::string Prefix(Step step, int index, int key) const {
    return Msg(step == Step::kMatch ? "depth " : "consistency ", index + 1, "/",
               total_, " ", scene_.views[key].Stem());
  }

  const Scene& scene_;
  const FileDepthWorkspace& workspace_;
  std::ostream& log_;
  int total_ = 0;
  std::unique_ptr<Progress> progress_;
};

}  // namespace

DepthStageResult RunDepthStage(const Scene& scene,
                               const std::vector<int>& views,
                               ImageCache& images,
                               const ReconstructConfig& config,
                               ThreadPool* pool, const std::string& out,
                               bool force, std::ostream& log, bool filter_now) {
  const auto t0 = Clock::now();
  const DepthController controller(config.mvs, pool);
  // With the consistency filter the MVS maps go to OUT/raw first; the
  // filter writes the final maps to OUT.
  FileDepthWorkspace workspace(scene, out, controller.filters());
  ProgressObserver progress(scene, workspace, log);
  DepthRun run;
  run.scene = &scene;
  run.views = views;
  run.images = &images;
  run.mask = [&scene](int v) { return LoadViewMask(scene.views[v]); };
  run.force = force;
  run.filter_now = filter_now;
  const DepthRunSummary s = controller.Run(run, &workspace, &progress);
  DepthStageResult r;
  r.computed = controller.filters() && filter_now ? s.filtered : s.matched;
  r.skipped = s.skipped;
  r.samples = s.samples;
  r.consistency_samples = s.filter_samples;
  r.consistency_kept = s.filter_kept;
  r.unfiltered = s.unfiltered;
  r.failures = s.failures;
  r.seconds = SecondsSince(t0);
  return r;
}

FilterStageResult FilterPendingViews(const Scene& scene, const MvsOptions& mvs,
                                     const std::string& out, ThreadPool* pool,
                                     std::ostream& log) {
  FilterStageResult r;
  if (!mvs.ablation.consistency) return r;
  FileDepthWorkspace workspace(scene, out, true);
  const std::string& raw = workspace.Folder(Stage::kRaw);
  std::vector<int> pending;
  int missing = 0;
  for (size_t i = 0; i < scene.views.size(); ++i) {
    const int v = static_cast<int>(i);
    const bool done = workspace.Has(Stage::kFinal, v);
    if (workspace.Has(Stage::kRaw, v)) {
      if (!done) pending.push_back(v);
    } else if (!done) {
      ++missing;
    }
  }
  if (pending.empty()) return r;
  log << "consistency: " << pending.size() << " views matched in " << raw
      << " but not yet filtered (e.g. by --shard runs)" << std::endl;
  if (missing > 0) {
    // A filtered map is final: one checked before its neighbours' maps
    // exist is checked against fewer maps than in a single run.
    log << "consistency: warning: " << missing << " of " << scene.views.size()
        << " views have no depth map yet; if shards are still running, "
           "their neighbours are filtered without them (wait for every "
           "shard before 'wild_mvs fuse')"
        << std::endl;
  }
  const DepthController controller(mvs, pool);
  ProgressObserver progress(scene, workspace, log);
  DepthRun run;
  run.scene = &scene;
  run.views = pending;
  const DepthRunSummary s = controller.FilterViews(run, &workspace, &progress);
  r.filtered = s.filtered;
  r.samples = s.filter_samples;
  r.kept = s.filter_kept;
  r.failures = s.failures;
  if (!r.failures.empty()) {
    std::string list;
    for (const std::string& f : r.failures) list += "\n  " + f;
    throw Error(Msg(r.failures.size(), " of ", pending.size(),
                    " views failed the consistency filter:", list));
  }
  return r;
}

std::string SparseTracksPath(const std::string& out) {
  return out + "/sparse/tracks.txt";
}

std::vector<std::string> TracksFingerprint(const OptionSet& options,
                                           const std::string& mask_dir) {
  // The tracker's own options and the image loading (size, linearisation);
  // not run.threads: the tracks do not depend on it.
  std::vector<std::string> f;
  for (const auto& o : options.options()) {
    const std::string& key = o.key();
    if (key.rfind("tracker.", 0) == 0 || key.rfind("image.", 0) == 0 ||
        key == "ablation.linearize") {
      if (key == "image.cache_mb") continue;
      f.push_back(key + " " + o.Text());
    }
  }
  f.push_back("dataset.mask_dir " + mask_dir);
  return f;
}

bool LoadSceneTracks(Scene* scene, const std::string& out,
                     const std::vector<std::string>& fingerprint,
                     std::ostream& log) {
  const std::string path = SparseTracksPath(out);
  std::error_code ec;
  if (!fs::is_regular_file(path, ec)) return false;
  std::string why;
  std::vector<SparsePoint> points;
  if (!ReadSparseTracks(path, *scene, fingerprint, &points, &why)) {
    log << "sparse: " << path << " is of another run (" << why << "); not used"
        << std::endl;
    return false;
  }
  scene->points = std::move(points);
  log << "sparse: " << scene->points.size() << " points read from " << path
      << std::endl;
  return true;
}

SparseSummary ComputeAndSaveSceneTracks(
    Scene* scene, const ReconstructConfig& config, ThreadPool* pool,
    const std::string& out, const std::vector<std::string>& fingerprint,
    std::ostream& log) {
  SparseSummary s = ComputeSceneTracks(scene, config, pool, log);
  WriteColmapText(*scene, out + "/sparse");
  WriteSparseTracks(SparseTracksPath(out), *scene, fingerprint);
  log << "sparse: model written to " << out << "/sparse (tracks.txt: the "
      << "exact tracks, reused by later runs and shards on " << out << ")"
      << std::endl;
  return s;
}

void RegisterDatasetRecord(DatasetRecord* r, OptionRegistry* set) {
  set->Add("dataset.path", &r->path, "dataset folder of this run");
  set->Add("dataset.model", &r->model, "--model override (\"\" = detected)");
  set->Add("dataset.images", &r->images, "--images override (\"\" = detected)");
  set->Add("dataset.format", &r->format, "--format (auto = detected)");
  set->Add("dataset.mask_dir", &r->mask_dir, "--mask-dir (\"\" = none)");
}

std::string RunRecordPath(const std::string& out) { return out + "/run.yaml"; }

}  // namespace cli
}  // namespace wild_mvs
