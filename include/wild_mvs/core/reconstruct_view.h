// Copyright wild_mvs authors. The per-view MVS driver: global view
// selection, rescaling, seeding, region growing with MPGC matching, for one
// reference view (Goesele et al. 2007; docs/ALGORITHM.md sections 1-5).
#pragma once

#include <atomic>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "wild_mvs/core/ablation.h"
#include "wild_mvs/core/depth_map.h"
#include "wild_mvs/core/depth_sweep.h"
#include "wild_mvs/core/geometric_consistency.h"
#include "wild_mvs/core/global_view_selection.h"
#include "wild_mvs/core/image.h"
#include "wild_mvs/core/local_view_selection.h"
#include "wild_mvs/core/mpgc.h"
#include "wild_mvs/core/option_registry.h"
#include "wild_mvs/core/region_growing.h"
#include "wild_mvs/core/rescaling.h"
#include "wild_mvs/core/scene.h"
#include "wild_mvs/core/thread_pool.h"

namespace wild_mvs {

struct MvsOptions {
  GlobalViewSelectionOptions global;
  LocalViewSelectionOptions local;
  MpgcOptions mpgc;
  RegionGrowingOptions growing;
  DepthSweepOptions sweep;  // fallback seeding without sparse features
  // The filter of the finished maps against their neighbours' (run by the
  // command line's pipeline after every view's map exists; not by
  // ReconstructView nor the depth node). Registered by the command line.
  GeometricConsistencyOptions consistency;
  int max_image_size = 0;  // longest side of R's working image; 0 = any
  // Parts of the method turned off for experiments; not registered by
  // RegisterOptions below (the command line registers them as ablation.*;
  // the ROS nodes never do).
  AblationOptions ablation;
  void Check() const;
};
// Registers the fields under `prefix` (option_registry.h), e.g. "mvs",
// except `consistency` and `ablation` (the command line's).
void RegisterOptions(OptionRegistry* registry, const std::string& prefix,
                     MvsOptions* options);

// The paper's pipeline with the paper's values (Goesele et al. 2007,
// section 6 and MVE's dmrecon where the paper is silent): plain windows,
// no explain test, no photometric offset, revisits from any better
// candidate, no consistency filter. `--preset paper`; the ablation tests
// run on it.
MvsOptions PaperMvsOptions();

struct ViewReport {
  std::vector<int> neighbors;           // scene view indices (N)
  std::vector<double> neighbor_scores;  // g_R(V)
  std::vector<double> scales;           // scale_R(V) before rescaling
  double working_scale = 1;             // working / original size of R
  int width = 0, height = 0;            // working resolution
  int seeds_tried = 0, seeds_accepted = 0;
  int samples = 0;                     // valid depth samples in the result
  int planar_samples = 0;              // of them, filled by the planar prior
  int coarse_samples = 0;              // of them, filled by the coarse pass
  long long pixel_visits = 0;          // MPGC runs
  std::vector<std::string> fallbacks;  // "fallback: ..." notes
  double seconds = 0, cpu_seconds = 0;
  // As JSON: ViewReportJson (wild_mvs/io/report_json.h).
};

// Reconstructs the depth map of view `ref`. images serves full-resolution
// images (resized copies come from it). pool may be null (inline) and must
// not be the pool this call runs on (ThreadPool::ParallelFor). mask: CV_8U of
// the reference image's size, 0 = ignore (empty = none). Deterministic: the
// same output whatever the number of threads. Throws Error on bad input,
// and Cancelled when *cancel became true while it ran (another thread: a
// node shutting down; the growing stops within a few pixels per tile).
// points_per_view: scene.PointsPerView() when the caller reconstructs many
// views of one scene (computed once: it costs O(points x track length), i.e.
// grows with the collection); null = computed here.
DepthMap ReconstructView(
    const Scene& scene, int ref, ImageCache& images, const MvsOptions& options,
    ThreadPool* pool, ViewReport* report, const cv::Mat& mask = cv::Mat(),
    const std::vector<std::vector<int>>* points_per_view = nullptr,
    const std::atomic<bool>* cancel = nullptr);

}  // namespace wild_mvs
