// Copyright wild_mvs authors. Coarse fronto-parallel plane sweep: seeds for a
// reference view without usable sparse features (a fallback the paper does
// not need, since it always has SfM features).
#pragma once

#include <opencv2/core.hpp>
#include <vector>

#include "wild_mvs/core/mpgc.h"
#include "wild_mvs/core/option_registry.h"
#include "wild_mvs/core/region_growing.h"
#include "wild_mvs/core/thread_pool.h"

namespace wild_mvs {

struct DepthSweepOptions {
  // The sweep seeds the pixels still empty when fewer than this many sparse
  // features matched, >= 1 (1 = only when none matched).
  int below_seeds = 20;
  void Check() const;
};
// Registers the fields under `prefix` (option_registry.h), e.g. "mvs.sweep".
void RegisterOptions(OptionRegistry* registry, const std::string& prefix,
                     DepthSweepOptions* options);

// Seeds from the sweep over [min_depth, max_depth] (z in R). Deterministic;
// parallel over grid rows when pool is given. *pool_cpu_seconds += the CPU
// time spent on pool threads (RunParallel).
std::vector<Seed> SweepSeeds(const PatchContext& context,
                             const MpgcOptions& mpgc,
                             const LocalViewSelectionOptions& local,
                             const DepthSweepOptions& options, double min_depth,
                             double max_depth, const cv::Mat& mask,
                             ThreadPool* pool,
                             double* pool_cpu_seconds = nullptr);

}  // namespace wild_mvs
