// Copyright wild_mvs authors.
#include "wild_mvs/core/depth_sweep.h"

#include <algorithm>

#include "wild_mvs/core/error.h"

namespace wild_mvs {

void DepthSweepOptions::Check() const {
  Require(step >= 1, "mvs.sweep.step = ", step, " must be >= 1");
  Require(num_depths >= 2, "mvs.sweep.num_depths = ", num_depths,
          " must be >= 2");
  Require(num_views >= 1 && num_views <= kMaxNeighbors,
          "mvs.sweep.num_views = ", num_views, " must be in [1, ",
          kMaxNeighbors, "]");
  Require(min_score >= -1 && min_score <= 1,
          "mvs.sweep.min_score = ", min_score, " must be in [-1, 1]");
  Require(below_seeds >= 0, "mvs.sweep.below_seeds = ", below_seeds,
          " must be >= 0");
}

void RegisterOptions(OptionRegistry* registry, const std::string& prefix,
                     DepthSweepOptions* o) {
  auto key = [&prefix](const char* name) {
    return OptionRegistry::Join(prefix, name);
  };
  registry
      ->Add(key("step"), &o->step,
            "fallback depth sweep: test every step-th pixel")
      .Min(1);
  registry
      ->Add(key("num_depths"), &o->num_depths,
            "fallback depth sweep: depths tested (uniform in 1/z)")
      .Min(2);
  registry
      ->Add(key("num_views"), &o->num_views,
            "fallback depth sweep: score = mean of the best k NCCs")
      .Min(1)
      .Max(kMaxNeighbors);
  registry
      ->Add(key("min_score"), &o->min_score,
            "fallback depth sweep: seed only above this mean NCC")
      .Min(-1)
      .Max(1);
  registry
      ->Add(key("below_seeds"), &o->below_seeds,
            "also sweep (the pixels still empty) when fewer sparse features "
            "than this matched; 0 = only when none did")
      .Min(0);
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
  const int k = std::min<int>(options.num_views, context.views.size());
  const int cols = (W + options.step - 1) / options.step;
  const int rows = (H + options.step - 1) / options.step;
  std::vector<Seed> found(static_cast<size_t>(rows) * cols);
  std::vector<uint8_t> ok(found.size(), 0);
  const double inv0 = 1.0 / max_depth, inv1 = 1.0 / min_depth;
  const double cpu = RunParallel(pool, rows, [&](int gy) {
    PatchMatcher m(context, mpgc, local);
    const Eigen::Vector3d fronto(0, 0, -1);
    const int y = std::min(H - 1, gy * options.step + options.step / 2);
    for (int gx = 0; gx < cols; ++gx) {
      const int x = std::min(W - 1, gx * options.step + options.step / 2);
      if (!m.WindowInside(x, y)) continue;
      if (!mask.empty() && !mask.at<uint8_t>(y, x)) continue;
      double best = -2, best_z = 0;
      for (int d = 0; d < options.num_depths; ++d) {
        const double inv =
            inv0 + (inv1 - inv0) * d / (options.num_depths - 1.0);
        const double z = 1.0 / inv;
        const double s = m.PlaneScore(x, y, z, fronto, k);
        if (s > best) {
          best = s;
          best_z = z;
        }
      }
      if (best >= options.min_score) {
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
