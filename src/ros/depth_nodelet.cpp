// Copyright wild_mvs authors.
#include "wild_mvs/ros/depth_nodelet.h"

#include <diagnostic_updater/diagnostic_updater.h>
#include <nodelet/nodelet.h>
#include <ros/ros.h>
#include <std_srvs/Trigger.h>

#include <cstdio>
#include <limits>
#include <pluginlib/class_list_macros.hpp>

#include "wild_mvs/core/error.h"
#include "wild_mvs/ros/bus_stats.h"
#include "wild_mvs/ros/depth_front_end.h"
#include "wild_mvs/ros/depth_inputs.h"
#include "wild_mvs/ros/depth_messages.h"
#include "wild_mvs/ros/depth_worker_input.h"
#include "wild_mvs/ros/diagnostics.h"
#include "wild_mvs/ros/keyframe_link.h"
#include "wild_mvs/ros/live_params.h"
#include "wild_mvs/ros/params_ros.h"
#include "wild_mvs/stream/drop_counter.h"
#include "wild_mvs/stream/stream_reconstructor.h"
#include "wild_mvs/stream/stream_reports.h"
#include "wild_mvs/stream/work_queue.h"

namespace wild_mvs {
namespace ros1 {

struct DepthNode::Impl {
  ros::NodeHandle nh, pnh;
  DepthNodeOptions options;
  DropCounter drops;
  std::unique_ptr<DepthInputs> inputs;
  std::unique_ptr<DepthOutputs> outputs;  // not a selector's
  std::unique_ptr<StreamReconstructor> stream;
  // Callbacks only queue frames (bounded, the oldest dropped and counted);
  // the queue's thread is the front end: it converts them and feeds the
  // stream.
  std::unique_ptr<WorkQueue<DepthFrame>> queue;
  // Periodic work about machine time (scheduling, diagnostics): steady
  // timers, so that it goes on when /clock pauses or stops (sim time).
  ros::SteadyTimer tick_timer, diag_timer;
  // Rates of input frames (every image received) and of depth maps (tasks
  // of the updater, which is destroyed first).
  std::unique_ptr<RateStatus> frame_rate, map_rate;
  std::unique_ptr<diagnostic_updater::Updater> updater;
  // Live tuning (dynamic_reconfigure protocol) and ~reset.
  std::unique_ptr<DepthLiveParams> live_params;
  ros::ServiceServer reset_srv;
  RoscppDropWatch roscpp_drops;  // roscpp's own queue drops, into `drops`
  // The roles: a selector's announcer, a worker's keyframe input.
  std::unique_ptr<KeyframeAnnouncer> announcer;
  std::unique_ptr<DepthWorkerInput> worker;
  ros::SteadyTimer index_timer;
  std::unique_ptr<DepthFrontEnd> front_end;  // the queue's thread

  // Counts and (throttled) reports one dropped input.
  void Drop(const std::string& topic, const std::string& problem,
            const std::string& detail = "") {
    LogDrop(&drops, pnh.getNamespace(), topic + ": " + problem, detail,
            kErrorThrottle);
  }

  // The topic frames come from: `image` (or its compressed topic), a
  // worker's `keyframes`.
  std::string InputTopic() const {
    if (worker) return worker->keyframes_topic();
    return inputs->Topic("image") +
           (options.image_transport == "raw" ? "" : "/compressed");
  }

  void Enqueue(DepthFrame f) {
    if (frame_rate && !f.index) frame_rate->tick();
    if (!queue->Push(std::move(f)))
      Drop(InputTopic(),
           "input queue full (frames arrive faster than they are processed)");
  }

  void FrontEnd(DepthFrame f) {
    try {
      if (worker)
        worker->Process(f);
      else
        front_end->ProcessImage(std::move(f));
    } catch (const std::exception& e) {
      Drop(InputTopic(), "unexpected error", e.what());
    }
  }

  bool OnReset(std_srvs::Trigger::Request&, std_srvs::Trigger::Response& res) {
    stream->Reset();
    res.success = true;
    res.message = "keyframes and tracks cleared; a new session starts";
    ROS_INFO("%s: ~reset: %s", pnh.getNamespace().c_str(), res.message.c_str());
    return true;
  }

