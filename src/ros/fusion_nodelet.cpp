// Copyright wild_mvs authors.
#include "wild_mvs/ros/fusion_nodelet.h"

#include <diagnostic_updater/diagnostic_updater.h>
#include <nodelet/nodelet.h>
#include <ros/ros.h>
#include <std_srvs/Trigger.h>
#include <wild_mvs/DepthView.h>
#include <wild_mvs/KeyframeIndex.h>
#include <wild_mvs/SaveCloud.h>

#include <cstdio>
#include <limits>
#include <pluginlib/class_list_macros.hpp>

#include "wild_mvs/core/error.h"
#include "wild_mvs/ros/bus_stats.h"
#include "wild_mvs/ros/conversions.h"
#include "wild_mvs/ros/diagnostics.h"
#include "wild_mvs/ros/fusion_messages.h"
#include "wild_mvs/ros/fusion_outputs.h"
#include "wild_mvs/ros/params_ros.h"
#include "wild_mvs/stream/fusion_session.h"
#include "wild_mvs/stream/keyframe_ledger.h"
#include "wild_mvs/stream/work_queue.h"

namespace wild_mvs {
namespace ros1 {

struct FusionNode::Impl {
  ros::NodeHandle nh, pnh;
  FusionNodeOptions options;
  DropCounter drops;
  RoscppDropWatch roscpp_drops;  // roscpp's own queue drops, into `drops`
  ros::Subscriber sub;
  ros::ServiceServer save_srv, reset_srv;
  // Periodic work about machine time: steady timers, so that diagnostics
  // go on when /clock pauses or stops (sim time, bag ended).
  ros::SteadyTimer diag_timer;
  // Rate of depth views received (a task of the updater, destroyed first).
  std::unique_ptr<RateStatus> view_rate;
  std::unique_ptr<diagnostic_updater::Updater> updater;
  // Reorder buffer, session policy, spill store and the fusion itself.
  std::unique_ptr<FusionSession> session;
  // ~cloud, ~mesh, saves and resets, on their own threads (destroyed
  // before the session).
  std::unique_ptr<FusionOutputs> outputs;
  // Input queue (callback -> its fusion thread).
  std::unique_ptr<WorkQueue<wild_mvs::DepthViewConstPtr>> queue;
  // Keyframes a selector announced (`keyframe_index`) and the depth views
  // received for them: names missing and twice-done keyframes.
  std::unique_ptr<KeyframeLedger> ledger;
  ros::Subscriber index_sub;

  std::string Topic() const { return nh.resolveName("depth_view"); }

  void Drop(const std::string& problem, const std::string& detail = "") {
    LogDrop(&drops, pnh.getNamespace(), Topic() + ": " + problem, detail,
            options.error_throttle);
  }

  void OnView(const wild_mvs::DepthViewConstPtr& msg) {
    view_rate->tick();
    if (!queue->Push(msg))
      Drop("input queue full (views arrive faster than they are fused)");
  }

  // Decodes and validates a view; hands it to the session.
  void Accept(const wild_mvs::DepthView& msg) {
    if (StripLeadingSlash(msg.camera_pose.header.frame_id) !=
        options.world_frame) {
      Drop("camera_pose frame is not the world frame",
           "'" + msg.camera_pose.header.frame_id + "' vs '" +
               options.world_frame + "'");
      return;
    }
    FusionView view;
    try {
      view = FusionViewFromMsg(msg);
    } catch (const Error& e) {
      Drop("invalid depth_view", e.what());
      return;
    }
    if (!ledger->Done(msg.session.toNSec(), msg.header.stamp.toNSec(),
                      static_cast<int>(msg.revision)))
      ROS_WARN_THROTTLE(options.error_throttle,
                        "%s: keyframe %s (session %s) reconstructed twice, "
                        "again by worker %u: two depth workers own it (the "
                        "first result is kept; throttled)",
                        pnh.getNamespace().c_str(),
                        StampText(msg.header.stamp.toNSec()).c_str(),
                        StampText(msg.session.toNSec()).c_str(),
                        msg.worker_index);
    session->Add(std::move(view));
  }

  void Work(const wild_mvs::DepthViewConstPtr& msg) {
    try {
      Accept(*msg);
    } catch (const std::exception& e) {
      Drop("unexpected error", e.what());
    }
  }

  bool OnSave(wild_mvs::SaveCloud::Request& req,
              wild_mvs::SaveCloud::Response& res) {
    const std::string& path =
        req.path.empty() ? options.session.output_path : req.path;
    if (path.empty()) {
      res.success = false;
      res.message = "no path given and ~output_path is not set";
      return true;
    }
    try {
      res.num_points = outputs->SaveOnWorker(path);
      res.success = true;
      res.message = path;
      ROS_INFO("%s: saved %lu points to %s", pnh.getNamespace().c_str(),
               static_cast<unsigned long>(res.num_points), path.c_str());
    } catch (const std::exception& e) {
      res.success = false;
      res.message = e.what();
      ROS_ERROR("%s: save failed: %s", pnh.getNamespace().c_str(), e.what());
    }
    return true;
  }

  bool OnReset(std_srvs::Trigger::Request&, std_srvs::Trigger::Response& res) {
    outputs->ResetOnWorker();
    res.success = true;
    res.message = "fused cloud cleared";
    return true;
  }

