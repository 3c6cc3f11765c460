// Copyright wild_mvs authors. Live tuning through dynamic_reconfigure's
// protocol (~set_parameters, ~parameter_descriptions, ~parameter_updates),
// so that rqt_reconfigure and `rosrun dynamic_reconfigure dynparam` work on
// the nodes. The parameters offered are options of the OptionRegistry
// (name = the ROS parameter name of the key, help and range from the
// registry): nothing is declared twice, no .cfg file. A change is applied
// only when the options struct's Check() accepts it; otherwise the node
// answers with the values it keeps and logs why.
#pragma once

#include <dynamic_reconfigure/Config.h>
#include <dynamic_reconfigure/Reconfigure.h>
#include <ros/node_handle.h>

#include <functional>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "wild_mvs/core/option_registry.h"
#include "wild_mvs/ros/params.h"

namespace wild_mvs {
namespace ros1 {

class LiveParams {
 public:
  // `registry` is over the node's live copy of its options; `keys` are the
  // registry keys offered. `apply` is called (under this object's lock)
  // with the registry's fields set to a requested change: it checks them
  // (throws Error to refuse) and hands them to the node. Throws Error for
  // an unknown key.
  LiveParams(const ros::NodeHandle& private_nh, OptionRegistry* registry,
             const std::vector<std::string>& keys, std::function<void()> apply);

  // The current values (as sent on ~parameter_updates).
  dynamic_reconfigure::Config Current() const;
  // The message of the last refused change ("" = none since the start).
  std::string last_error() const;

 private:
  bool OnSet(dynamic_reconfigure::Reconfigure::Request& req,
             dynamic_reconfigure::Reconfigure::Response& res);
  dynamic_reconfigure::Config CurrentLocked() const;
  void PublishLocked();

  ros::NodeHandle pnh_;
  OptionRegistry* registry_;
  std::vector<OptionRegistry::Option*> options_;
  std::function<void()> apply_;
  mutable std::mutex mutex_;
  std::string last_error_;
  ros::Publisher descriptions_pub_, updates_pub_;
  ros::ServiceServer set_srv_;
};

// The depth node's live parameters: the keyframe thresholds and the main
// MVS thresholds (keyframe_min_baseline, keyframe_min_angle_deg,
// mvs/max_image_size, mvs/global/num_neighbors, mvs/local/min_ncc,
// mvs/mpgc/drop_ncc, mvs/growing/revisit_margin; those its role registers)
// over a copy of the node's options; a change DepthNodeOptions::Check()
// accepts goes to `apply`.
class DepthLiveParams {
 public:
  DepthLiveParams(const ros::NodeHandle& private_nh,
                  const DepthNodeOptions& options,
                  std::function<void(const StreamOptions&)> apply);

 private:
  DepthNodeOptions live_;
  OptionRegistry registry_;
  std::unique_ptr<LiveParams> params_;
};

}  // namespace ros1
}  // namespace wild_mvs
