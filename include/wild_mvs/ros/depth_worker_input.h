// Copyright wild_mvs authors. A depth worker's input (the depth node's
// ~role worker): the keyframes one selector publishes on `keyframes` and
// announces on `keyframe_index`, put in id order by a KeyframeReceiver
// (which fetches the missed ones from `get_keyframe`), each converted into
// a frame with its camera (intrinsics from its camera_info, the selector's
// pose) and the selector's session, keyframe id and sparse tracks. A
// keyframe that cannot be converted is dropped through the node's drop
// callback, naming the problem.
#pragma once

#include <ros/node_handle.h>
#include <ros/subscriber.h>

#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "wild_mvs/core/camera.h"
#include "wild_mvs/ros/depth_inputs.h"
#include "wild_mvs/ros/depth_messages.h"
#include "wild_mvs/ros/keyframe_link.h"
#include "wild_mvs/ros/params.h"
#include "wild_mvs/stream/stream_reconstructor.h"

namespace wild_mvs {
namespace ros1 {

// One keyframe of the selector, ready for the stream.
struct WorkerKeyframe {
  std::string topic;  // the keyframes topic, for messages
  DepthFrame frame;   // the selector's image and camera_info, shared
  Camera camera;      // intrinsics and the selector's pose
  uint64_t session_ns = 0;
  uint32_t keyframe_id = 0;
  std::vector<StreamReconstructor::StampedPoint> points;  // sparse tracks
};

class DepthWorkerInput {
 public:
  using KeyframeFn = std::function<void(const WorkerKeyframe&)>;
  using FrameFn = DepthInputs::FrameFn;

  // `options` and `inputs` (the node's, outliving this) are read when used
  // (world_frame, camera_info conversion, '/' of frame ids). Keyframes go
  // to `on_keyframe` on the front-end thread, in id order.
  DepthWorkerInput(const ros::NodeHandle& nh, const DepthNodeOptions& options,
                   DepthInputs* inputs, KeyframeReceiver::DropFn drop,
                   KeyframeFn on_keyframe);
  // Subscribes `keyframes` and `keyframe_index`: both go to `enqueue` (the
  // front end's queue) on the callback threads.
  void Subscribe(FrameFn enqueue);
  void Stop();  // unsubscribes
  // Front end: a queued keyframe or index message.
  void Process(const DepthFrame& f);

  std::string keyframes_topic() const { return receiver_.keyframes_topic(); }
  // The subscribed keyframes topic ("" before Subscribe), for the roscpp
  // queue-drop watch.
  std::string subscribed_topic() const { return keyframe_sub_.getTopic(); }
  // Keyframes received, fetched, lost and repeated, into the diagnostics.
  void AddStats(DepthInputStats* in) const;
  // "depth worker <i> of <n>, keyframes from ..." for the start message.
  std::string Describe() const;

 private:
  void Take(const wild_mvs::SelectedKeyframeConstPtr& k);

  ros::NodeHandle nh_;
  const DepthNodeOptions& options_;
  DepthInputs* inputs_;
  KeyframeReceiver::DropFn drop_;
  KeyframeFn on_keyframe_;
  KeyframeReceiver receiver_;
  ros::Subscriber keyframe_sub_, index_sub_;
};

}  // namespace ros1
}  // namespace wild_mvs
