// Copyright wild_mvs authors.
#include "wild_mvs/core/depth_sweep.h"

#include <algorithm>

#include "wild_mvs/core/error.h"

namespace wild_mvs {

namespace {
constexpr int kStep = 8;           // test every kStep-th pixel on a grid
constexpr int kNumDepths = 64;     // depths, uniform in 1/z over the range
constexpr int kNumViews = 2;       // score = mean of the best k NCCs
constexpr double kMinScore = 0.6;  // seed only above this mean NCC
}  // namespace

void DepthSweepOptions::Check() const {
  Require(below_seeds >= 1, "mvs.sweep.below_seeds = ", below_seeds,
          " must be >= 1 (1 = only when no sparse feature matched)");
}

void RegisterOptions(OptionRegistry* registry, const std::string& prefix,
                     DepthSweepOptions* o) {
  registry
      ->Add(OptionRegistry::Join(prefix, "below_seeds"), &o->below_seeds,
            "seed the pixels still empty from a fronto-parallel depth sweep "
            "when fewer sparse features than this matched (1 = only when "
            "none did)")
      .Min(1);
}

std::vector<Seed> SweepSeeds(const PatchContext& context,
                             const MpgcOptions& mpgc,
                             const LocalViewSelectionOptions& local,
                             const DepthSweepOptions& options, double min_depth,
                             double max_depth, const cv::Mat& mask,
                             ThreadPool* pool, double* pool_cpu_seconds) {
  options.Check();
  std::vector<Seed> seeds;
  if (!(min_depth > 0) || !(max_depth > min_depth) || context.views.empty())
    return seeds;
  const int W = context.ref_image.width, H = context.ref_image.height;
  const int k = std::min<int>(kNumViews, context.views.size());
  const int cols = (W + kStep - 1) / kStep;
  const int rows = (H + kStep - 1) / kStep;
  std::vector<Seed> found(static_cast<size_t>(rows) * cols);
  std::vector<uint8_t> ok(found.size(), 0);
  const double inv0 = 1.0 / max_depth, inv1 = 1.0 / min_depth;
  const double cpu = RunParallel(pool, rows, [&](int gy) {
    PatchMatcher m(context, mpgc, local);
    const Eigen::Vector3d fronto(0, 0, -1);
    const int y = std::min(H - 1, gy * kStep + kStep / 2);
    for (int gx = 0; gx < cols; ++gx) {
      const int x = std::min(W - 1, gx * kStep + kStep / 2);
      if (!m.WindowInside(x, y)) continue;
      if (!mask.empty() && !mask.at<uint8_t>(y, x)) continue;
      double best = -2, best_z = 0;
      for (int d = 0; d < kNumDepths; ++d) {
        const double inv = inv0 + (inv1 - inv0) * d / (kNumDepths - 1.0);
        const double z = 1.0 / inv;
        const double s = m.PlaneScore(x, y, z, fronto, k);
        if (s > best) {
          best = s;
          best_z = z;
        }
      }
      if (best >= kMinScore) {
        const size_t i = static_cast<size_t>(gy) * cols + gx;
        found[i] = Seed{x, y, best_z};
        ok[i] = 1;
      }
    }
  });
  if (pool_cpu_seconds) *pool_cpu_seconds += cpu;
  for (size_t i = 0; i < found.size(); ++i)
    if (ok[i]) seeds.push_back(found[i]);
  return seeds;
}

}  // namespace wild_mvs
