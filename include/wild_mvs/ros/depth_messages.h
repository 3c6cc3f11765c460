// Copyright wild_mvs authors. The depth node's messages around the ROS-free
// StreamReconstructor: its outputs built from a StreamResult and published
// (the images and points only when subscribed), the SparsePoints input as
// stamped points, and its diagnostics.
#pragma once

#include <diagnostic_updater/DiagnosticStatusWrapper.h>
#include <image_transport/image_transport.h>
#include <ros/node_handle.h>
#include <ros/publisher.h>
#include <wild_mvs/SparsePoints.h>

#include <cstdint>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "wild_mvs/ros/diagnostics.h"
#include "wild_mvs/ros/params.h"
#include "wild_mvs/stream/drop_counter.h"
#include "wild_mvs/stream/stream_reconstructor.h"

namespace wild_mvs {
namespace ros1 {

// The outputs in the private namespace (~name), each with the source
// image's header: depth/image_rect + depth/camera_info (32FC1 metres or
// 16UC1 mm), confidence/image + confidence/camera_info, normals/image,
// points (world frame), depth_view (always).
class DepthOutputs {
 public:
  DepthOutputs(const ros::NodeHandle& private_nh,
               const std::string& world_frame,
               const std::string& depth_encoding, int worker_index);
  // Publishes one reconstructed keyframe (and logs it).
  void Publish(const StreamResult& r);

 private:
  ros::NodeHandle pnh_;
  std::string world_frame_, depth_encoding_;
  int worker_index_;
  std::unique_ptr<image_transport::ImageTransport> it_;
  // REP 118 camera pairs (image_transport CameraPublisher).
  image_transport::CameraPublisher depth_pub_, confidence_pub_;
  image_transport::Publisher normals_pub_;
  ros::Publisher points_pub_, view_pub_;
};

// SparsePoints -> stamped points for StreamReconstructor::SetSparsePoints:
// points with a non-finite position are skipped; pixels go from the ROS
// convention to the core's (+0.5), or NaN (= project) when not given.
std::vector<StreamReconstructor::StampedPoint> StampedPointsFromMsg(
    const wild_mvs::SparsePoints& msg);

// The depth node's diagnostics: the stream's statistics, the input queue
// and the drops by reason.
struct DepthInputStats {
  uint64_t received = 0;          // frames received
  size_t queued = 0;              // input queue length
  int queue_size = 0;             // its bound
  uint64_t recent_evictions = 0;  // within the drop counter's window
  // The node's role (params.h); the selector's keyframes published and
  // served on ~get_keyframe, a worker's keyframes received, fetched and
  // lost (KeyframeReceiver::Stats).
  DepthRole role = DepthRole::kStandalone;
  uint64_t keyframes_published = 0, keyframes_served = 0;
  uint64_t keyframes_received = 0, keyframes_fetched = 0;
  uint64_t keyframes_lost = 0, keyframes_repeated = 0;
};
void FillDepthDiagnostics(const StreamStats& s, const DepthInputStats& in,
                          const DropCounter& drops,
                          diagnostic_updater::DiagnosticStatusWrapper& stat);

}  // namespace ros1
}  // namespace wild_mvs