  void Diagnose(diagnostic_updater::DiagnosticStatusWrapper& stat) {
    std::map<std::string, std::string> queues = inputs->QueueParams();
    if (worker)
      queues[worker->subscribed_topic()] =
          "the worker falls behind the keyframes";
    roscpp_drops.Update(queues, &drops);
    const StreamStats s = stream->Stats();
    DepthInputStats in;
    in.role = options.role;
    if (announcer) {
      in.keyframes_published = announcer->published();
      in.keyframes_served = announcer->served();
    }
    in.received = queue->received();
    if (worker) worker->AddStats(&in);  // keyframes, not queued messages
    in.queued = queue->size();
    in.queue_size = static_cast<int>(queue->capacity());
    front_end->ReportEvictions(s.evicted_waiting);
    in.recent_evictions = front_end->recent_evictions();
    FillDepthDiagnostics(s, in, drops, stat);
  }
};

DepthNode::DepthNode(const ros::NodeHandle& nh, const ros::NodeHandle& pnh,
                     DepthRole role)
    : impl_(std::make_unique<Impl>()) {
  Impl& m = *impl_;
  m.nh = nh;
  m.pnh = pnh;
  m.options = LoadDepthNodeOptions(pnh, role);
  auto drop = [&m](const std::string& topic, const std::string& problem,
                   const std::string& detail) {
    m.Drop(topic, problem, detail);
  };
  m.inputs = std::make_unique<DepthInputs>(m.nh, m.pnh, m.options, drop);
  // Frame ids as tf2 wants them (leading '/' stripped, warned once).
  m.options.world_frame = m.inputs->NoSlash(m.options.world_frame);
  if (!m.options.camera_frame.empty())
    m.options.camera_frame = m.inputs->NoSlash(m.options.camera_frame);
  m.drops.set_throttle(kErrorThrottle);
  m.drops.set_window(kDropWindow);
  const DepthNodeOptions& o = m.options;

  // Created before any callback or worker can tick them.
  const double inf = std::numeric_limits<double>::infinity();
  m.frame_rate = std::make_unique<RateStatus>(
      "rate: input frames", 0.0, inf, 10,
      diagnostic_msgs::DiagnosticStatus::WARN,
      "no input frame in the last 10 diagnostics periods");
  m.map_rate = std::make_unique<RateStatus>(
      "rate: depth maps", 0.0, inf, 10, diagnostic_msgs::DiagnosticStatus::OK,
      "no depth map in the last 10 diagnostics periods (no new keyframe)");
  if (Reconstructs(role))  // a selector publishes no depth
    m.outputs = std::make_unique<DepthOutputs>(
        m.pnh, o.world_frame, o.depth_encoding, o.stream.worker_index);
  m.stream = std::make_unique<StreamReconstructor>(
      o.stream,
      [&m](const StreamResult& r) {
        if (m.outputs) m.outputs->Publish(r);
        if (m.map_rate) m.map_rate->tick();
      },
      [&m](const std::string& e) {
        m.Drop("reconstruction", "keyframe failed", e);
      });
  // A worker's queue holds keyframes (a few per second at most).
  m.queue = std::make_unique<WorkQueue<DepthFrame>>(
      role == DepthRole::kWorker ? kKeyframeQueueSize : o.input_queue_size,
      [&m](DepthFrame f) { m.FrontEnd(std::move(f)); });
  if (role == DepthRole::kSelector) {
    m.announcer = std::make_unique<KeyframeAnnouncer>(m.pnh, o.world_frame,
                                                      kKeyframeHistory);
    m.index_timer = m.nh.createSteadyTimer(
        ros::WallDuration(1.0),
        [&m](const ros::SteadyTimerEvent&) { m.announcer->PublishIndex(); });
  }
  m.front_end = std::make_unique<DepthFrontEnd>(pnh.getNamespace(), m.options,
                                                m.inputs.get(), m.stream.get(),
                                                m.announcer.get(), drop);
  auto enqueue = [&m](DepthFrame f) { m.Enqueue(std::move(f)); };
  if (role == DepthRole::kWorker) {
    m.worker = std::make_unique<DepthWorkerInput>(
        m.nh, m.options, m.inputs.get(), drop,
        [&m](const WorkerKeyframe& k) { m.front_end->TakeKeyframe(k); });
    m.worker->Subscribe(enqueue);
  } else {
    m.inputs->Subscribe(
        enqueue, [&m](std::vector<StreamReconstructor::StampedPoint> points) {
          m.stream->SetSparsePoints(points);
        });
  }
  m.updater = std::make_unique<diagnostic_updater::Updater>(
      m.nh, m.pnh, m.pnh.getNamespace());
  m.updater->setHardwareID("wild_mvs_depth");
  m.updater->add("depth_node", &m, &Impl::Diagnose);
  m.updater->add(*m.frame_rate);
  m.updater->add(*m.map_rate);
  m.diag_timer = m.nh.createSteadyTimer(
      ros::WallDuration(o.diagnostics_period),
      [&m](const ros::SteadyTimerEvent&) { m.updater->force_update(); });
  m.tick_timer = m.nh.createSteadyTimer(
      ros::WallDuration(0.2),
      [&m](const ros::SteadyTimerEvent&) { m.stream->Tick(); });
  m.live_params = std::make_unique<DepthLiveParams>(
      m.pnh, m.options,
      [&m](const StreamOptions& live) { m.stream->SetOptions(live); });
  m.reset_srv = m.pnh.advertiseService("reset", &Impl::OnReset, &m);
  m.queue->Start();  // the front-end thread
  std::string what = role == DepthRole::kSelector
                         ? "keyframe selector (~keyframes)"
                         : Msg("worker ", o.stream.worker_index, " of ",
                               o.stream.worker_count);
  what = m.worker ? m.worker->Describe() : what + ", " + m.inputs->Describe();
  ROS_INFO("%s: %s", pnh.getNamespace().c_str(), what.c_str());
}

DepthNode::~DepthNode() {
  Impl& m = *impl_;
  m.tick_timer.stop();
  m.diag_timer.stop();
  m.index_timer.stop();
  if (m.worker) m.worker->Stop();
  m.inputs->Stop();  // ends the waits, unsubscribes the images
  m.queue->Stop();   // joins the front end; frames still queued are dropped
  // A running depth map is cancelled (it ends within a few pixels per
  // tile: roslaunch escalates to SIGKILL 15 s after SIGINT).
  m.stream->Shutdown();
  const StreamStats s = m.stream->Stats();
  std::fprintf(stderr, "depth node: %s\n",
               StreamSummary(m.queue->received(), m.drops.Total(), s).c_str());
  m.stream.reset();
}

// The nodelets: the node of one role inside a nodelet manager.
template <DepthRole kRole>
class DepthRoleNodelet : public nodelet::Nodelet {
 private:
  void onInit() override {
    try {
      // Multi-threaded callback queues (image, camera_info and pose
      // callbacks, timers and services never wait for one another).
      node_ = std::make_unique<DepthNode>(getMTNodeHandle(),
                                          getMTPrivateNodeHandle(), kRole);
    } catch (const std::exception& e) {
      NODELET_FATAL("%s", e.what());
      throw;
    }
  }
  std::unique_ptr<DepthNode> node_;
};

class DepthNodelet : public DepthRoleNodelet<DepthRole::kStandalone> {};
class KeyframeSelectorNodelet : public DepthRoleNodelet<DepthRole::kSelector> {
};
class DepthWorkerNodelet : public DepthRoleNodelet<DepthRole::kWorker> {};

}  // namespace ros1
}  // namespace wild_mvs

PLUGINLIB_EXPORT_CLASS(wild_mvs::ros1::DepthNodelet, nodelet::Nodelet)
PLUGINLIB_EXPORT_CLASS(wild_mvs::ros1::KeyframeSelectorNodelet,
                       nodelet::Nodelet)
PLUGINLIB_EXPORT_CLASS(wild_mvs::ros1::DepthWorkerNodelet, nodelet::Nodelet)
