// Copyright wild_mvs authors. Global view selection benchmark: the cost per
// reference view in collections of growing size with a fixed track length
// and fixed points per view (test/support/random_collection.h).
//
//   bench_view_selection [--views 100,250,500] [--points-per-view 1500]
//                        [--track-length 12] [--refs 100]
//
// Per collection size: the mean CPU time of SelectGlobalViews per reference
// view (over --refs views spread over the collection), of the per-view
// scene.PointsPerView() that ReconstructView used to compute, and a checksum
// of the selections (neighbours and score bits) to compare runs.
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <sstream>
#include <string>
#include <vector>

#include "../test/support/random_collection.h"
#include "wild_mvs/core/error.h"
#include "wild_mvs/core/global_view_selection.h"
#include "wild_mvs/core/stats.h"

using namespace wild_mvs;  // NOLINT

namespace {

std::vector<int> ParseList(const std::string& s) {
  std::vector<int> out;
  std::stringstream ss(s);
  std::string item;
  while (std::getline(ss, item, ',')) out.push_back(std::stoi(item));
  return out;
}

uint64_t Mix(uint64_t h, uint64_t v) {
  h ^= v + 0x9E3779B97F4A7C15ull + (h << 6) + (h >> 2);
  return h;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    std::vector<int> sizes{100, 250, 500};
    int ppv_count = 1500, track = 12, refs = 100;
    for (int i = 1; i < argc; ++i) {
      const std::string a = argv[i];
      Require(i + 1 < argc, "bench_view_selection: ", a, " needs a value");
      const std::string v = argv[++i];
      if (a == "--views") {
        sizes = ParseList(v);
      } else if (a == "--points-per-view") {
        ppv_count = std::stoi(v);
      } else if (a == "--track-length") {
        track = std::stoi(v);
      } else if (a == "--refs") {
        refs = std::stoi(v);
      } else {
        throw Error(Msg("bench_view_selection: unknown option ", a));
      }
    }
    std::printf(
        "views\tpoints\tmean_track\tselect_ms_per_view\t"
        "points_per_view_ms_per_call\tchecksum\n");
    for (int n : sizes) {
      const Scene scene =
          testing::RandomCollection(n, ppv_count, track, 1000u + n);
      size_t obs = 0;
      for (const SparsePoint& p : scene.points) obs += p.track.size();
      const int k = std::min(refs, n);
      double t0 = CpuSeconds();
      std::vector<std::vector<int>> ppv;
      for (int i = 0; i < k; ++i) ppv = scene.PointsPerView();
      const double ppv_ms = 1e3 * (CpuSeconds() - t0) / k;
      const GlobalViewSelectionOptions opt;
      uint64_t sum = 0;
      t0 = CpuSeconds();
      for (int i = 0; i < k; ++i) {
        const int ref = static_cast<int>(static_cast<int64_t>(i) * n / k);
        const GlobalViewSelection sel = SelectGlobalViews(scene, ref, ppv, opt);
        for (size_t j = 0; j < sel.neighbors.size(); ++j) {
          uint64_t bits;
          std::memcpy(&bits, &sel.scores[j], sizeof(bits));
          sum = Mix(Mix(sum, sel.neighbors[j]), bits);
        }
      }
      const double sel_ms = 1e3 * (CpuSeconds() - t0) / k;
      std::printf("%d\t%zu\t%.1f\t%.3f\t%.3f\t%016llx\n", n,
                  scene.points.size(),
                  static_cast<double>(obs) / scene.points.size(), sel_ms,
                  ppv_ms, static_cast<unsigned long long>(sum));
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "bench_view_selection: %s\n", e.what());
    return 1;
  }
  return 0;
}
