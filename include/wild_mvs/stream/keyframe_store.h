// Copyright wild_mvs authors. Keyframes of a live stream, bounded in count
// and bytes (ROS-free).
//
// A keyframe is an undistorted input image (CV_32FC3 linear RGB, the core's
// image type) with its pinhole camera (world-to-camera pose, camera.h
// conventions). Keyframes are numbered 0, 1, 2, ... in arrival order. The
// depth worker that owns a keyframe follows from its stamp alone
// (KeyframeOwner), so that workers agree on ownership whatever frames each
// of them saw.
//
// The store is bounded by `max_keyframes` and `max_mb`. Beyond a bound it
// evicts the least useful keyframe, never the newest:
//  1. keyframes that are done (reconstructed by this worker, or owned by
//     another worker) before keyframes still waiting for their depth map;
//  2. among those, the one whose viewpoint is farthest from the newest
//     keyframe (camera-centre distance in units of the median keyframe
//     baseline, plus the viewing-angle difference in units of 10 degrees):
//     it is the least likely to be a good neighbour for what comes next.
// Not thread-safe: StreamReconstructor guards it.
#pragma once

#include <cstddef>
#include <cstdint>
#include <map>
#include <memory>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "wild_mvs/core/camera.h"
#include "wild_mvs/core/option_registry.h"

namespace wild_mvs {

struct Keyframe {
  uint32_t id = 0;
  double stamp = 0;           // seconds (ROS time of the image)
  uint64_t stamp_ns = 0;      // the image's exact stamp (ns), passed through
  std::string frame_id;       // camera optical frame of the image
  Camera camera;              // of `image` (undistorted, maybe downscaled)
  cv::Mat image;              // CV_32FC3 linear RGB
  double image_scale = 1;     // image size / received image size
  bool owned = false;         // this worker reconstructs it
  int reconstructions = 0;    // depth maps produced so far
  double neighbor_score = 0;  // neighbour score at the last reconstruction
  bool done() const { return !owned || reconstructions > 0; }
  size_t Bytes() const;
};
using KeyframePtr = std::shared_ptr<Keyframe>;

// The depth worker (0 .. worker_count - 1) that reconstructs the keyframe
// with this image stamp (ns): a 64-bit mix of the stamp (SplitMix64's
// finaliser) modulo worker_count. It depends on the stamp only, never on
// the order or number of frames a worker received; keyframes spread evenly
// over the workers whatever the frame rate.
int KeyframeOwner(uint64_t stamp_ns, int worker_count);

struct KeyframeSelectionOptions {
  // A frame becomes a keyframe when its camera centre is at least this far
  // (metres) from the last keyframe's ...
  double min_baseline = 0.05;
  // ... or its viewing direction differs from it by at least this (degrees).
  double min_angle_deg = 5.0;
  void Check() const;
};

struct KeyframeStoreOptions {
  int max_keyframes = 40;  // count bound (>= 2)
  double max_mb = 512;     // image bytes bound, megabytes
  void Check() const;
};
// Register the fields under `prefix` (option_registry.h); the depth node
// uses prefix "" (keyframe_min_baseline, max_keyframes, ...).
void RegisterOptions(OptionRegistry* registry, const std::string& prefix,
                     KeyframeSelectionOptions* options);
void RegisterOptions(OptionRegistry* registry, const std::string& prefix,
                     KeyframeStoreOptions* options);

class KeyframeStore {
 public:
  explicit KeyframeStore(const KeyframeStoreOptions& options);

  // True when a frame with this camera is a new keyframe relative to the last
  // keyframe added (always true for the first one).
  bool IsNewKeyframe(const Camera& camera,
                     const KeyframeSelectionOptions& selection) const;
  // Adds a keyframe (its id must be larger than every id held) and evicts
  // beyond the bounds. Returns the evicted keyframes.
  std::vector<KeyframePtr> Add(KeyframePtr keyframe);
  KeyframePtr Get(uint32_t id) const;
  KeyframePtr Newest() const;
  // Every keyframe held, by increasing id.
  std::vector<KeyframePtr> All() const;
  size_t size() const { return keyframes_.size(); }
  size_t bytes() const { return bytes_; }
  void Clear();

  // How useful `k` is to keep, relative to the newest keyframe (larger =
  // more useful); exposed for tests.
  double Usefulness(const Keyframe& k) const;

 private:
  KeyframeStoreOptions options_;
  std::map<uint32_t, KeyframePtr> keyframes_;
  size_t bytes_ = 0;
};

}  // namespace wild_mvs
