// Copyright wild_mvs authors.
#include "wild_mvs/ros/depth_nodelet.h"

#include <diagnostic_updater/diagnostic_updater.h>
#include <nodelet/nodelet.h>
#include <ros/ros.h>
#include <std_srvs/Trigger.h>

#include <atomic>
#include <cstdio>
#include <limits>
#include <pluginlib/class_list_macros.hpp>

#include "wild_mvs/core/error.h"
#include "wild_mvs/ros/bus_stats.h"
#include "wild_mvs/ros/conversions.h"
#include "wild_mvs/ros/depth_inputs.h"
#include "wild_mvs/ros/depth_messages.h"
#include "wild_mvs/ros/keyframe_link.h"
#include "wild_mvs/ros/live_params.h"
#include "wild_mvs/ros/params_ros.h"
#include "wild_mvs/stream/drop_counter.h"
#include "wild_mvs/stream/stream_reconstructor.h"
#include "wild_mvs/stream/work_queue.h"

namespace wild_mvs {
namespace ros1 {

struct DepthNode::Impl {
  ros::NodeHandle nh, pnh;
  DepthNodeOptions options;
  DropCounter drops;
  std::unique_ptr<DepthInputs> inputs;
  std::unique_ptr<DepthOutputs> outputs;
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
  // Live tuning (dynamic_reconfigure protocol) over a copy of the options,
  // and ~reset.
  DepthNodeOptions live;
  OptionRegistry live_registry;
  std::unique_ptr<LiveParams> live_params;
  ros::ServiceServer reset_srv;
  std::atomic<uint64_t> evictions_reported{0};
  DropCounter evictions;         // throttles the warning below
  RoscppDropWatch roscpp_drops;  // roscpp's own queue drops, into `drops`
  // Several workers: the selector's announcer, a worker's receiver.
  std::unique_ptr<KeyframeAnnouncer> announcer;
  std::unique_ptr<KeyframeReceiver> receiver;
  ros::Subscriber keyframe_sub, index_sub;
  ros::SteadyTimer index_timer;

  // Warns (throttled) when keyframes were evicted from the full keyframe
  // store before their depth map was made: reconstruction is slower than
  // keyframes arrive. They are counted in diagnostics and in the summary.
  // `total`: StreamStats::evicted_waiting.
  void ReportEvictions(uint64_t total) {
    uint64_t seen = evictions_reported.load();
    while (seen < total &&
           !evictions_reported.compare_exchange_weak(seen, total)) {
    }
    if (seen >= total) return;
    bool log = false;
    for (uint64_t k = seen; k < total; ++k) log |= evictions.Count("evicted");
    if (log)
      ROS_WARN(
          "%s: keyframe store full: %lu keyframes so far evicted before "
          "their depth map (depth maps are made slower than keyframes "
          "arrive; max_keyframes = %d, max_keyframe_mb = %.0f: raise them, "
          "lower the frame rate or keyframe_min_baseline; throttled to one "
          "message per %.0f s)",
          pnh.getNamespace().c_str(), static_cast<unsigned long>(total),
          options.stream.store.max_keyframes, options.stream.store.max_mb,
          kErrorThrottle);
  }

  // Counts and (throttled) reports one dropped input.
  void Drop(const std::string& topic, const std::string& problem,
            const std::string& detail = "") {
    uint64_t n = 0;
    const std::string reason = topic + ": " + problem;
    if (drops.Count(reason, &n)) {
      ROS_ERROR(
          "%s: dropped: %s%s%s (%lu so far; throttled to one message "
          "per %.0f s per problem)",
          pnh.getNamespace().c_str(), reason.c_str(),
          detail.empty() ? "" : ": ", detail.c_str(),
          static_cast<unsigned long>(n), kErrorThrottle);
    }
  }

  // The topic frames come from: `image` (or its compressed topic), a
  // worker's `keyframes`.
  std::string InputTopic() const {
    if (receiver) return receiver->keyframes_topic();
    return inputs->Topic("image") +
           (options.image_transport == "raw" ? "" : "/compressed");
  }

  void Enqueue(DepthFrame f) {
    if (frame_rate && !f.index) frame_rate->tick();
    if (!queue->Push(std::move(f)))
      Drop(InputTopic(),
           "input queue full (frames arrive faster than they are processed)");
  }

