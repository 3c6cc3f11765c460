// Copyright wild_mvs authors.
#include "wild_mvs/cli/run_steps.h"

#include <sys/resource.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <memory>
#include <regex>
#include <sstream>

#include "wild_mvs/cli/progress.h"
#include "wild_mvs/cli/scene_setup.h"
#include "wild_mvs/core/reconstruct_view.h"
#include "wild_mvs/core/sparse_tracker.h"
#include "wild_mvs/io/atomic_file.h"
#include "wild_mvs/io/depth_map_io.h"

namespace wild_mvs {
namespace cli {
namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

double SecondsSince(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

double Median(std::vector<double> v) {
  if (v.empty()) return 0;
  std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
  return v[v.size() / 2];
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

double CpuSeconds() {
  rusage u;
  if (getrusage(RUSAGE_SELF, &u) != 0) return 0;
  return u.ru_utime.tv_sec + u.ru_stime.tv_sec +
         1e-6 * (u.ru_utime.tv_usec + u.ru_stime.tv_usec);
}

double PeakRssMb() {
  rusage u;
  if (getrusage(RUSAGE_SELF, &u) != 0) return 0;
  return u.ru_maxrss / 1024.0;  // Linux: kilobytes
}

SparseSummary ComputeSceneTracks(Scene* scene, const ReconstructConfig& config,
                                 ThreadPool* pool, std::ostream& log) {
  const auto t0 = Clock::now();
  log << "sparse: computing tracks from the known poses of "
      << scene->views.size() << " views..." << std::endl;
  ImageCache images(MakeSceneLoader(*scene, config.image),
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

DepthStageResult RunDepthStage(const Scene& scene,
                               const std::vector<int>& views,
                               ImageCache& images,
                               const ReconstructConfig& config,
                               ThreadPool* pool, const std::string& out,
                               bool force, std::ostream& log) {
  const auto t0 = Clock::now();
  DepthStageResult r;
  Progress progress("depth", static_cast<int>(views.size()), log,
                    StderrIsTerminal());
  const int total = static_cast<int>(views.size());
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
    progress.Begin(stem);
    DepthMap map;
    ViewReport report;
    try {
      const cv::Mat mask = LoadMaskForView(view);
      map = ReconstructView(scene, v, images, config.mvs, pool, &report, mask);
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
    WriteDepthMapFiles(out, stem, map, names, true);
    std::string json = report.ToJson(scene);
    if (json.rfind("{\n", 0) == 0) {
      json = "{\n  \"view\": " + JsonString(view.name) +
             ",\n  \"stem\": " + JsonString(stem) + "," + json.substr(1);
    }
    WriteFileAtomically(LogPath(out, stem),
                        [&](std::ostream& os) { os << json; });
    const int valid = map.CountValid();
    r.samples += valid;
    ++r.computed;
    const double fill =
        map.empty() ? 0.0 : 100.0 * valid / (map.width() * map.height());
    std::string note =
        Msg(prefix, ": ", valid, " samples (", map.width(), "x", map.height(),
            ", ", static_cast<int>(fill + 0.5), "% filled), ",
            report.seeds_accepted, "/", report.seeds_tried, " seeds, ",
            Progress::FormatDuration(report.seconds));
    for (const std::string& f : report.fallbacks) note += "\n    " + f;
    progress.End(note);
  }
  progress.Finish();
  r.seconds = SecondsSince(t0);
  return r;
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
