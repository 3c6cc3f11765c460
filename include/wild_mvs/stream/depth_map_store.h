// Copyright wild_mvs authors. The depth maps of fused views, kept for the
// fusion's consistency checks with bounded memory (ROS-free; the fusion
// node's spill store).
//
// Hold() keeps a view's map and image in memory; beyond `max_mb` (estimated
// as 20 bytes per depth pixel plus the image) the oldest maps are spilled:
// written to the spill folder (depth + camera files, io/depth_map_io.h,
// stem view_<v>) and read back by Map() when the fusion needs them again.
// A spilled view's image is released (no colour from it afterwards) and
// its map comes back without neighbours. The spill folder is a new
// temporary folder, removed by the destructor, unless one is given.
// Not thread-safe: FusionSession guards it.
#pragma once

#include <cstddef>
#include <cstdint>
#include <deque>
#include <functional>
#include <map>
#include <memory>
#include <opencv2/core.hpp>
#include <string>

#include "wild_mvs/core/depth_map.h"

namespace wild_mvs {

class DepthMapStore {
 public:
  // problem, detail (the exception's message)
  using ErrorCallback =
      std::function<void(const std::string&, const std::string&)>;

  // Creates `spill_dir` when given (Error when it cannot), else a
  // temporary folder.
  DepthMapStore(double max_mb, const std::string& spill_dir);
  ~DepthMapStore();  // removes its own temporary folder
  DepthMapStore(const DepthMapStore&) = delete;
  DepthMapStore& operator=(const DepthMapStore&) = delete;

  // Holds view v, then spills the oldest held maps while over the bound
  // (never the last one held). A map that cannot be written stays in
  // memory; the failure goes to `on_error` and spilling stops until the
  // next Hold.
  void Hold(int v, DepthMap map, cv::Mat image,
            const ErrorCallback& on_error = nullptr);
  // View v's map, from memory or read back from the spill folder (view set
  // to v). Throws Error for a view never held (or forgotten by Clear).
  std::shared_ptr<const DepthMap> Map(int v) const;
  // View v's image (empty when spilled, unknown or held without one).
  cv::Mat Image(int v) const;
  bool InMemory(int v) const;
  // Forgets every view (spilled files stay until the destructor).
  void Clear();

  size_t bytes() const { return bytes_; }  // held in memory (estimate)
  // The estimate of one view: 20 bytes per depth pixel plus the image.
  static size_t HeldBytes(const DepthMap& map, const cv::Mat& image) {
    return map.depth.total() * 20 + image.total() * image.elemSize();
  }
  uint64_t spilled() const { return spilled_; }
  const std::string& dir() const { return dir_; }
  static std::string Stem(int v) { return "view_" + std::to_string(v); }

 private:
  struct Held {
    std::shared_ptr<const DepthMap> map;  // null when spilled
    cv::Mat image;
    size_t bytes = 0;
  };
  size_t max_bytes_;
  std::string dir_;
  bool own_dir_ = false;
  std::map<int, Held> held_;
  std::deque<int> order_;  // in memory, oldest first
  size_t bytes_ = 0;
  uint64_t spilled_ = 0;
};

}  // namespace wild_mvs
