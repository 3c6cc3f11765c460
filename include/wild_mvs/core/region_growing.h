// Copyright wild_mvs authors. Region growing (paper section 6.1 /
// docs/ALGORITHM.md section 5), parallel over image tiles and deterministic.
//
// The image is cut into tiles coloured 2 x 2 (same-coloured tiles never
// touch). Growth runs in phases: in a phase every tile of one colour grows in
// parallel from its own priority queue (highest expected confidence first),
// writing only its own pixels; candidates for pixels of other tiles go to
// those tiles' inboxes, merged in a fixed order after the phase. Phases
// repeat over the four colours until every queue is empty. The result does
// not depend on the number of threads.
#pragma once

#include <atomic>
#include <functional>
#include <opencv2/core.hpp>
#include <vector>

#include "wild_mvs/core/depth_map.h"
#include "wild_mvs/core/mpgc.h"
#include "wild_mvs/core/option_registry.h"
#include "wild_mvs/core/thread_pool.h"

namespace wild_mvs {

struct RegionGrowingOptions {
  // A pixel that already holds a depth is matched again only from a
  // candidate whose expected mean NCC beats the stored one by more than
  // this, in NCC units, [0, 2] (paper: 0).
  double revisit_margin = 0.1;
  void Check() const;
};
// Registers the fields under `prefix` (option_registry.h), e.g. "mvs.growing".
void RegisterOptions(OptionRegistry* registry, const std::string& prefix,
                     RegionGrowingOptions* options);

struct Seed {
  int x = 0, y = 0;  // pixel (column, row) of R's working image
  double depth = 0;  // z
};

struct GrowStats {
  int seeds_tried = 0, seeds_accepted = 0;
  long long pixel_visits = 0;  // MPGC runs, seeds included
  int phases = 0;
  double cpu_seconds = 0;  // CPU time of the work run on pool threads
                           // (the calling thread's own time excluded)
};

// Runs body(i) for i in [0, n) on the pool (inline when null) and returns
// the CPU seconds the bodies used on threads other than the caller (add the
// caller's own thread CPU time for the total).
double RunParallel(ThreadPool* pool, int n,
                   const std::function<void(int)>& body);

// CPU seconds used so far by the calling thread.
double ThreadCpuSeconds();

// Grows depth/normal/confidence (CV_32F / CV_32FC3 / CV_32F of R's working
// size, filled by the caller with zeros or earlier results) from `seeds`,
// matched fronto-parallel. mask (CV_8U of the working size, may be empty):
// 0 = never seed or grow there. pool may be null (inline). When *cancel
// becomes true (another thread), growing stops within a few pixels per
// tile and the maps hold what grew so far.
void GrowRegions(const PatchContext& context, const MpgcOptions& mpgc,
                 const LocalViewSelectionOptions& local,
                 const RegionGrowingOptions& options,
                 const std::vector<Seed>& seeds, const cv::Mat& mask,
                 ThreadPool* pool, cv::Mat* depth, cv::Mat* normal,
                 cv::Mat* confidence, GrowStats* stats,
                 const std::atomic<bool>* cancel = nullptr);

}  // namespace wild_mvs
