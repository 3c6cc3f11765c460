// Copyright wild_mvs authors.
#include "wild_mvs/ros/depth_front_end.h"

#include <ros/console.h>

#include "wild_mvs/core/error.h"

namespace wild_mvs {
namespace ros1 {

using FrameStatus = StreamReconstructor::FrameStatus;

DepthFrontEnd::DepthFrontEnd(const std::string& name,
                             const DepthNodeOptions& options,
                             DepthInputs* inputs, StreamReconstructor* stream,
                             KeyframeAnnouncer* announcer,
                             DepthInputs::DropFn drop)
    : name_(name),
      options_(options),
      inputs_(inputs),
      stream_(stream),
      announcer_(announcer),
      drop_(std::move(drop)) {}

void DepthFrontEnd::ReportEvictions(uint64_t total) {
  if (evictions_.Update(total))
    ROS_WARN(
        "%s: %s", name_.c_str(),
        EvictionWarning(total, options_.stream.store, kErrorThrottle).c_str());
}

FrameStatus DepthFrontEnd::Add(const DepthFrame& f, const Camera& cam,
                               const std::string& topic) {
  FrameStatus status;
  try {
    status = stream_->AddFrame(f.stamp.toNSec(), f.frame_id, cam,
                               [this, &f](Camera* c, cv::Mat* image) {
                                 return inputs_->ConvertImage(f, c, image);
                               });
  } catch (const Error& e) {
    drop_(topic, "rejected frame", e.what());
    return FrameStatus::kDropped;
  }
  ReportEvictions(stream_->Stats().evicted_waiting);
  switch (status) {
    case FrameStatus::kOutOfOrder:
      drop_(topic, "stamp out of order (not after the previous frame)", "");
      break;
    case FrameStatus::kReset:
      ROS_WARN(
          "%s: time or pose jump at stamp %.3f: keyframes and tracks "
          "reset, starting again from this frame",
          name_.c_str(), f.stamp.toSec());
      break;
    default:
      break;
  }
  return status;
}

void DepthFrontEnd::TakeKeyframe(const WorkerKeyframe& k) {
  // The selector's session, numbering and tracks.
  stream_->FollowSession(k.session_ns);
  stream_->SetNextKeyframeId(k.keyframe_id);
  stream_->SetSparsePoints(k.points);
  Add(k.frame, k.camera, k.topic);
}

void DepthFrontEnd::ProcessImage(DepthFrame f) {
  const std::string image_topic = inputs_->ImageTopic(f);
  if (!inputs_->PairCameraInfo(&f)) return;
  if (stream_->IsOutOfOrder(f.stamp.toNSec())) {
    drop_(image_topic, "stamp out of order (not after the previous frame)", "");
    return;
  }
  // Intrinsics and pose first: the keyframe test needs only the pose, and
  // only a keyframe's image is decoded and undistorted.
  Camera cam;
  if (!inputs_->CameraFromInfo(f, &cam) || !inputs_->LookupPose(f, &cam))
    return;
  const FrameStatus status = Add(f, cam, image_topic);
  // A selector hands each new keyframe to the workers.
  if (announcer_ &&
      (status == FrameStatus::kKeyframe || status == FrameStatus::kReset)) {
    StreamReconstructor::KeyframeInfo info;
    if (stream_->Newest(&info) && info.stamp_ns == f.stamp.toNSec())
      announcer_->Publish(info, f, cam, stream_->TrackedPoints());
  }
}

}  // namespace ros1
}  // namespace wild_mvs
