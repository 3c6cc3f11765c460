// Copyright wild_mvs authors.
#include "wild_mvs/pipeline/depth_workspace.h"

#include "wild_mvs/core/error.h"

namespace wild_mvs {

bool MemoryDepthWorkspace::Has(Stage stage, int key) const {
  return maps_.count({stage, key}) > 0;
}

std::shared_ptr<const DepthMap> MemoryDepthWorkspace::Read(Stage stage,
                                                           int key) const {
  auto it = maps_.find({stage, key});
  Require(it != maps_.end(), "no ", stage == Stage::kRaw ? "matched" : "final",
          " depth map of view ", key, " in memory");
  return it->second;
}

long long MemoryDepthWorkspace::Samples(Stage stage, int key) const {
  auto it = maps_.find({stage, key});
  return it == maps_.end() ? -1 : it->second->CountValid();
}

void MemoryDepthWorkspace::Write(Stage stage, int key,
                                 const ViewResult& result) {
  Put(stage, key, std::make_shared<DepthMap>(result.map));
}

void MemoryDepthWorkspace::Put(Stage stage, int key,
                               std::shared_ptr<const DepthMap> map) {
  maps_[{stage, key}] = std::move(map);
}

}  // namespace wild_mvs