  // Adds a frame whose camera (intrinsics and pose) is known to the stream;
  // only a keyframe's image is converted.
  StreamReconstructor::FrameStatus AddToStream(const DepthFrame& f,
                                               const Camera& cam,
                                               const std::string& topic) {
    StreamReconstructor::FrameStatus status;
    try {
      status = stream->AddFrame(f.stamp.toNSec(), f.frame_id, cam,
                                [this, &f](Camera* c, cv::Mat* image) {
                                  return inputs->ConvertImage(f, c, image);
                                });
    } catch (const Error& e) {
      Drop(topic, "rejected frame", e.what());
      return StreamReconstructor::FrameStatus::kDropped;
    }
    ReportEvictions(stream->Stats().evicted_waiting);
    switch (status) {
      case StreamReconstructor::FrameStatus::kOutOfOrder:
        Drop(topic, "stamp out of order (not after the previous frame)");
        break;
      case StreamReconstructor::FrameStatus::kReset:
        ROS_WARN(
            "%s: time or pose jump at stamp %.3f: keyframes and tracks "
            "reset, starting again from this frame",
            pnh.getNamespace().c_str(), f.stamp.toSec());
        break;
      default:
        break;
    }
    return status;
  }

  // A worker: one keyframe of the selector (in id order, KeyframeReceiver).
  void TakeKeyframe(const wild_mvs::SelectedKeyframeConstPtr& k) {
    const std::string topic = receiver->keyframes_topic();
    if (inputs->NoSlash(k->camera_pose.header.frame_id) !=
        options.world_frame) {
      Drop(topic, "camera_pose frame is not the world frame",
           "'" + k->camera_pose.header.frame_id + "' vs '" +
               options.world_frame + "'");
      return;
    }
    DepthFrame f;
    f.stamp = k->header.stamp;
    f.frame_id = inputs->NoSlash(k->header.frame_id);
    // The selector's messages, shared (no copy of the pixels).
    if (!k->image.data.empty())
      f.raw = sensor_msgs::ImageConstPtr(k, &k->image);
    else if (!k->compressed.data.empty())
      f.compressed = sensor_msgs::CompressedImageConstPtr(k, &k->compressed);
    if (!f.raw && !f.compressed) {
      Drop(topic, "keyframe without an image");
      return;
    }
    f.info = sensor_msgs::CameraInfoConstPtr(k, &k->camera_info);
    Camera cam;
    if (!inputs->CameraFromInfo(f, &cam)) return;
    try {
      SetCameraPose(k->camera_pose.pose, &cam);
    } catch (const Error& e) {
      Drop(topic, "invalid camera_pose", e.what());
      return;
    }
    // The selector's session, numbering and tracks.
    stream->FollowSession(k->session.toNSec());
    stream->SetNextKeyframeId(k->keyframe_id);
    stream->SetSparsePoints(StampedPointsFromMsg(k->points));
    AddToStream(f, cam, topic);
  }

  // The front end, one frame at a time.
  void Process(DepthFrame f) {
    if (f.keyframe) return receiver->OnKeyframe(f.keyframe);
    if (f.index) return receiver->OnIndex(f.index);
    const std::string image_topic = inputs->ImageTopic(f);
    if (!inputs->PairCameraInfo(&f)) return;
    if (stream->IsOutOfOrder(f.stamp.toNSec())) {
      Drop(image_topic, "stamp out of order (not after the previous frame)");
      return;
    }
    // Intrinsics and pose first: the keyframe test needs only the pose, and
    // only a keyframe's image is decoded and undistorted.
    Camera cam;
    if (!inputs->CameraFromInfo(f, &cam) || !inputs->LookupPose(f, &cam))
      return;
    const StreamReconstructor::FrameStatus status =
        AddToStream(f, cam, image_topic);
    // A selector hands each new keyframe to the workers.
    if (announcer && (status == StreamReconstructor::FrameStatus::kKeyframe ||
                      status == StreamReconstructor::FrameStatus::kReset)) {
      StreamReconstructor::KeyframeInfo info;
      if (stream->Newest(&info) && info.stamp_ns == f.stamp.toNSec())
        announcer->Publish(info, f, cam, stream->TrackedPoints());
    }
  }

