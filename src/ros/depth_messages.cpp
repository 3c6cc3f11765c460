// Copyright wild_mvs authors.
#include "wild_mvs/ros/depth_messages.h"

#include <ros/console.h>
#include <sensor_msgs/Image.h>
#include <sensor_msgs/PointCloud2.h>
#include <wild_mvs/DepthView.h>

#include <cmath>

#include "wild_mvs/ros/conversions.h"

namespace wild_mvs {
namespace ros1 {

DepthOutputs::DepthOutputs(const ros::NodeHandle& private_nh,
                           const std::string& world_frame,
                           const std::string& depth_encoding, int worker_index)
    : pnh_(private_nh),
      world_frame_(world_frame),
      depth_encoding_(depth_encoding),
      worker_index_(worker_index) {
  it_ = std::make_unique<image_transport::ImageTransport>(pnh_);
  depth_pub_ = it_->advertiseCamera("depth/image_rect", 2);
  confidence_pub_ = it_->advertiseCamera("confidence/image", 2);
  normals_pub_ = it_->advertise("normals/image", 2);
  points_pub_ = pnh_.advertise<sensor_msgs::PointCloud2>("points", 2);
  view_pub_ = pnh_.advertise<wild_mvs::DepthView>("depth_view", 20);
}

void DepthOutputs::Publish(const StreamResult& r) {
  // Stamps pass through bit for bit (ns), never through a double.
  std_msgs::Header header;
  header.stamp.fromNSec(r.stamp_ns);
  header.frame_id = r.frame_id;
  auto view = boost::make_shared<wild_mvs::DepthView>();
  view->header = header;
  view->keyframe_id = r.keyframe_id;
  view->session.fromNSec(r.session_ns);
  view->neighbor_ids = r.neighbor_ids;
  for (uint64_t s : r.neighbor_stamps_ns) {
    ros::Time t;
    t.fromNSec(s);
    view->neighbor_stamps.push_back(t);
  }
  view->worker_index = worker_index_;
  view->revision = r.revision;
  view->final_revision = r.final_revision;
  FillDepthView(r.depth, world_frame_, view.get());
  if (!r.image.empty())
    view->image = ColorToMsg(r.image, r.depth.width(), r.depth.height());
  view->image.header = header;
  // Lazy outputs: only built / sent when someone listens. Every image
  // and camera_info has the source image's header (stamp and frame).
  view->depth.header = view->confidence.header = view->normals.header =
      view->camera_info.header = header;
  if (depth_pub_.getNumSubscribers() > 0) {
    if (depth_encoding_ == "16UC1") {
      sensor_msgs::Image mm = DepthToMsg16(r.depth.depth);
      mm.header = header;
      depth_pub_.publish(mm, view->camera_info);
    } else {
      depth_pub_.publish(view->depth, view->camera_info);
    }
  }
  if (confidence_pub_.getNumSubscribers() > 0)
    confidence_pub_.publish(view->confidence, view->camera_info);
  if (normals_pub_.getNumSubscribers() > 0) normals_pub_.publish(view->normals);
  if (points_pub_.getNumSubscribers() > 0) {
    sensor_msgs::PointCloud2 pc = CloudToMsg(DepthMapToCloud(r.depth, r.image));
    pc.header.stamp = header.stamp;
    pc.header.frame_id = world_frame_;
    points_pub_.publish(pc);
  }
  view_pub_.publish(view);
  ROS_INFO(
      "%s: keyframe %u (rev %u): %d depth samples, %zu neighbours, "
      "%.2f s",
      pnh_.getNamespace().c_str(), r.keyframe_id, r.revision,
      r.depth.CountValid(), r.neighbor_ids.size(), r.seconds);
}

std::vector<StreamReconstructor::StampedPoint> StampedPointsFromMsg(
    const wild_mvs::SparsePoints& msg) {
  std::vector<StreamReconstructor::StampedPoint> pts;
  pts.reserve(msg.points.size());
  for (const auto& p : msg.points) {
    StreamReconstructor::StampedPoint q;
    q.xyz = Eigen::Vector3d(p.position.x, p.position.y, p.position.z);
    if (!q.xyz.allFinite()) continue;
    const bool have_xy =
        p.x.size() == p.stamps.size() && p.y.size() == p.stamps.size();
    for (size_t i = 0; i < p.stamps.size(); ++i) {
      StreamReconstructor::StampedObservation o;
      o.stamp = p.stamps[i].toSec();
      // ROS pixel convention -> core (+0.5).
      o.xy = have_xy ? Eigen::Vector2d(p.x[i] + 0.5, p.y[i] + 0.5)
                     : Eigen::Vector2d(NAN, NAN);
      q.observations.push_back(o);
    }
    pts.push_back(std::move(q));
  }
  return pts;
}

void FillDepthDiagnostics(const StreamStats& s, const DepthInputStats& in,
                          const DropCounter& drops,
                          diagnostic_updater::DiagnosticStatusWrapper& stat) {
  // The level follows the recent window (WARN clears once drops stop); the
  // totals stay in the values.
  const uint64_t recent = drops.RecentTotal();
  if (recent > 0 || in.recent_evictions > 0) {
    stat.summaryf(diagnostic_msgs::DiagnosticStatus::WARN,
                  "%lu frames dropped and %lu keyframes evicted before "
                  "reconstruction in the last %.0f s (see dropped: entries)",
                  static_cast<unsigned long>(recent),
                  static_cast<unsigned long>(in.recent_evictions),
                  drops.window());
  } else {
    stat.summary(diagnostic_msgs::DiagnosticStatus::OK, "running");
  }
  // (A lost keyframe is also a drop: WARN while recent.)
  stat.add("role", RoleName(in.role));
  if (in.role == DepthRole::kSelector) {
    stat.add("keyframes published", in.keyframes_published);
    stat.add("keyframes served", in.keyframes_served);
  } else if (in.role == DepthRole::kWorker) {
    stat.add("keyframes received", in.keyframes_received);
    stat.add("keyframes fetched", in.keyframes_fetched);
    stat.add("keyframes lost", in.keyframes_lost);
    stat.add("keyframe messages repeated", in.keyframes_repeated);
  }
  stat.add("frames received", in.received);
  stat.add("input queue length", in.queued);
  stat.add("input queue size", in.queue_size);
  stat.add("keyframes held", s.keyframes);
  stat.add("keyframe store MB", s.store_mb);
  stat.add("keyframes created", s.keyframes_total);
  stat.add("reconstructions pending", s.pending);
  stat.add("keyframes waiting", s.waiting);
  stat.add("depth maps", s.reconstructed);
  stat.add("depth maps running", s.running);
  stat.add("depth maps cancelled", s.cancelled);
  stat.add("revisions 1", s.early_revised);
  stat.add("depth maps revised", s.revised);  // final revisions
  stat.add("revisions to come", s.unrevised);
  stat.add("reconstructions failed", s.failed);
  stat.add("keyframes evicted before reconstruction", s.evicted_waiting);
  stat.add("stream resets", s.resets);
  stat.addf("session", "%.6f", s.session);  // stamp that started it
  stat.add("sparse points", s.sparse_points);
  stat.add("tracker MB", s.tracker_mb);
  stat.add("last seconds per depth map", s.last_seconds);
  stat.add("mean seconds per depth map", s.mean_seconds);
  AddDropValues(drops, "frames", stat);
}

}  // namespace ros1
}  // namespace wild_mvs
