// Copyright wild_mvs authors. Keyframes from one keyframe selector to several
// depth workers (the depth node's ~role selector / worker, docs/ROS.md).
//
// The selector is the only node that decides what a keyframe is. It
// publishes each keyframe (the received image and camera_info, the pose,
// the sparse tracks) on ~keyframes with consecutive ids per session, the
// list of its recent keyframes on ~keyframe_index (with every keyframe and
// once per second), and serves the keyframes it still holds on
// ~get_keyframe. A worker takes every keyframe it receives (ownership is a
// hash of the stamp, KeyframeOwner, so it needs no agreement with the other
// workers on which frames they saw) and fetches what it missed: a gap in
// the ids at once, a keyframe the index announced after repair_delay
// (KeyframeSequencer, stream/keyframe_sequencer.h, decides; this file
// carries the messages and calls the service).
#pragma once

#include <ros/node_handle.h>
#include <ros/publisher.h>
#include <ros/service_client.h>
#include <ros/service_server.h>
#include <ros/subscriber.h>
#include <wild_mvs/GetKeyframe.h>
#include <wild_mvs/KeyframeIndex.h>
#include <wild_mvs/SelectedKeyframe.h>

#include <cstdint>
#include <functional>
#include <mutex>
#include <string>
#include <vector>

#include "wild_mvs/core/camera.h"
#include "wild_mvs/ros/depth_inputs.h"
#include "wild_mvs/stream/keyframe_history.h"
#include "wild_mvs/stream/keyframe_sequencer.h"
#include "wild_mvs/stream/stream_reconstructor.h"

namespace wild_mvs {
namespace ros1 {

// The selector's side: ~keyframes, ~keyframe_index, ~get_keyframe.
class KeyframeAnnouncer {
 public:
  KeyframeAnnouncer(const ros::NodeHandle& private_nh,
                    const std::string& world_frame, int history);
  // Publishes keyframe `info`, made from frame `f` (with its camera_info)
  // whose camera pose is `camera`'s, with the selector's sparse tracks.
  void Publish(const StreamReconstructor::KeyframeInfo& info,
               const DepthFrame& f, const Camera& camera,
               const std::vector<StreamReconstructor::StampedPoint>& points);
  // Publishes the index again (a steady timer: workers and the fusion node
  // learn of a keyframe whose messages they missed).
  void PublishIndex();
  uint64_t published() const;
  uint64_t served() const;

 private:
  bool OnGet(wild_mvs::GetKeyframe::Request& req,
             wild_mvs::GetKeyframe::Response& res);
  void PublishIndexLocked();

  ros::NodeHandle pnh_;
  std::string world_frame_;
  ros::Publisher keyframe_pub_, index_pub_;
  ros::ServiceServer get_srv_;
  mutable std::mutex mutex_;
  // The newest keyframes of the current session, consecutive ids.
  KeyframeHistory<wild_mvs::SelectedKeyframeConstPtr> history_;
  uint64_t published_ = 0, served_ = 0;
};

// SparsePoints of stamped points (core pixels -> ROS pixel convention, -0.5).
wild_mvs::SparsePoints SparsePointsToMsg(
    const std::vector<StreamReconstructor::StampedPoint>& points,
    const std::string& world_frame);

// The worker's side: orders what arrives on `keyframes` and
// `keyframe_index` (both queued to the node's front end by the callbacks)
// into the keyframes to process, fetching the missing ones from
// `get_keyframe`. Front-end thread only (Next*), except the counters.
class KeyframeReceiver {
 public:
  using ProcessFn =
      std::function<void(const wild_mvs::SelectedKeyframeConstPtr&)>;
  // topic, problem, detail
  using DropFn = std::function<void(const std::string&, const std::string&,
                                    const std::string&)>;
  KeyframeReceiver(const ros::NodeHandle& nh, double repair_delay,
                   ProcessFn process, DropFn drop);
  // A keyframe message: the ones missing before it are fetched first,
  // repeats are skipped; each keyframe goes to `process` once, in order.
  void OnKeyframe(const wild_mvs::SelectedKeyframeConstPtr& msg);
  // An index message: keyframes it lists that have not arrived within
  // repair_delay of their first announcement are fetched.
  void OnIndex(const wild_mvs::KeyframeIndexConstPtr& msg);

  struct Stats {
    uint64_t received = 0;  // keyframe messages taken from the topic
    uint64_t fetched = 0;   // fetched from get_keyframe
    uint64_t lost = 0;      // missed and not to be had from the selector
    uint64_t repeated = 0;  // messages of keyframes already taken
  };
  Stats stats() const;
  std::string keyframes_topic() const;

 private:
  void Take(const wild_mvs::SelectedKeyframeConstPtr& msg);
  // Fetches keyframes [next_id, end) of the sequencer's session, in order.
  void Fetch(uint32_t end);

  ros::NodeHandle nh_;
  KeyframeSequencer sequencer_;  // what to take, skip and fetch
  ProcessFn process_;
  DropFn drop_;
  ros::ServiceClient get_client_;
  mutable std::mutex stats_mutex_;
  Stats stats_;
};

}  // namespace ros1
}  // namespace wild_mvs
