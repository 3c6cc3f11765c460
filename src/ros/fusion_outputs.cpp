// Copyright wild_mvs authors.
#include "wild_mvs/ros/fusion_outputs.h"

#include <ros/console.h>
#include <sensor_msgs/PointCloud2.h>
#include <visualization_msgs/Marker.h>

#include "wild_mvs/core/meshing.h"
#include "wild_mvs/ros/conversions.h"
#include "wild_mvs/stream/cloud_file.h"

namespace wild_mvs {
namespace ros1 {

FusionOutputs::FusionOutputs(const ros::NodeHandle& private_nh,
                             const FusionNodeOptions& options,
                             FusionSession* session)
    : pnh_(private_nh), options_(options), session_(session) {
  cloud_pub_ = pnh_.advertise<sensor_msgs::PointCloud2>("cloud", 1, true);
  if (options_.mesh_period > 0)
    mesh_pub_ = pnh_.advertise<visualization_msgs::Marker>("mesh", 1, true);
  output_worker_.Every(options_.publish_period,
                       [this] { PublishCloud(false); });
  if (options_.mesh_period > 0)
    mesh_worker_.Every(options_.mesh_period, [this] { PublishMesh(); });
}

void FusionOutputs::Start() {
  output_worker_.Start();
  mesh_worker_.Start();
}

void FusionOutputs::Stop() {
  mesh_worker_.Stop();
  output_worker_.Stop();
}

void FusionOutputs::PublishCloud(bool force) {
  session_->FuseReady();  // views that waited reorder_timeout
  PointCloud cloud;
  uint64_t stamp = 0;
  if (!session_->CloudIfChanged(&published_version_, force, &cloud, &stamp))
    return;
  sensor_msgs::PointCloud2 msg =
      CloudToMsg(cloud, static_cast<size_t>(options_.max_published_points));
  msg.header.stamp.fromNSec(stamp);
  msg.header.frame_id = options_.world_frame;
  cloud_pub_.publish(msg);
}

void FusionOutputs::PublishMesh() {
  PointCloud cloud;
  uint64_t stamp = 0;
  if (!session_->CloudIfChanged(&meshed_version_, false, &cloud, &stamp))
    return;
  if (cloud.size() < 100 || !cloud.has_normal()) return;
  try {
    // The offline tool's meshing step, with the same options.
    Mesh mesh = MeshPointCloud(cloud, options_.meshing);
    visualization_msgs::Marker m = MeshToMarker(mesh);
    m.header.stamp.fromNSec(stamp);
    m.header.frame_id = options_.world_frame;
    m.ns = "wild_mvs";
    mesh_pub_.publish(m);
  } catch (const std::exception& e) {
    ROS_WARN_THROTTLE(30, "%s: meshing failed: %s", pnh_.getNamespace().c_str(),
                      e.what());
  }
}

size_t FusionOutputs::Save(const std::string& path) {
  // Views still waiting for an earlier keyframe are fused first.
  const PointCloud cloud = session_->FlushAndCloud();
  SaveCloudPly(path, cloud);
  return cloud.size();
}

size_t FusionOutputs::SaveOnWorker(const std::string& path) {
  // The disk I/O never runs on a callback thread.
  size_t n = 0;
  output_worker_.Post([&] { n = Save(path); }).get();
  return n;
}

void FusionOutputs::ResetOnWorker() {
  output_worker_
      .Post([this] {
        session_->Reset();
        PublishCloud(true);
      })
      .get();
}

}  // namespace ros1
}  // namespace wild_mvs
