// Copyright wild_mvs authors. The depth node: calibrated, posed images in,
// per-keyframe depth / confidence / normals / points and DepthView out.
//
// Topics (relative, meant for remapping):
//   in:  image (sensor_msgs/Image, or image/compressed with
//        ~image_transport:=compressed), camera_info, pose
//        (geometry_msgs/PoseStamped, ~pose_source:=topic), sparse_points
//        (wild_mvs/SparsePoints, ~sparse_source:=topic)
//   out (private, ~name): depth, confidence, normals (sensor_msgs/Image),
//        depth_camera_info, points (sensor_msgs/PointCloud2, world frame)
//        -- only built when subscribed --, depth_view (wild_mvs/DepthView,
//        always); diagnostics on /diagnostics.
// Pose by default from tf2: ~world_frame <- the image's frame_id at the image
// stamp, waiting up to ~tf_timeout. Parameters: config/depth_node.yaml.
//
// Callbacks only queue messages (bounded; the oldest is dropped and counted
// when full). A front-end thread converts, looks up the pose and feeds the
// StreamReconstructor, whose worker thread reconstructs keyframes. Bad input
// is dropped with a throttled ROS_ERROR naming the topic and the problem and
// counted by reason in the diagnostics.
#pragma once

#include <ros/node_handle.h>

#include <memory>

namespace wild_mvs {
namespace ros1 {

class DepthNode {
 public:
  // Throws wild_mvs::Error on bad parameters.
  DepthNode(const ros::NodeHandle& nh, const ros::NodeHandle& private_nh);
  ~DepthNode();

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace ros1
}  // namespace wild_mvs
