// Copyright wild_mvs authors. Fusion benchmark: time and peak memory.
//
//   bench_fusion OUT [--views N] [--threads T] [--cache-mb M]
//                [--pending-mb P] [--min-support K]
//     fuses the depth maps of a `wild_mvs reconstruct` output folder (OUT/
//     depth, normal, confidence, cameras; the first N views in name order)
//     streaming them from disk, and prints the time, the fusion's own memory
//     accounting and the process's peak RSS (getrusage). Run once per N so
//     the RSS peaks are separate: e.g. N = 16 and N = 47 for templeRing.
//   bench_fusion --make-synthetic OUT N [WIDTH HEIGHT]
//     writes N analytic depth maps (sphere on a ground square, ring cameras,
//     0.2 % depth noise, 5 % outliers; default 640 x 480 like templeRing) to
//     OUT in the same layout, for runs before real depth maps exist.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include "../test/unit/test_fusion_scene.h"
#include "wild_mvs/core/error.h"
#include "wild_mvs/core/fusion.h"
#include "wild_mvs/core/scene.h"
#include "wild_mvs/core/stats.h"
#include "wild_mvs/io/depth_map_io.h"

namespace fs = std::filesystem;
using namespace wild_mvs;  // NOLINT

namespace {

int MakeSynthetic(const std::string& out, int n, int w, int h) {
  fusion_test::AnalyticScene scene;
  scene.width = w;
  scene.height = h;
  scene.focal = 1.2 * w;
  for (int i = 0; i < n; ++i) {
    DepthMap m = scene.Render(i, n);
    fusion_test::Corrupt(&m, 0.002, 0.05, 0.05, 100 + i);
    std::vector<std::string> names;
    for (int k : m.neighbors) names.push_back(Msg("view_", 1000 + k, ".png"));
    WriteDepthMapFiles(out, Msg("view_", 1000 + i), m, names, false);
  }
  std::printf("wrote %d synthetic %dx%d depth maps to %s\n", n, w, h,
              out.c_str());
  return 0;
}

int Run(int argc, char** argv) {
  if (argc >= 4 && std::string(argv[1]) == "--make-synthetic") {
    const int w = argc >= 6 ? std::atoi(argv[4]) : 640;
    const int h = argc >= 6 ? std::atoi(argv[5]) : 480;
    return MakeSynthetic(argv[2], std::atoi(argv[3]), w, h);
  }
  if (argc < 2 || argv[1][0] == '-') {
    std::fprintf(stderr,
                 "usage: bench_fusion OUT [--views N] [--threads T] "
                 "[--cache-mb M] [--pending-mb P] [--min-support K]\n"
                 "       bench_fusion --make-synthetic OUT N [W H]\n");
    return 2;
  }
  const std::string out = argv[1];
  int max_views = 0, threads = 1;
  FusionOptions options;
  for (int i = 2; i + 1 < argc; i += 2) {
    const std::string a = argv[i];
    const char* v = argv[i + 1];
    if (a == "--views")
      max_views = std::atoi(v);
    else if (a == "--threads")
      threads = std::atoi(v);
    else if (a == "--cache-mb")
      options.map_cache_mb = std::atof(v);
    else if (a == "--pending-mb")
      options.pending_mb = std::atof(v);
    else if (a == "--min-support")
      options.min_support = std::atoi(v);
    else
      throw Error(Msg("bench_fusion: unknown option ", a));
  }
  // Views: the camera files present (a complete depth map set each).
  std::vector<std::string> stems;
  Require(fs::is_directory(out + "/cameras"), "bench_fusion: ", out,
          "/cameras is not a directory (not a reconstruct output folder)");
  for (const auto& e : fs::directory_iterator(out + "/cameras"))
    if (e.path().extension() == ".txt") stems.push_back(e.path().stem());
  std::sort(stems.begin(), stems.end());
  if (max_views > 0 && static_cast<int>(stems.size()) > max_views)
    stems.resize(max_views);
  Require(!stems.empty(), "bench_fusion: no depth maps in ", out);
  std::map<std::string, int> index;
  for (size_t i = 0; i < stems.size(); ++i)
    index[stems[i]] = static_cast<int>(i);

  DepthMapProvider provider = [&](int view) {
    DepthMapFiles f = ReadDepthMapFiles(out, stems.at(view));
    auto m = std::make_shared<DepthMap>(std::move(f.map));
    m->view = view;
    for (const std::string& name : f.neighbor_names) {
      View tmp;
      tmp.name = name;
      auto it = index.find(tmp.Stem());
      if (it != index.end()) m->neighbors.push_back(it->second);
    }
    return std::shared_ptr<const DepthMap>(m);
  };
  std::vector<int> views(stems.size());
  for (size_t i = 0; i < views.size(); ++i) views[i] = static_cast<int>(i);

  const double rss_before = PeakRssMb();
  ThreadPool pool(threads);
  FusionStats stats;
  const double cpu0 = CpuSeconds();
  const auto t0 = std::chrono::steady_clock::now();
  const PointCloud cloud =
      FuseDepthMaps(views, options, provider, nullptr, nullptr,
                    threads > 1 ? &pool : nullptr, &stats);
  const double secs =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0)
          .count();
  const double cpu = CpuSeconds() - cpu0;
  std::printf(
      "views %d  time %.2f s (%.3f s/view)  cpu %.2f s  points %zu  samples "
      "%zu  "
      "accepted %zu  promoted %zu  pending_dropped %zu  map_loads %zu\n"
      "memory: fusion peak %.1f MB (held maps peak %.1f MB, cloud %.1f MB, "
      "pending %.1f MB)  process peak RSS %.1f MB (%.1f MB before fusion)\n",
      stats.views, secs, secs / std::max(1, stats.views), cpu, cloud.size(),
      stats.samples, stats.accepted, stats.promoted, stats.pending_dropped,
      stats.map_loads, stats.peak_bytes / 1048576.0,
      stats.peak_held_map_bytes / 1048576.0, stats.cloud_bytes / 1048576.0,
      stats.pending_bytes / 1048576.0, PeakRssMb(), rss_before);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    return Run(argc, argv);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "bench_fusion: %s\n", e.what());
    return 1;
  }
}
