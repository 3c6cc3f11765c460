// Copyright wild_mvs authors. ParamSource over a ros::NodeHandle (the
// node's private namespace).
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

}  // namespace ros1
}  // namespace wild_mvs