  void FrontEnd(DepthFrame f) {
    try {
      Process(std::move(f));
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
    if (keyframe_sub)
      queues[keyframe_sub.getTopic()] = "the worker falls behind the keyframes";
    roscpp_drops.Update(queues, &drops);
    const StreamStats s = stream->Stats();
    DepthInputStats in;
    in.role = options.role;
    if (announcer) {
      in.keyframes_published = announcer->published();
      in.keyframes_served = announcer->served();
    }
    if (receiver) {
      const KeyframeReceiver::Stats r = receiver->stats();
      in.keyframes_received = r.received;
      in.keyframes_fetched = r.fetched;
      in.keyframes_lost = r.lost;
      in.keyframes_repeated = r.repeated;
    }
    // A worker's queue also carries the index messages: count keyframes.
    in.received = receiver ? receiver->stats().received : queue->received();
    in.queued = queue->size();
    in.queue_size = static_cast<int>(queue->capacity());
    ReportEvictions(s.evicted_waiting);
    in.recent_evictions = evictions.RecentTotal();
    FillDepthDiagnostics(s, in, drops, stat);
  }
};

DepthNode::DepthNode(const ros::NodeHandle& nh, const ros::NodeHandle& pnh)
    : impl_(std::make_unique<Impl>()) {
  Impl& m = *impl_;
  m.nh = nh;
  m.pnh = pnh;
  RosParamSource params(pnh);
  m.options = ReadDepthNodeOptions(params);
  for (const std::string& n : UnknownDepthNodeParams(params))
    ROS_WARN("%s: unknown parameter '%s' (ignored; see config/depth_node.yaml)",
             pnh.getNamespace().c_str(), n.c_str());
  m.inputs = std::make_unique<DepthInputs>(
      m.nh, m.pnh, m.options,
      [&m](const std::string& topic, const std::string& problem,
           const std::string& detail) { m.Drop(topic, problem, detail); });
  // Frame ids as tf2 wants them (leading '/' stripped, warned once).
  m.options.world_frame = m.inputs->NoSlash(m.options.world_frame);
  if (!m.options.camera_frame.empty())
    m.options.camera_frame = m.inputs->NoSlash(m.options.camera_frame);
  m.drops.set_throttle(kErrorThrottle);
  m.evictions.set_throttle(kErrorThrottle);
  m.drops.set_window(kDropWindow);
  m.evictions.set_window(kDropWindow);
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
  m.outputs = std::make_unique<DepthOutputs>(
      m.pnh, o.world_frame, o.depth_encoding, o.stream.worker_index);
  m.stream = std::make_unique<StreamReconstructor>(
      o.stream,
      [&m](const StreamResult& r) {
        m.outputs->Publish(r);
        if (m.map_rate) m.map_rate->tick();
      },
      [&m](const std::string& e) {
        m.Drop("reconstruction", "keyframe failed", e);
      });
  // A worker's queue holds keyframes (a few per second at most).
  m.queue = std::make_unique<WorkQueue<DepthFrame>>(
      o.role == "worker" ? kKeyframeQueueSize : o.input_queue_size,
      [&m](DepthFrame f) { m.FrontEnd(std::move(f)); });
  if (o.role == "worker") {
    m.receiver = std::make_unique<KeyframeReceiver>(
        m.nh, kRepairDelay,
        [&m](const wild_mvs::SelectedKeyframeConstPtr& k) {
          m.TakeKeyframe(k);
        },
        [&m](const std::string& topic, const std::string& problem,
             const std::string& detail) { m.Drop(topic, problem, detail); });
    m.keyframe_sub = m.nh.subscribe<wild_mvs::SelectedKeyframe>(
        "keyframes", kKeyframeQueueSize,
        [&m](const wild_mvs::SelectedKeyframeConstPtr& k) {
          DepthFrame f;
          f.keyframe = k;
          f.stamp = k->header.stamp;
          m.Enqueue(std::move(f));
        });
    m.index_sub = m.nh.subscribe<wild_mvs::KeyframeIndex>(
        "keyframe_index", 10, [&m](const wild_mvs::KeyframeIndexConstPtr& k) {
          DepthFrame f;
          f.index = k;
          m.Enqueue(std::move(f));
        });
  } else {
    if (o.role == "selector") {
      m.announcer = std::make_unique<KeyframeAnnouncer>(m.pnh, o.world_frame,
                                                        kKeyframeHistory);
      m.index_timer = m.nh.createSteadyTimer(
          ros::WallDuration(1.0),
          [&m](const ros::SteadyTimerEvent&) { m.announcer->PublishIndex(); });
    }
    m.inputs->Subscribe(
        [&m](DepthFrame f) { m.Enqueue(std::move(f)); },
        [&m](std::vector<StreamReconstructor::StampedPoint> points) {
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
  // Live: the keyframe thresholds and the main MVS thresholds.
  m.live = m.options;
  RegisterOptions(&m.live_registry, "", &m.live);
  m.live_params = std::make_unique<LiveParams>(
      m.pnh, &m.live_registry,
      std::vector<std::string>{
          "keyframe_min_baseline", "keyframe_min_angle_deg",
          "mvs.max_image_size", "mvs.global.num_neighbors", "mvs.local.min_ncc",
          "mvs.mpgc.drop_ncc", "mvs.growing.revisit_margin"},
      [&m] {
        m.live.Check();
        m.stream->SetOptions(m.live.stream);
      });
  m.reset_srv = m.pnh.advertiseService("reset", &Impl::OnReset, &m);
  m.queue->Start();  // the front-end thread
  if (o.role == "worker") {
    ROS_INFO(
        "%s: depth worker %d of %d, keyframes from %s (missed ones from %s), "
        "world frame '%s'",
        pnh.getNamespace().c_str(), o.stream.worker_index,
        o.stream.worker_count, m.receiver->keyframes_topic().c_str(),
        m.nh.resolveName("get_keyframe").c_str(), o.world_frame.c_str());
  } else {
    const std::string what = o.role == "selector"
                                 ? std::string("keyframe selector (~keyframes)")
                                 : Msg("worker ", o.stream.worker_index, " of ",
                                       o.stream.worker_count);
    ROS_INFO(
        "%s: %s, images %s (%s%s), camera_info %s (%s), pose from %s, sparse "
        "points from %s, world frame '%s'",
        pnh.getNamespace().c_str(), what.c_str(),
        m.inputs->image_topic().c_str(), o.image_transport.c_str(),
        m.inputs->rectified() ? ", rectified" : "",
        m.inputs->info_topic().c_str(),
        o.camera_info_latest ? "latest" : "paired by stamp",
        o.pose_source.c_str(), o.sparse_source.c_str(), o.world_frame.c_str());
  }
}

DepthNode::~DepthNode() {
  Impl& m = *impl_;
  m.tick_timer.stop();
  m.diag_timer.stop();
  m.index_timer.stop();
  m.keyframe_sub.shutdown();
  m.index_sub.shutdown();
  m.inputs->Stop();  // ends the waits, unsubscribes the images
  m.queue->Stop();   // joins the front end; frames still queued are dropped
  // A running depth map is cancelled (it ends within a few pixels per
  // tile: roslaunch escalates to SIGKILL 15 s after SIGINT).
  m.stream->Shutdown();
  const StreamStats s = m.stream->Stats();
  std::fprintf(stderr,
               "depth node: %lu frames received, %lu keyframes, %lu depth "
               "maps (%lu cancelled at shutdown), %lu frames dropped, %lu "
               "keyframes evicted before a depth map, %lu stream resets\n",
               static_cast<unsigned long>(m.queue->received()),
               static_cast<unsigned long>(s.keyframes_total),
               static_cast<unsigned long>(s.reconstructed),
               static_cast<unsigned long>(s.cancelled),
               static_cast<unsigned long>(m.drops.Total()),
               static_cast<unsigned long>(s.evicted_waiting),
               static_cast<unsigned long>(s.resets));
  m.stream.reset();
}

// The nodelet: the same node inside a nodelet manager.
class DepthNodelet : public nodelet::Nodelet {
 private:
  void onInit() override {
    try {
      // Multi-threaded callback queues (image, camera_info and pose
      // callbacks, timers and services never wait for one another).
      node_ = std::make_unique<DepthNode>(getMTNodeHandle(),
                                          getMTPrivateNodeHandle());
    } catch (const std::exception& e) {
      NODELET_FATAL("%s", e.what());
      throw;
    }
  }
  std::unique_ptr<DepthNode> node_;
};

}  // namespace ros1
}  // namespace wild_mvs

PLUGINLIB_EXPORT_CLASS(wild_mvs::ros1::DepthNodelet, nodelet::Nodelet)
