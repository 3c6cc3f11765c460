// Copyright wild_mvs authors. Shared main() of the node executables.
#pragma once

#include <ros/ros.h>

#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <fstream>
#include <memory>
#include <string>

#include "wild_mvs/core/stats.h"

namespace wild_mvs {
namespace ros1 {

inline void RequestShutdownOnSignal(int) { ros::requestShutdown(); }

// Runs node type T (constructed from the public and private node handles,
// then `args`) until SIGINT or SIGTERM, then destroys it (so its destructor
// runs: the fusion node saves there). Returns the process exit code.
template <typename T, typename... Args>
int RunNode(int argc, char** argv, const char* name, Args... args) {
  ros::init(argc, argv, name, ros::init_options::NoSigintHandler);
  std::signal(SIGINT, RequestShutdownOnSignal);
  std::signal(SIGTERM, RequestShutdownOnSignal);
  ros::NodeHandle nh, pnh("~");
  std::unique_ptr<T> node;
  try {
    node = std::make_unique<T>(nh, pnh, args...);
  } catch (const std::exception& e) {
    ROS_FATAL("%s: %s", pnh.getNamespace().c_str(), e.what());
    return 1;
  }
  ros::AsyncSpinner spinner(2);  // services stay responsive during a save
  spinner.start();
  ros::waitForShutdown();
  spinner.stop();
  node.reset();
  std::fprintf(stderr, "%s: peak RSS %.0f MB\n", name, wild_mvs::PeakRssMb());
  return 0;
}

}  // namespace ros1
}  // namespace wild_mvs
