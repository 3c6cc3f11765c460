// Copyright wild_mvs authors. ParamSource over a ros::NodeHandle (the
// node's private namespace), and the nodes' options read from it.
#pragma once

#include <ros/node_handle.h>

#include <string>
#include <vector>

#include "wild_mvs/ros/params.h"

namespace wild_mvs {
namespace ros1 {

class RosParamSource : public ParamSource {
 public:
  explicit RosParamSource(const ros::NodeHandle& private_nh)
      : nh_(private_nh) {}
  bool Lookup(const std::string& name, Value* value) const override;
  std::vector<std::string> Names() const override;
  std::string Where() const override { return nh_.getNamespace(); }

 private:
  ros::NodeHandle nh_;
};

// A node's options from its private parameters (Read*NodeOptions: throws
// Error on a bad value); each unknown parameter is warned about
// (ROS_WARN), naming the config file that lists the known ones. The fusion
// node's world_frame loses a leading '/' (tf2 frame ids have none; warned).
DepthNodeOptions LoadDepthNodeOptions(const ros::NodeHandle& private_nh,
                                      DepthRole role);
FusionNodeOptions LoadFusionNodeOptions(const ros::NodeHandle& private_nh);

}  // namespace ros1
}  // namespace wild_mvs
