// Copyright wild_mvs authors. The fusion node's outputs around its
// FusionSession: the fused cloud on ~cloud (sensor_msgs/PointCloud2,
// latched, world frame, at most max_published_points) at most every
// publish_period, with the views that waited reorder_timeout fused first;
// the Poisson mesh on ~mesh (visualization_msgs/Marker) every mesh_period
// when it is > 0; saves (binary PLY, atomic) and resets. Periodic
// publishing, saves and resets run on one worker thread, meshing on
// another, never on a callback thread: callbacks post and wait.
#pragma once

#include <ros/node_handle.h>
#include <ros/publisher.h>

#include <cstddef>
#include <cstdint>
#include <string>

#include "wild_mvs/ros/params.h"
#include "wild_mvs/stream/fusion_session.h"
#include "wild_mvs/stream/periodic_worker.h"

namespace wild_mvs {
namespace ros1 {

class FusionOutputs {
 public:
  // Advertises ~cloud (and ~mesh when mesh_period > 0). `options` and
  // `session` are the node's and outlive this.
  FusionOutputs(const ros::NodeHandle& private_nh,
                const FusionNodeOptions& options, FusionSession* session);
  void Start();  // the worker threads
  // A running mesh or publication finishes; nothing new starts.
  void Stop();
  // Fuses every waiting view and saves the cloud to `path` on the calling
  // thread; the number of points. Throws on failure.
  size_t Save(const std::string& path);
  // The same on the output worker (the caller waits).
  size_t SaveOnWorker(const std::string& path);
  // Clears the session and publishes the empty cloud, on the output worker.
  void ResetOnWorker();

 private:
  void PublishCloud(bool force);
  void PublishMesh();

  ros::NodeHandle pnh_;
  const FusionNodeOptions& options_;
  FusionSession* session_;
  ros::Publisher cloud_pub_, mesh_pub_;
  PeriodicWorker output_worker_, mesh_worker_;
  // Cloud versions sent (only touched inside FusionSession::CloudIfChanged).
  uint64_t published_version_ = 0, meshed_version_ = 0;
};

}  // namespace ros1
}  // namespace wild_mvs
