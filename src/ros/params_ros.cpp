// Copyright wild_mvs authors.
#include "wild_mvs/ros/params_ros.h"

#include <ros/console.h>
#include <xmlrpcpp/XmlRpcValue.h>

#include <algorithm>

#include "wild_mvs/core/error.h"
#include "wild_mvs/ros/conversions.h"

namespace wild_mvs {
namespace ros1 {

bool RosParamSource::Lookup(const std::string& name, Value* value) const {
  XmlRpc::XmlRpcValue x;
  if (!nh_.getParam(name, x)) return false;
  switch (x.getType()) {
    case XmlRpc::XmlRpcValue::TypeBoolean:
      *value = static_cast<bool>(x);
      return true;
    case XmlRpc::XmlRpcValue::TypeInt:
      *value = static_cast<int>(x);
      return true;
    case XmlRpc::XmlRpcValue::TypeDouble:
      *value = static_cast<double>(x);
      return true;
    case XmlRpc::XmlRpcValue::TypeString:
      *value = static_cast<std::string>(x);
      return true;
    default:
      throw Error(Msg(Where(), "/", name,
                      " has an unsupported type (a list or a map where a "
                      "single value is expected)"));
  }
}

std::vector<std::string> RosParamSource::Names() const {
  std::vector<std::string> all, out;
  if (!nh_.getParamNames(all)) return out;
  const std::string prefix = nh_.getNamespace() + "/";
  for (const std::string& n : all)
    if (n.compare(0, prefix.size(), prefix) == 0)
      out.push_back(n.substr(prefix.size()));
  return out;
}

DepthNodeOptions LoadDepthNodeOptions(const ros::NodeHandle& pnh,
                                      DepthRole role) {
  RosParamSource params(pnh);
  DepthNodeOptions o = ReadDepthNodeOptions(params, role);
  // A key of another depth role (one YAML for a selector and its workers)
  // is only noted; a key of none is a typo.
  const std::vector<std::string> typos =
      UnknownDepthNodeParams(params, DepthRole::kStandalone);
  for (const std::string& n : UnknownDepthNodeParams(params, role)) {
    if (std::count(typos.begin(), typos.end(), n))
      ROS_WARN("%s: unknown parameter '%s' (ignored; see config/%s)",
               pnh.getNamespace().c_str(), n.c_str(), ConfigFileName(role));
    else
      ROS_INFO("%s: parameter '%s' is not read by a %s (ignored)",
               pnh.getNamespace().c_str(), n.c_str(), RoleName(role));
  }
  return o;
}

FusionNodeOptions LoadFusionNodeOptions(const ros::NodeHandle& pnh) {
  RosParamSource params(pnh);
  FusionNodeOptions o = ReadFusionNodeOptions(params);
  for (const std::string& n : UnknownFusionNodeParams(params))
    ROS_WARN(
        "%s: unknown parameter '%s' (ignored; see config/fusion_node.yaml)",
        pnh.getNamespace().c_str(), n.c_str());
  const std::string w = StripLeadingSlash(o.world_frame);
  if (w != o.world_frame) {
    ROS_WARN("%s: world_frame '%s' starts with '/': using '%s'",
             pnh.getNamespace().c_str(), o.world_frame.c_str(), w.c_str());
    o.world_frame = w;
  }
  return o;
}

}  // namespace ros1
}  // namespace wild_mvs
