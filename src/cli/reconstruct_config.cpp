// Copyright wild_mvs authors.
#include "wild_mvs/cli/reconstruct_config.h"

#include <limits>

#include "wild_mvs/cli/args.h"
#include "wild_mvs/core/error.h"

namespace wild_mvs {
namespace cli {
namespace {
constexpr int kIntMax = std::numeric_limits<int>::max();
constexpr double kInf = std::numeric_limits<double>::infinity();
const char* const kStages[] = {"depth", "fuse", "mesh"};
}  // namespace

void RunOptions::Check() const {
  Require(threads >= 0, "run.threads = ", threads,
          " must be >= 0 (0 = one per core)");
  const auto list = SplitList(stages);
  Require(!list.empty(),
          "run.stages is empty: give a subset of depth,fuse,mesh");
  for (const std::string& s : list) {
    bool known = false;
    for (const char* k : kStages) known |= (s == k);
    Require(known, "run.stages: unknown stage '", s,
            "' (stages are depth, fuse, mesh)");
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
}

void RegisterOptions(ReconstructConfig* c, OptionSet* set) {
  set->Add("run.threads", &c->run.threads,
           "worker threads, 0 = one per core; results do not depend on it", 0,
           4096);
  set->Add("run.stages", &c->run.stages,
           "stages of reconstruct: comma-separated subset of depth,fuse,mesh");

  set->Add("image.linearize", &c->image.linearize,
           "apply the inverse sRGB curve at load (match in linear radiance)");
  set->Add("image.cache_mb", &c->image.cache_mb,
           "image cache budget in MB (least recently used images evicted)",
           1e-3, kInf);
  set->Add("image.max_image_size", &c->image.max_image_size,
           "downscale images (and cameras) whose longest side exceeds this "
           "many pixels; 0 = full size",
           0, kIntMax);
}

}  // namespace cli
}  // namespace wild_mvs
