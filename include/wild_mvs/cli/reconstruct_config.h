// Copyright wild_mvs authors. Every option of `wild_mvs reconstruct` (and of
// sparse / fuse / mesh) in one struct, with its YAML key and flag.
//
// The keys are section.key where the section names the option struct:
//   run.*      the tool itself (threads, stages)
//   image.*    ImageOptions (image loading and cache)
//   tracker.*  TrackerOptions (sparse tracks from known poses;
//              tracker.features.* its FeatureOptions)
//   mvs.*      MvsOptions (mvs.global, mvs.local, mvs.mpgc, mvs.growing,
//              mvs.sweep, mvs.consistency: the per-view depth maps)
//   ablation.* AblationOptions (MvsOptions::ablation: parts of the method
//              turned off for experiments; not read by the ROS nodes)
//   fusion.*   FusionOptions (consistency-checked fusion)
//   meshing.*  MeshingOptions (screened Poisson, trimming, decimation)
// Keys are the C++ member names, so the headers document them; each struct
// registers its fields beside its definition (core/option_registry.h), with
// the valid range its Check() states. The depth node reads the same mvs.* and
// tracker.* keys from ~mvs/... and ~tracker/... (docs/ROS.md).
// The default config file config/reconstruct.yaml is exactly
// `wild_mvs reconstruct --dump-config` with the defaults, written by
// wild_mvs_write_config (a test checks it).
#pragma once

#include <string>
#include <vector>

#include "wild_mvs/cli/option_set.h"
#include "wild_mvs/core/fusion.h"
#include "wild_mvs/core/image.h"
#include "wild_mvs/core/meshing.h"
#include "wild_mvs/core/reconstruct_view.h"
#include "wild_mvs/core/sparse_tracker.h"

namespace wild_mvs {
namespace cli {

struct RunOptions {
  // Worker threads; 0 = one per core. Results do not depend on it.
  int threads = 0;
  // Stages of `reconstruct`, comma-separated subset of sparse,depth,fuse,mesh.
  // "depth" computes the sparse tracks itself when the dataset has none;
  // "sparse" alone computes only them (OUT/sparse), e.g. before --shard runs.
  std::string stages = "depth,fuse,mesh";
  void Check() const;
  bool HasStage(const std::string& stage) const;
};
// Registers the fields under `prefix` ("run").
void RegisterOptions(OptionRegistry* registry, const std::string& prefix,
                     RunOptions* options);

struct ReconstructConfig {
  RunOptions run;
  ImageOptions image;
  TrackerOptions tracker;
  MvsOptions mvs;
  FusionOptions fusion;
  MeshingOptions mesh;
  // Runs every struct's Check() (errors name section.key and the value).
  void Check() const;
  // The image loader's options: image.* with mvs.ablation.linearize.
  ImageOptions LoaderOptions() const {
    ImageOptions o = image;
    o.linearize = mvs.ablation.linearize;
    return o;
  }
};

// Registers every field of `config` under its section.key.
void RegisterOptions(ReconstructConfig* config, OptionRegistry* registry);

}  // namespace cli
}  // namespace wild_mvs
