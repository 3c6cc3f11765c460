// Copyright wild_mvs authors.
#include "wild_mvs/cli/reconstruct_config.h"

#include "wild_mvs/cli/args.h"
#include "wild_mvs/core/error.h"

namespace wild_mvs {
namespace cli {
namespace {
const char* const kStages[] = {"sparse", "depth", "fuse", "mesh"};
}  // namespace

void RunOptions::Check() const {
  Require(threads >= 0 && threads <= 4096, "run.threads = ", threads,
          " must be in [0, 4096] (0 = one per core)");
  const auto list = SplitList(stages);
  Require(!list.empty(),
          "run.stages is empty: give a subset of sparse,depth,fuse,mesh");
  for (const std::string& s : list) {
    bool known = false;
    for (const char* k : kStages) known |= (s == k);
    Require(known, "run.stages: unknown stage '", s,
            "' (stages are sparse, depth, fuse, mesh)");
  }
}

bool RunOptions::HasStage(const std::string& stage) const {
  for (const std::string& s : SplitList(stages)) {
    if (s == stage) return true;
  }
  return false;
}

void ReconstructConfig::Check() const {
  run.Check();
  image.Check();
  tracker.Check();
  mvs.Check();
  fusion.Check();
  mesh.Check();
}

void RegisterOptions(OptionRegistry* registry, const std::string& prefix,
                     RunOptions* o) {
  registry
      ->Add(OptionRegistry::Join(prefix, "threads"), &o->threads,
            "worker threads, 0 = one per core; results do not depend on it")
      .Min(0)
      .Max(4096);
  registry
      ->Add(OptionRegistry::Join(prefix, "stages"), &o->stages,
            "stages of reconstruct: comma-separated subset of "
            "sparse,depth,fuse,mesh (sparse alone: only the sparse tracks, "
            "before --shard runs)")
      .Note("not empty");
}

void RegisterOptions(ReconstructConfig* c, OptionRegistry* registry) {
  RegisterOptions(registry, "run", &c->run);
  RegisterOptions(registry, "image", &c->image);
  // Sparse tracks from known poses (used when the dataset has no points).
  RegisterOptions(registry, "tracker", &c->tracker);
  // Per-view depth maps (Goesele et al. 2007).
  RegisterOptions(registry, "mvs", &c->mvs);
  // The filter of the finished depth maps (not the depth node's).
  RegisterOptions(registry, "consistency", &c->mvs.consistency);
  // Parts of the method turned off for experiments (--preset paper sets
  // some); the depth node does not register them.
  RegisterOptions(registry, "ablation", &c->mvs.ablation);
  // Fusion of the depth maps into one point cloud.
  RegisterOptions(registry, "fusion", &c->fusion);
  // Poisson mesh of the fused cloud.
  RegisterOptions(registry, "meshing", &c->mesh);
}

}  // namespace cli
}  // namespace wild_mvs
