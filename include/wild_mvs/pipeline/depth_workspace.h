// Copyright wild_mvs authors. Where the depth pipeline keeps its per-view
// maps (as COLMAP's mvs::Workspace): the matched ("raw") map of a view and
// its final map, after the consistency filter. The pipeline
// (depth_controller.h) never names a file: offline the maps live in an
// output folder (FileDepthWorkspace, file_workspace.h), live in memory
// (MemoryDepthWorkspace below).
//
// Views are named by keys: scene view indices offline, keyframe ids live.
// A map's `neighbors` hold keys of the same workspace.
#pragma once

#include <map>
#include <memory>
#include <mutex>
#include <utility>

#include "wild_mvs/core/depth_map.h"
#include "wild_mvs/core/geometric_consistency.h"
#include "wild_mvs/core/lru_cache.h"
#include "wild_mvs/core/reconstruct_view.h"

namespace wild_mvs {

// What a step of the pipeline made of one view.
struct ViewResult {
  DepthMap map;
  ViewReport report;             // matching: view selection, seeds, time
  bool filtered = false;         // the consistency filter ran on `map`
  ConsistencyStats consistency;  // its counts (filtered only)
  int neighbor_maps = 0;         // neighbours' maps it was checked against
};

class DepthWorkspace {
 public:
  enum class Stage { kRaw, kFinal };
  virtual ~DepthWorkspace() = default;
  // True when the workspace holds a complete map of `key` at `stage`.
  virtual bool Has(Stage stage, int key) const = 0;
  // The map of `key` at `stage` (neighbours as keys); throws Error when it
  // is missing or unreadable. Safe to call from several threads at once.
  virtual std::shared_ptr<const DepthMap> Read(Stage stage, int key) const = 0;
  // Valid samples of the complete map of `key` at `stage` (as recorded
  // when it was written), -1 = unknown.
  virtual long long Samples(Stage stage, int key) const = 0;
  // Stores `result` as the map of `key` at `stage` (complete or not at all).
  virtual void Write(Stage stage, int key, const ViewResult& result) = 0;
};

// Maps held in memory (the live path): shared, never copied. Reads are
// thread-safe while nobody writes.
class MemoryDepthWorkspace : public DepthWorkspace {
 public:
  bool Has(Stage stage, int key) const override;
  std::shared_ptr<const DepthMap> Read(Stage stage, int key) const override;
  long long Samples(Stage stage, int key) const override;
  void Write(Stage stage, int key, const ViewResult& result) override;
  // Holds `map` (shared) as the map of `key` at `stage`.
  void Put(Stage stage, int key, std::shared_ptr<const DepthMap> map);

 private:
  std::map<std::pair<Stage, int>, std::shared_ptr<const DepthMap>> maps_;
};

// Another workspace's maps, the last `capacity` read kept in memory (least
// recently read dropped first): the consistency filter reads each raw map
// once per view that has it as a neighbour, and views in order share most
// of their neighbours. Memory stays bounded by `capacity` maps beside the
// ones in use. Writes go to the other workspace (a cached map of the key
// and stage written is dropped). Reads are thread-safe.
class CachedDepthWorkspace : public DepthWorkspace {
 public:
  // `inner` must outlive this; capacity >= 1.
  CachedDepthWorkspace(DepthWorkspace* inner, int capacity);

  bool Has(Stage stage, int key) const override;
  std::shared_ptr<const DepthMap> Read(Stage stage, int key) const override;
  long long Samples(Stage stage, int key) const override;
  void Write(Stage stage, int key, const ViewResult& result) override;

 private:
  using Key = std::pair<Stage, int>;
  DepthWorkspace* inner_;
  size_t capacity_;
  mutable std::mutex mutex_;
  // The maps read, cost 1 each.
  mutable LruCache<Key, std::shared_ptr<const DepthMap>> recent_;
};

}  // namespace wild_mvs
