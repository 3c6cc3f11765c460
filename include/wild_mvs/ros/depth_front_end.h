// Copyright wild_mvs authors. The depth node's front end: what its
// front-end thread does with one queued frame. An image is paired with its
// camera_info, its camera's intrinsics and pose are looked up, the
// StreamReconstructor's keyframe test decides on the pose, and only a
// keyframe's image is decoded and undistorted (DepthInputs); a selector
// then announces each new keyframe to the workers (KeyframeAnnouncer). A
// worker's keyframes (DepthWorkerInput) come with the selector's camera,
// session, keyframe id and sparse tracks. Bad input is dropped through the
// node's drop callback; keyframes evicted from the full keyframe store
// before their depth map are warned about (throttled).
#pragma once

#include <cstdint>
#include <string>

#include "wild_mvs/core/camera.h"
#include "wild_mvs/ros/depth_inputs.h"
#include "wild_mvs/ros/depth_worker_input.h"
#include "wild_mvs/ros/keyframe_link.h"
#include "wild_mvs/ros/params.h"
#include "wild_mvs/stream/stream_reconstructor.h"
#include "wild_mvs/stream/stream_reports.h"

namespace wild_mvs {
namespace ros1 {

class DepthFrontEnd {
 public:
  // Everything is the node's and outlives this; `announcer` is null but
  // for a selector. `name` prefixes the log messages (the node's
  // namespace).
  DepthFrontEnd(const std::string& name, const DepthNodeOptions& options,
                DepthInputs* inputs, StreamReconstructor* stream,
                KeyframeAnnouncer* announcer, DepthInputs::DropFn drop);
  // An image frame (standalone, selector).
  void ProcessImage(DepthFrame f);
  // A worker: one keyframe of the selector, in id order.
  void TakeKeyframe(const WorkerKeyframe& k);
  // Warns (throttled) about evictions not seen before; `total`:
  // StreamStats::evicted_waiting.
  void ReportEvictions(uint64_t total);
  uint64_t recent_evictions() const { return evictions_.RecentTotal(); }

 private:
  // Adds a frame whose camera (intrinsics and pose) is known to the
  // stream; only a keyframe's image is converted.
  StreamReconstructor::FrameStatus Add(const DepthFrame& f, const Camera& cam,
                                       const std::string& topic);

  std::string name_;
  const DepthNodeOptions& options_;
  DepthInputs* inputs_;
  StreamReconstructor* stream_;
  KeyframeAnnouncer* announcer_;
  DepthInputs::DropFn drop_;
  EvictionWatch evictions_{kErrorThrottle, kDropWindow};
};

}  // namespace ros1
}  // namespace wild_mvs
