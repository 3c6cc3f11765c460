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

CachedDepthWorkspace::CachedDepthWorkspace(DepthWorkspace* inner, int capacity)
    : inner_(inner), capacity_(static_cast<size_t>(capacity)) {
  Require(inner != nullptr && capacity >= 1,
          "a cached workspace needs a workspace and a capacity >= 1");
}

bool CachedDepthWorkspace::Has(Stage stage, int key) const {
  return inner_->Has(stage, key);
}

std::shared_ptr<const DepthMap> CachedDepthWorkspace::Read(Stage stage,
                                                           int key) const {
  const Key k{stage, key};
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (const auto* hit = recent_.Find(k)) return *hit;
  }
  // Read outside the lock: other threads' reads go on meanwhile (two may
  // read the same map at once; both get the same contents).
  std::shared_ptr<const DepthMap> map = inner_->Read(stage, key);
  std::lock_guard<std::mutex> lock(mutex_);
  if (const auto* hit = recent_.Find(k)) return *hit;
  recent_.Insert(k, map, 1);
  recent_.Evict(capacity_);
  return map;
}

long long CachedDepthWorkspace::Samples(Stage stage, int key) const {
  return inner_->Samples(stage, key);
}

void CachedDepthWorkspace::Write(Stage stage, int key,
                                 const ViewResult& result) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    recent_.Erase(Key{stage, key});
  }
  inner_->Write(stage, key, result);
}

}  // namespace wild_mvs
