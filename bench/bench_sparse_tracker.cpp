// Copyright wild_mvs authors. Timing and quality of the sparse tracker on a
// dataset (cameras only; existing points are ignored).
//   bench_sparse_tracker DATASET [max_features] [feature_max_image_size]
//   [threads]
// Prints feature extraction and matching/triangulation times, point count,
// track-length histogram and reprojection error percentiles.
#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <iostream>
#include <vector>

#include "wild_mvs/core/error.h"
#include "wild_mvs/core/image.h"
#include "wild_mvs/core/sparse_tracker.h"
#include "wild_mvs/core/thread_pool.h"
#include "wild_mvs/core/triangulation.h"
#include "wild_mvs/io/dataset.h"
#include "wild_mvs/io/image_files.h"

using Clock = std::chrono::steady_clock;

static double Seconds(Clock::time_point a, Clock::time_point b) {
  return std::chrono::duration<double>(b - a).count();
}

int main(int argc, char** argv) {
  using namespace wild_mvs;
  if (argc < 2) {
    std::cerr << "usage: " << argv[0]
              << " DATASET [max_features] [feature_max_image_size] [threads]\n";
    return 2;
  }
  try {
    DatasetOptions dopt;
    dopt.path = argv[1];
    const Scene scene = LoadDataset(dopt);
    TrackerOptions opt;
    if (argc > 2) opt.features.max_features = std::atoi(argv[2]);
    if (argc > 3) opt.features.max_image_size = std::atoi(argv[3]);
    const int threads = argc > 4 ? std::atoi(argv[4]) : 2;
    opt.Check();
    ThreadPool pool(threads);
    ImageCache cache(MakeSceneLoader(scene, ImageOptions()), 512);

    const auto t0 = Clock::now();
    const int n = static_cast<int>(scene.views.size());
    std::vector<Features> feats(n);
    pool.ParallelFor(n, [&](int i) {
      feats[i] = ExtractFeatures(*cache.Get(i), opt.features);
    });
    const auto t1 = Clock::now();
    SparseTracker tracker(opt, &pool);
    for (int i = 0; i < n; ++i) {
      tracker.AddView(i, scene.views[i].camera, std::move(feats[i]));
    }
    const std::vector<SparsePoint> pts = tracker.Points();
    const auto t2 = Clock::now();

    const TrackerStats st = tracker.Stats();
    std::vector<double> err;
    std::vector<int> hist(10, 0);
    for (const SparsePoint& p : pts) {
      hist[std::min<size_t>(p.track.size(), 9)]++;
      for (const Observation& o : p.track) {
        err.push_back(
            ReprojectionError(scene.views[o.view].camera, p.xyz, o.xy));
      }
    }
    std::sort(err.begin(), err.end());
    auto pct = [&err](double f) {
      return err.empty() ? 0.0
                         : err[std::min(err.size() - 1,
                                        static_cast<size_t>(f * err.size()))];
    };
    std::cout << "dataset " << argv[1] << ": " << n << " views, " << st.features
              << " features, " << st.pairs_matched << " pairs, " << st.matches
              << " matches, " << st.tracks << " tracks ("
              << st.conflicting_tracks << " conflicting), " << pts.size()
              << " points, " << err.size()
              << " observations\n  track lengths 2..9+:";
    for (int k = 2; k < 10; ++k) std::cout << " " << hist[k];
    std::cout << "\n  reprojection error median " << pct(0.5) << " px, p95 "
              << pct(0.95) << " px, max " << pct(1.0) << " px\n"
              << "  time: features " << Seconds(t0, t1)
              << " s, matching+tracks " << Seconds(t1, t2) << " s (" << threads
              << " threads); tracker memory " << tracker.bytes() / 1e6
              << " MB\n";
  } catch (const Error& e) {
    std::cerr << "error: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
