// Copyright wild_mvs authors.
#include "wild_mvs/cli/run_steps.h"

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <regex>
#include <sstream>

#include "wild_mvs/cli/progress.h"
#include "wild_mvs/cli/scene_setup.h"
#include "wild_mvs/core/geometric_consistency.h"
#include "wild_mvs/core/reconstruct_view.h"
#include "wild_mvs/core/sparse_tracker.h"
#include "wild_mvs/core/stats.h"
#include "wild_mvs/io/atomic_file.h"
#include "wild_mvs/io/colmap.h"
#include "wild_mvs/io/depth_map_io.h"
#include "wild_mvs/io/image_files.h"
#include "wild_mvs/io/report_json.h"
#include "wild_mvs/io/sparse_tracks_file.h"

namespace wild_mvs {
namespace cli {
namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

double SecondsSince(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

std::string LogPath(const std::string& out, const std::string& stem) {
  return out + "/log/" + stem + ".json";
}

std::string JsonString(const std::string& s) {
  std::string o = "\"";
  for (char c : s) {
    if (c == '"' || c == '\\') {
      o += '\\';
      o += c;
    } else if (static_cast<unsigned char>(c) < 0x20) {
      char buf[8];
      std::snprintf(buf, sizeof(buf), "\\u%04x", c);
      o += buf;
    } else {
      o += c;
    }
  }
  return o + "\"";
}

// "samples" of a finished view's log, or -1 when unreadable.
long long SamplesFromLog(const std::string& path) {
  std::ifstream in(path);
  std::stringstream ss;
  ss << in.rdbuf();
  std::smatch m;
  const std::string text = ss.str();
  static const std::regex re("\"samples\"\\s*:\\s*([0-9]+)");
  if (!std::regex_search(text, m, re)) return -1;
  return std::stoll(m[1].str());
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

bool ViewOutputsComplete(const std::string& out, const std::string& stem) {
  std::error_code ec;
  return DepthMapFilesExist(out, stem) &&
         fs::is_regular_file(LogPath(out, stem), ec);
}

namespace {

// Writes one view's depth map and its log (log last: the view is complete
// once it exists). extra_json: more members for the log ("" = none).
void WriteViewOutputs(const View& view, const std::string& dir,
                      const DepthMap& map,
                      const std::vector<std::string>& neighbor_names,
                      const std::string& json_body, const std::string& extra) {
  WriteDepthMapFiles(dir, view.Stem(), map, neighbor_names, true);
  std::string json = json_body;
  if (json.rfind("{\n", 0) == 0) {
    json = "{\n  \"view\": " + JsonString(view.name) +
           ",\n  \"stem\": " + JsonString(view.Stem()) + "," + extra +
           json.substr(1);
  }
  WriteFileAtomically(LogPath(dir, view.Stem()),
                      [&](std::ostream& os) { os << json; });
}

std::string ReadText(const std::string& path) {
  std::ifstream in(path);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

// The view log's body without the "view"/"stem" members the writer adds
// (so that a raw log can be rewritten with more members).
std::string StripViewHeader(const std::string& json) {
  static const std::regex re(
      "^\\{\\n  \"view\": \"(?:[^\"\\\\]|\\\\.)*\",\\n  \"stem\": "
      "\"(?:[^\"\\\\]|\\\\.)*\",");
  return std::regex_replace(json, re, "{",
                            std::regex_constants::format_first_only);
}

}  // namespace

DepthStageResult RunDepthStage(const Scene& scene,
                               const std::vector<int>& views,
                               ImageCache& images,
                               const ReconstructConfig& config,
                               ThreadPool* pool, const std::string& out,
                               bool force, std::ostream& log, bool filter_now) {
  const auto t0 = Clock::now();
  DepthStageResult r;
  // With the consistency filter the MVS maps go to OUT/raw first; the
  // filter writes the final maps to OUT.
  const bool filter = config.mvs.ablation.consistency;
  const std::string raw = filter ? out + "/raw" : out;
  Progress progress("depth", static_cast<int>(views.size()), log,
                    StderrIsTerminal());
  const int total = static_cast<int>(views.size());
  std::vector<int> to_filter;
  // Once for the run, not per view (it grows with the collection).
  const std::vector<std::vector<int>> points_per_view = scene.PointsPerView();
  for (int k = 0; k < total; ++k) {
    const int v = views[k];
    const View& view = scene.views[v];
    const std::string stem = view.Stem();
    const std::string prefix = Msg("depth ", k + 1, "/", total, " ", stem);
    if (!force && ViewOutputsComplete(out, stem)) {
      const long long samples = SamplesFromLog(LogPath(out, stem));
      if (samples > 0) r.samples += samples;
      ++r.skipped;
      progress.Skip(Msg(prefix, ": done earlier, skipped (",
                        samples >= 0 ? std::to_string(samples) : "?",
                        " samples; --force recomputes)"));
      continue;
    }
    if (filter && !force && ViewOutputsComplete(raw, stem)) {
      to_filter.push_back(v);
      if (!filter_now) {  // a shard: resumed, its raw samples counted
        const long long samples = SamplesFromLog(LogPath(raw, stem));
        if (samples > 0) r.samples += samples;
        ++r.skipped;
      }
      progress.Skip(Msg(prefix, ": matched earlier, to be filtered"));
      continue;
    }
    progress.Begin(stem);
    DepthMap map;
    ViewReport report;
    try {
      const cv::Mat mask = LoadViewMask(view);
      map = ReconstructView(scene, v, images, config.mvs, pool, &report, mask,
                            &points_per_view);
    } catch (const Error& e) {
      r.failures.push_back(Msg(view.name, ": ", e.what()));
      progress.End(Msg(prefix, ": FAILED: ", e.what()));
      continue;
    }
    // Output errors (unwritable folder, full disk) abort the run; every
    // file is atomic, the log last, so a view is either complete or redone.
    std::vector<std::string> names;
    for (int n : map.neighbors) {
      if (n >= 0 && n < static_cast<int>(scene.views.size())) {
        names.push_back(scene.views[n].name);
      }
    }
    WriteViewOutputs(view, raw, map, names, ViewReportJson(report, scene), "");
    const int valid = map.CountValid();
    if (filter) {
      to_filter.push_back(v);
    }
    if (!filter || !filter_now) {
      r.samples += valid;
      ++r.computed;
    }
    const double fill =
        map.empty() ? 0.0 : 100.0 * valid / (map.width() * map.height());
    std::string note = Msg(
        prefix, ": ", valid, " samples (", map.width(), "x", map.height(), ", ",
        static_cast<int>(fill + 0.5), "% filled), ", report.seeds_accepted, "/",
        report.seeds_tried, " seeds, ", report.planar_samples, " from planes, ",
        Progress::FormatDuration(report.seconds));
    for (const std::string& f : report.fallbacks) note += "\n    " + f;
    progress.End(note);
  }
  progress.Finish();
  ReleaseFreeMemory();  // the stages' peaks do not add up
  if (filter && !filter_now) {
    r.unfiltered = static_cast<int>(to_filter.size());
  } else if (filter && !to_filter.empty()) {
    FilterStageResult f = FilterDepthMaps(
        scene, to_filter, config.mvs.consistency, out + "/raw", out, pool, log);
    ReleaseFreeMemory();
    r.computed += f.filtered;
    r.samples += f.kept;
    r.consistency_samples += f.samples;
    r.consistency_kept += f.kept;
    for (const std::string& e : f.failures) r.failures.push_back(e);
  }
  r.seconds = SecondsSince(t0);
  return r;
}

FilterStageResult FilterDepthMaps(const Scene& scene,
                                  const std::vector<int>& views,
                                  const GeometricConsistencyOptions& options,
                                  const std::string& raw,
                                  const std::string& out, ThreadPool* pool,
                                  std::ostream& log,
                                  const std::string& member) {
  options.Check();
  FilterStageResult r;
  std::map<std::string, int> by_name;
  for (size_t i = 0; i < scene.views.size(); ++i)
    by_name[scene.views[i].name] = static_cast<int>(i);
  const int total = static_cast<int>(views.size());
  struct Job {
    DepthMapFiles ref;
    ConsistencyStats stats;
    int neighbor_maps = 0;
    std::string error;
  };
  std::vector<Job> jobs(views.size());
  Progress progress("consistency", total, log, StderrIsTerminal());
  // One view per task: each reads its raw map and its neighbours' (the
  // neighbours' maps are read again by every view that needs them: a few
  // MB each, and memory stays bounded by threads x neighbours).
  auto run = [&](int k) {
    Job& job = jobs[k];
    const View& view = scene.views[views[k]];
    try {
      job.ref = ReadDepthMapFiles(raw, view.Stem());
      std::vector<DepthMapFiles> nbs;
      for (const std::string& name : job.ref.neighbor_names) {
        auto it = by_name.find(name);
        if (it == by_name.end()) continue;
        const std::string stem = scene.views[it->second].Stem();
        if (!DepthMapFilesExist(raw, stem)) continue;
        nbs.push_back(ReadDepthMapFiles(raw, stem));
      }
      std::vector<const DepthMap*> ptrs;
      for (const DepthMapFiles& n : nbs) ptrs.push_back(&n.map);
      job.neighbor_maps = static_cast<int>(ptrs.size());
      FilterByConsistency(&job.ref.map, ptrs, options, &job.stats);
    } catch (const Error& e) {
      job.error = e.what();
    }
  };
  const int chunk = pool ? std::max(1, pool->size()) : 1;
  for (int k0 = 0; k0 < total; k0 += chunk) {
    const int n = std::min(chunk, total - k0);
    if (pool && n > 1) {
      pool->ParallelFor(n, [&](int i) { run(k0 + i); });
    } else {
      for (int i = 0; i < n; ++i) run(k0 + i);
    }
    // Written in order by this thread (atomic files, the log last).
    for (int k = k0; k < k0 + n; ++k) {
      const View& view = scene.views[views[k]];
      Job& job = jobs[k];
      const std::string prefix =
          Msg("consistency ", k + 1, "/", total, " ", view.Stem());
      progress.Begin(view.Stem());
      if (!job.error.empty()) {
        r.failures.push_back(Msg(view.name, ": ", job.error));
        progress.End(Msg(prefix, ": FAILED: ", job.error));
        continue;
      }
      const std::string extra =
          Msg("\n  \"", member, "\": {\"samples_before\": ", job.stats.samples,
              ", \"kept\": ", job.stats.kept,
              ", \"neighbor_maps\": ", job.neighbor_maps, "},");
      // The raw log with the filtered count as its "samples" (written once:
      // the log marks the view complete).
      static const std::regex samples_re("\"samples\": [0-9]+");
      const std::string body = std::regex_replace(
          StripViewHeader(ReadText(LogPath(raw, view.Stem()))), samples_re,
          Msg("\"samples\": ", job.stats.kept),
          std::regex_constants::format_first_only);
      WriteViewOutputs(view, out, job.ref.map, job.ref.neighbor_names, body,
                       extra);
      ++r.filtered;
      r.samples += job.stats.samples;
      r.kept += job.stats.kept;
      progress.End(
          job.neighbor_maps == 0 && job.stats.samples > 0
              ? Msg(prefix, ": no neighbour's map in ", raw,
                    " to check against (reconstruct its neighbours too): ",
                    job.stats.samples, " samples kept unfiltered")
              : Msg(prefix, ": kept ", job.stats.kept, " of ",
                    job.stats.samples, " samples (", job.neighbor_maps,
                    " neighbour maps)"));
      job.ref = DepthMapFiles();
    }
  }
  progress.Finish();
  return r;
}

FilterStageResult FilterPendingViews(const Scene& scene, const MvsOptions& mvs,
                                     const std::string& out, ThreadPool* pool,
                                     std::ostream& log) {
  FilterStageResult r;
  if (!mvs.ablation.consistency) return r;
  const std::string raw = out + "/raw";
  std::vector<int> pending;
  int missing = 0;
  for (size_t i = 0; i < scene.views.size(); ++i) {
    const std::string stem = scene.views[i].Stem();
    const bool done = ViewOutputsComplete(out, stem);
    if (ViewOutputsComplete(raw, stem)) {
      if (!done) pending.push_back(static_cast<int>(i));
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
  r = FilterDepthMaps(scene, pending, mvs.consistency, raw, out, pool, log);
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
