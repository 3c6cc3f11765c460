// Copyright wild_mvs authors. The fusion node: DepthView in, fused cloud out.
//
// Subscribes depth_view (wild_mvs/DepthView from one or several depth
// workers), fuses the views incrementally in keyframe order with the core's
// consistency-checked StreamingFusion, and publishes `~cloud`
// (sensor_msgs/PointCloud2, latched, world frame) at most every
// ~publish_period, optionally `~mesh` (visualization_msgs/Marker) every
// ~mesh_period. Services: ~save (wild_mvs/SaveCloud: binary PLY written
// atomically) and ~reset (std_srvs/Trigger). On shutdown (SIGINT, SIGTERM,
// nodelet unload) the cloud is saved to ~output_path when set.
// Parameters: config/fusion_node.yaml.
#pragma once

#include <ros/node_handle.h>

#include <memory>
#include <string>

namespace wild_mvs {
namespace ros1 {

class FusionNode {
 public:
  // Throws wild_mvs::Error on bad parameters.
  FusionNode(const ros::NodeHandle& nh, const ros::NodeHandle& private_nh);
  ~FusionNode();  // saves to ~output_path when set
  // Saves the cloud now (atomic PLY); returns the number of points. Throws
  // Error on failure.
  size_t Save(const std::string& path);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace ros1
}  // namespace wild_mvs
