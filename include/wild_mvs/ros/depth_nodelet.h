// Copyright wild_mvs authors. The depth node: calibrated, posed images in,
// per-keyframe depth / confidence / normals / points and DepthView out.
// One class for the three roles (DepthRole, params.h), each a nodelet and
// an executable of its own: wild_mvs/DepthNodelet (depth_node) selects and
// reconstructs; wild_mvs/KeyframeSelectorNodelet (keyframe_selector_node)
// selects and publishes ~keyframes; wild_mvs/DepthWorkerNodelet
// (depth_worker_node) reconstructs its share of a selector's `keyframes`
// (below, "in" is the camera input of the first two).
//
// Topics (relative, meant for remapping):
//   in:  image (through image_transport: ~image_transport names the plugin;
//        "compressed" is decoded here when its plugin is not installed),
//        camera_info (beside the image, image_transport's CameraSubscriber
//        convention, unless `camera_info` itself is remapped; paired with
//        the image by exact stamp, or the latest with ~camera_info_latest),
//        pose (~pose_source: pose = topic (PoseStamped),
//        pose_with_covariance, transform (TransformStamped) or odometry
//        (nav_msgs/Odometry), of the camera or of a body frame with the
//        camera extrinsic; interpolated at the image stamp),
//        sparse_points (wild_mvs/SparsePoints, ~sparse_source:=topic)
//   out (private, ~name), each with the source image's header (stamp bit
//        for bit, frame = the camera optical frame):
//        depth/image_rect + depth/camera_info (image_transport
//        CameraPublisher; 32FC1 metres, NaN unknown, REP 118, or 16UC1 mm
//        with ~depth_encoding), confidence/image + confidence/camera_info
//        (32FC1 in [0, 1]), normals/image (32FC3, camera frame), points
//        (sensor_msgs/PointCloud2, world frame) -- only built when
//        subscribed --, depth_view (wild_mvs/DepthView, always);
//        diagnostics on /diagnostics.
// Pose by default from tf2: ~world_frame <- ~camera_frame (default: the
// image's frame_id) at the image stamp, waiting up to ~tf_timeout of wall
// time (never ROS time: /clock may stand still). Leading '/' of incoming
// frame ids is stripped (one warning per id). Periodic work runs on steady
// timers. Parameters: config/depth_node.yaml, keyframe_selector.yaml,
// depth_worker.yaml (each role registers only the keys it reads).
//
// Callbacks only queue messages (bounded; the oldest is dropped and counted
// when full). A front-end thread looks up the pose, lets the
// StreamReconstructor's keyframe test decide on it, converts (decodes,
// undistorts) only the keyframes' images and feeds them to the
// StreamReconstructor, whose worker thread reconstructs keyframes. Bad input
// is dropped with a throttled ROS_ERROR naming the topic and the problem and
// counted by reason in the diagnostics.
#pragma once

#include <ros/node_handle.h>

#include <memory>

#include "wild_mvs/ros/params.h"

namespace wild_mvs {
namespace ros1 {

class DepthNode {
 public:
  // Throws wild_mvs::Error on bad parameters.
  DepthNode(const ros::NodeHandle& nh, const ros::NodeHandle& private_nh,
            DepthRole role);
  ~DepthNode();

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace ros1
}  // namespace wild_mvs
