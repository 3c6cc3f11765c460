// Copyright wild_mvs authors. Benchmark of the per-view MVS core (not a test).
//
//   bench_mvs MODEL_DIR IMAGES_DIR [--threads N] [--views i,j,...]
//             [--max-image-size S] [--previews DIR] [--grey] [--no-lvs]
//             [--no-normal] [--no-color-scale] [--save DIR]
//
// --save DIR writes each depth map with WriteDepthMapFiles (depth, normal,
// confidence PFM, camera) for bench_depth_stats.
//
// Runs ReconstructView on each view (one view at a time, every thread of the
// pool inside the view) and prints per view and in total: valid samples,
// wall seconds, CPU seconds, samples per CPU second, peak RSS.
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <iostream>
#include <opencv2/imgcodecs.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "wild_mvs/core/error.h"
#include "wild_mvs/core/reconstruct_view.h"
#include "wild_mvs/core/stats.h"
#include "wild_mvs/io/colmap.h"
#include "wild_mvs/io/depth_map_io.h"
#include "wild_mvs/io/image_files.h"
#include "wild_mvs/io/preview.h"

using namespace wild_mvs;

int main(int argc, char** argv) {
  if (argc < 3) {
    std::cerr << "usage: bench_mvs MODEL_DIR IMAGES_DIR [--threads N] "
                 "[--views i,j] [--max-image-size S] [--previews DIR] "
                 "[--grey] [--no-lvs] [--no-normal] [--no-color-scale] "
                 "[--min-views K] [--revisit-margin M] [--save DIR]\n";
    return 2;
  }
  try {
    int threads = 0;
    std::vector<int> views;
    std::string previews, save;
    MvsOptions opt;
    for (int i = 3; i < argc; ++i) {
      const std::string a = argv[i];
      auto next = [&]() -> std::string {
        if (i + 1 >= argc) throw wild_mvs::Error("missing value after " + a);
        return argv[++i];
      };
      if (a == "--threads") {
        threads = std::stoi(next());
      } else if (a == "--views") {
        std::stringstream ss(next());
        std::string tok;
        while (std::getline(ss, tok, ',')) views.push_back(std::stoi(tok));
      } else if (a == "--max-image-size") {
        opt.max_image_size = std::stoi(next());
      } else if (a == "--previews") {
        previews = next();
      } else if (a == "--save") {
        save = next();
      } else if (a == "--grey") {
        opt.ablation.color = false;
      } else if (a == "--no-lvs") {
        opt.ablation.local_view_selection = false;
      } else if (a == "--no-normal") {
        opt.ablation.optimize_normal = false;
      } else if (a == "--no-color-scale") {
        opt.ablation.optimize_color_scale = false;
      } else if (a == "--revisit-margin") {
        opt.growing.revisit_margin = std::stod(next());
      } else if (a == "--min-views") {
        opt.mpgc.min_active_views = std::stoi(next());
      } else {
        throw wild_mvs::Error("unknown option " + a);
      }
    }
    const Scene scene = ReadColmapModel(argv[1], argv[2]);
    if (views.empty())
      for (size_t v = 0; v < scene.views.size(); ++v) views.push_back(v);
    ImageOptions iopt;
    ImageCache cache(MakeSceneLoader(scene, iopt), iopt.cache_mb);
    ThreadPool pool(threads);
    long long total = 0;
    double wall = 0, cpu = 0;
    std::printf("%-24s %8s %8s %8s %10s %6s %6s\n", "view", "samples",
                "seconds", "cpu_s", "samples/cpu_s", "seeds", "visits");
    for (int v : views) {
      ViewReport rep;
      const DepthMap dm =
          ReconstructView(scene, v, cache, opt, &pool, &rep, cv::Mat());
      total += rep.samples;
      wall += rep.seconds;
      cpu += rep.cpu_seconds;
      std::printf("%-24s %8d %8.2f %8.2f %10.0f %6d %8lld\n",
                  scene.views[v].name.c_str(), rep.samples, rep.seconds,
                  rep.cpu_seconds,
                  rep.samples / std::max(1e-9, rep.cpu_seconds),
                  rep.seeds_accepted, rep.pixel_visits);
      for (const auto& f : rep.fallbacks) std::printf("  %s\n", f.c_str());
      if (!previews.empty()) {
        const std::string stem = previews + "/" + scene.views[v].Stem();
        cv::imwrite(stem + "_depth.png", DepthPreview(dm.depth));
        cv::imwrite(stem + "_normal.png", NormalPreview(dm.normal));
        cv::imwrite(stem + "_confidence.png", ConfidencePreview(dm.confidence));
      }
      if (!save.empty()) {
        std::vector<std::string> names;
        for (int nb : dm.neighbors) names.push_back(scene.views[nb].name);
        WriteDepthMapFiles(save, scene.views[v].Stem(), dm, names, false);
      }
      std::fflush(stdout);
    }
    std::printf(
        "TOTAL views=%zu samples=%lld seconds=%.2f cpu_seconds=%.2f "
        "samples_per_cpu_second=%.0f threads=%d peak_rss_mb=%.0f\n",
        views.size(), total, wall, cpu, total / std::max(1e-9, cpu),
        pool.size(), PeakRssMb());
  } catch (const std::exception& e) {
    std::cerr << "bench_mvs: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