  void Diagnose(diagnostic_updater::DiagnosticStatusWrapper& stat) {
    roscpp_drops.Update({{sub.getTopic(), "raise ~input_queue_size"}}, &drops);
    const uint64_t received = queue->received();
    const size_t queued = queue->size();
    FillFusionDiagnostics(session->Stats(), received, queued, drops, stat);
    AddKeyframeLedgerValues(ledger->Summarize(8), stat);
  }

  void OnIndex(const wild_mvs::KeyframeIndexConstPtr& msg) {
    for (const ros::Time& t : msg->stamps)
      ledger->Announce(msg->session.toNSec(), t.toNSec());
  }

  void Log(bool error, const std::string& message) {
    if (error)
      ROS_ERROR("%s: %s", pnh.getNamespace().c_str(), message.c_str());
    else
      ROS_INFO("%s: %s", pnh.getNamespace().c_str(), message.c_str());
  }
};

FusionNode::FusionNode(const ros::NodeHandle& nh, const ros::NodeHandle& pnh)
    : impl_(std::make_unique<Impl>()) {
  Impl& m = *impl_;
  m.nh = nh;
  m.pnh = pnh;
  m.options = LoadFusionNodeOptions(pnh);
  m.drops.set_throttle(m.options.error_throttle);
  m.drops.set_window(m.options.drop_window);
  const FusionNodeOptions& o = m.options;
  m.session = std::make_unique<FusionSession>(
      o.session,
      [&m](const std::string& problem, const std::string& detail) {
        m.Drop(problem, detail);
      },
      [&m](bool error, const std::string& message) { m.Log(error, message); });
  m.queue = std::make_unique<WorkQueue<wild_mvs::DepthViewConstPtr>>(
      o.input_queue_size,
      [&m](wild_mvs::DepthViewConstPtr msg) { m.Work(msg); });
  m.outputs = std::make_unique<FusionOutputs>(m.pnh, o, m.session.get());
  m.save_srv = m.pnh.advertiseService("save", &Impl::OnSave, &m);
  m.reset_srv = m.pnh.advertiseService("reset", &Impl::OnReset, &m);
  m.view_rate = std::make_unique<RateStatus>(
      "rate: depth views", 0.0, std::numeric_limits<double>::infinity(), 10,
      diagnostic_msgs::DiagnosticStatus::OK,
      "no depth view in the last 10 diagnostics periods");
  m.ledger = std::make_unique<KeyframeLedger>(o.keyframes);
  m.sub = m.nh.subscribe("depth_view", o.input_queue_size, &Impl::OnView, &m);
  m.index_sub = m.nh.subscribe("keyframe_index", 10, &Impl::OnIndex, &m);
  m.updater = std::make_unique<diagnostic_updater::Updater>(
      m.nh, m.pnh, m.pnh.getNamespace());
  m.updater->setHardwareID("wild_mvs_fusion");
  m.updater->add("fusion_node", &m, &Impl::Diagnose);
  m.updater->add(*m.view_rate);
  m.diag_timer = m.nh.createSteadyTimer(
      ros::WallDuration(o.diagnostics_period),
      [&m](const ros::SteadyTimerEvent&) { m.updater->force_update(); });
  m.queue->Start();  // the fusion thread
  m.outputs->Start();
}

size_t FusionNode::Save(const std::string& path) {
  return impl_->outputs->Save(path);
}

FusionNode::~FusionNode() {
  Impl& m = *impl_;
  m.sub.shutdown();
  m.index_sub.shutdown();
  m.diag_timer.stop();
  m.outputs->Stop();
  // Views already queued are fused before the final save.
  for (const auto& msg : m.queue->Stop()) {
    try {
      m.Accept(*msg);
    } catch (const std::exception&) {
    }
  }
  const std::string& path = m.options.session.output_path;
  if (!path.empty()) {
    try {
      const size_t n = m.outputs->Save(path);
      ROS_INFO("%s: saved %zu points to %s on shutdown",
               m.pnh.getNamespace().c_str(), n, path.c_str());
      std::fprintf(stderr, "fusion node: saved %zu points to %s\n", n,
                   path.c_str());
    } catch (const std::exception& e) {
      ROS_ERROR("%s: saving on shutdown failed: %s",
                m.pnh.getNamespace().c_str(), e.what());
      std::fprintf(stderr, "fusion node: saving on shutdown failed: %s\n",
                   e.what());
    }
  }
  // The session removes its temporary spill folder when it goes.
}

class FusionNodelet : public nodelet::Nodelet {
 private:
  void onInit() override {
    try {
      // Multi-threaded callback queues: a service or timer never holds up
      // the depth_view callback.
      node_ = std::make_unique<FusionNode>(getMTNodeHandle(),
                                           getMTPrivateNodeHandle());
    } catch (const std::exception& e) {
      NODELET_FATAL("%s", e.what());
      throw;
    }
  }
  std::unique_ptr<FusionNode> node_;
};

}  // namespace ros1
}  // namespace wild_mvs

PLUGINLIB_EXPORT_CLASS(wild_mvs::ros1::FusionNodelet, nodelet::Nodelet)
