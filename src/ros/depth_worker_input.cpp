// Copyright wild_mvs authors.
#include "wild_mvs/ros/depth_worker_input.h"

#include "wild_mvs/core/error.h"
#include "wild_mvs/ros/conversions.h"

namespace wild_mvs {
namespace ros1 {

DepthWorkerInput::DepthWorkerInput(const ros::NodeHandle& nh,
                                   const DepthNodeOptions& options,
                                   DepthInputs* inputs,
                                   KeyframeReceiver::DropFn drop,
                                   KeyframeFn on_keyframe)
    : nh_(nh),
      options_(options),
      inputs_(inputs),
      drop_(drop),
      on_keyframe_(std::move(on_keyframe)),
      receiver_(
          nh, kRepairDelay,
          [this](const wild_mvs::SelectedKeyframeConstPtr& k) { Take(k); },
          std::move(drop)) {}

void DepthWorkerInput::Subscribe(FrameFn enqueue) {
  keyframe_sub_ = nh_.subscribe<wild_mvs::SelectedKeyframe>(
      "keyframes", kKeyframeQueueSize,
      [enqueue](const wild_mvs::SelectedKeyframeConstPtr& k) {
        DepthFrame f;
        f.keyframe = k;
        f.stamp = k->header.stamp;
        enqueue(std::move(f));
      });
  index_sub_ = nh_.subscribe<wild_mvs::KeyframeIndex>(
      "keyframe_index", 10,
      [enqueue](const wild_mvs::KeyframeIndexConstPtr& k) {
        DepthFrame f;
        f.index = k;
        enqueue(std::move(f));
      });
}

void DepthWorkerInput::Stop() {
  keyframe_sub_.shutdown();
  index_sub_.shutdown();
}

void DepthWorkerInput::Process(const DepthFrame& f) {
  if (f.keyframe) receiver_.OnKeyframe(f.keyframe);
  if (f.index) receiver_.OnIndex(f.index);
}

void DepthWorkerInput::Take(const wild_mvs::SelectedKeyframeConstPtr& k) {
  const std::string topic = receiver_.keyframes_topic();
  if (inputs_->NoSlash(k->camera_pose.header.frame_id) !=
      options_.world_frame) {
    drop_(topic, "camera_pose frame is not the world frame",
          "'" + k->camera_pose.header.frame_id + "' vs '" +
              options_.world_frame + "'");
    return;
  }
  WorkerKeyframe w;
  w.topic = topic;
  DepthFrame& f = w.frame;
  f.stamp = k->header.stamp;
  f.frame_id = inputs_->NoSlash(k->header.frame_id);
  // The selector's messages, shared (no copy of the pixels).
  if (!k->image.data.empty())
    f.raw = sensor_msgs::ImageConstPtr(k, &k->image);
  else if (!k->compressed.data.empty())
    f.compressed = sensor_msgs::CompressedImageConstPtr(k, &k->compressed);
  if (!f.raw && !f.compressed) {
    drop_(topic, "keyframe without an image", "");
    return;
  }
  f.info = sensor_msgs::CameraInfoConstPtr(k, &k->camera_info);
  f.rectified = k->rectified;
  if (!inputs_->CameraFromInfo(f, &w.camera)) return;
  try {
    SetCameraPose(k->camera_pose.pose, &w.camera);
  } catch (const Error& e) {
    drop_(topic, "invalid camera_pose", e.what());
    return;
  }
  w.session_ns = k->session.toNSec();
  w.keyframe_id = k->keyframe_id;
  w.points = StampedPointsFromMsg(k->points);
  on_keyframe_(w);
}

void DepthWorkerInput::AddStats(DepthInputStats* in) const {
  const KeyframeReceiver::Stats r = receiver_.stats();
  in->keyframes_received = r.received;
  in->keyframes_fetched = r.fetched;
  in->keyframes_lost = r.lost;
  in->keyframes_repeated = r.repeated;
  // The front end's queue also carries the index messages: count keyframes.
  in->received = r.received;
}

std::string DepthWorkerInput::Describe() const {
  return Msg("depth worker ", options_.stream.worker_index, " of ",
             options_.stream.worker_count, ", keyframes from ",
             keyframes_topic(), " (missed ones from ",
             nh_.resolveName("get_keyframe"), "), world frame '",
             options_.world_frame, "'");
}

}  // namespace ros1
}  // namespace wild_mvs
