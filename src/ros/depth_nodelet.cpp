// Copyright wild_mvs authors.
#include "wild_mvs/ros/depth_nodelet.h"

#include <diagnostic_updater/diagnostic_updater.h>
#include <geometry_msgs/PoseStamped.h>
#include <image_transport/camera_common.h>
#include <image_transport/image_transport.h>
#include <nodelet/nodelet.h>
#include <ros/ros.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/CompressedImage.h>
#include <sensor_msgs/Image.h>
#include <sensor_msgs/PointCloud2.h>
#include <tf2_ros/buffer.h>
#include <tf2_ros/transform_listener.h>
#include <wild_mvs/DepthView.h>
#include <wild_mvs/SparsePoints.h>

#include <atomic>
#include <cmath>
#include <condition_variable>
#include <cstdio>
#include <deque>
#include <map>
#include <mutex>
#include <pluginlib/class_list_macros.hpp>
#include <set>
#include <thread>

#include "wild_mvs/core/error.h"
#include "wild_mvs/ros/conversions.h"
#include "wild_mvs/ros/params_ros.h"
#include "wild_mvs/ros/undistorter.h"
#include "wild_mvs/stream/drop_counter.h"
#include "wild_mvs/stream/stream_reconstructor.h"

namespace wild_mvs {
namespace ros1 {

struct DepthNode::Impl {
  struct Frame {
    sensor_msgs::ImageConstPtr raw;
    sensor_msgs::CompressedImageConstPtr compressed;
    sensor_msgs::CameraInfoConstPtr info;
    ros::Time stamp;
    std::string frame_id;
  };

  ros::NodeHandle nh, pnh;
  DepthNodeOptions options;
  DropCounter drops;
  std::unique_ptr<tf2_ros::Buffer> tf_buffer;
  std::unique_ptr<tf2_ros::TransformListener> tf_listener;
  std::unique_ptr<image_transport::ImageTransport> it, private_it;
  image_transport::Subscriber image_sub;
  ros::Subscriber compressed_sub, info_sub, pose_sub, points_sub;
  // REP 118 camera pairs (image_transport CameraPublisher: ~depth/image_rect
  // + ~depth/camera_info, ~confidence/image + ~confidence/camera_info).
  image_transport::CameraPublisher depth_pub, confidence_pub;
  image_transport::Publisher normals_pub;
  ros::Publisher points_pub, view_pub;
  // Periodic work about machine time (scheduling, diagnostics): steady
  // timers, so that it goes on when /clock pauses or stops (sim time).
  ros::SteadyTimer tick_timer, diag_timer;
  std::string image_topic, info_topic;       // resolved input names
  bool rectified = false;                    // camera from P, D ignored
  std::unique_ptr<Undistorter> undistorter;  // front end only
  std::unique_ptr<diagnostic_updater::Updater> updater;
  std::unique_ptr<StreamReconstructor> stream;

  std::mutex mutex;  // guards the fields below
  std::condition_variable cv;
  std::deque<Frame> queue;
  sensor_msgs::CameraInfoConstPtr latest_info;
  // Recent camera_infos by exact stamp (ns), for pairing with images.
  std::map<uint64_t, sensor_msgs::CameraInfoConstPtr> infos;
  std::set<std::string> slash_warned;  // frame ids warned about once
  std::deque<geometry_msgs::PoseStampedConstPtr> poses;
  bool stop = false;
  uint64_t received = 0;
  std::thread frontend;

  double last_stamp = -1;  // front end only
  std::atomic<uint64_t> reset_count{0};
  std::atomic<uint64_t> evictions_reported{0};
  DropCounter evictions;  // throttles the warning below

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
    if (evictions.Count("evicted", nullptr))
      ROS_WARN(
          "%s: keyframe store full: %lu keyframes so far evicted before "
          "their depth map (depth maps are made slower than keyframes "
          "arrive; max_keyframes = %d, max_keyframe_mb = %.0f: raise them, "
          "lower the frame rate or keyframe_min_baseline; throttled to one "
          "message per %.0f s)",
          pnh.getNamespace().c_str(), static_cast<unsigned long>(total),
          options.stream.store.max_keyframes, options.stream.store.max_mb,
          options.error_throttle);
  }

  std::string Topic(const std::string& name) const {
    return nh.resolveName(name);
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
          static_cast<unsigned long>(n), options.error_throttle);
    }
  }

  void Enqueue(Frame f) {
    bool dropped = false;
    {
      std::lock_guard<std::mutex> lock(mutex);
      ++received;
      if (static_cast<int>(queue.size()) >= options.input_queue_size) {
        queue.pop_front();
        dropped = true;
      }
      queue.push_back(std::move(f));
    }
    cv.notify_all();
    if (dropped)
      Drop(Topic("image") +
               (options.image_transport == "raw" ? "" : "/compressed"),
           "input queue full (frames arrive faster than they are processed)");
  }

  // A frame id as tf2 wants it: without leading '/' (tf2 rejects them, and
  // many recorded bags have them); warns once per frame id.
  std::string NoSlash(const std::string& frame_id) {
    const std::string stripped = StripLeadingSlash(frame_id);
    if (stripped == frame_id) return frame_id;
    bool first = false;
    {
      std::lock_guard<std::mutex> lock(mutex);
      first = slash_warned.insert(frame_id).second;
    }
    if (first)
      ROS_WARN(
          "%s: frame id '%s' starts with '/', which tf2 does not accept: "
          "using '%s' (warned once per frame id)",
          pnh.getNamespace().c_str(), frame_id.c_str(), stripped.c_str());
    return stripped;
  }

  void OnImage(const sensor_msgs::ImageConstPtr& msg) {
    Frame f;
    f.raw = msg;
    f.stamp = msg->header.stamp;
    f.frame_id = msg->header.frame_id;
    Enqueue(std::move(f));
  }
  void OnCompressed(const sensor_msgs::CompressedImageConstPtr& msg) {
    Frame f;
    f.compressed = msg;
    f.stamp = msg->header.stamp;
    f.frame_id = msg->header.frame_id;
    Enqueue(std::move(f));
  }
  void OnInfo(const sensor_msgs::CameraInfoConstPtr& msg) {
    {
      std::lock_guard<std::mutex> lock(mutex);
      latest_info = msg;
      infos[msg->header.stamp.toNSec()] = msg;
      while (infos.size() > 100) infos.erase(infos.begin());
    }
    cv.notify_all();
  }

  // The camera_info for a frame: the one with the frame's exact stamp
  // (waiting up to tf_timeout of wall time for it), or with
  // camera_info_latest the latest one. Null (and counted) when none.
  sensor_msgs::CameraInfoConstPtr InfoFor(const Frame& f) {
    const uint64_t key = f.stamp.toNSec();
    const auto deadline = std::chrono::steady_clock::now() +
                          std::chrono::duration<double>(options.tf_timeout);
    std::unique_lock<std::mutex> lock(mutex);
    auto ready = [&] {
      if (stop) return true;
      if (options.camera_info_latest) return latest_info != nullptr;
      return infos.count(key) > 0;
    };
    cv.wait_until(lock, deadline, ready);
    if (options.camera_info_latest) {
      if (latest_info) return latest_info;
      lock.unlock();
      Drop(info_topic, "no camera_info received yet");
      return nullptr;
    }
    auto it_info = infos.find(key);
    if (it_info != infos.end()) return it_info->second;
    const bool any = !infos.empty();
    lock.unlock();
    Drop(info_topic,
         any ? "no camera_info with the image's stamp (images and "
               "camera_info are paired by exact stamp; set "
               "camera_info_latest:=true for a driver that publishes it "
               "once or at another rate)"
             : "no camera_info received yet");
    return nullptr;
  }
  void OnPose(const geometry_msgs::PoseStampedConstPtr& msg) {
    {
      std::lock_guard<std::mutex> lock(mutex);
      poses.push_back(msg);
      while (poses.size() > 500) poses.pop_front();
    }
    cv.notify_all();
  }
  void OnSparsePoints(const wild_mvs::SparsePointsConstPtr& msg) {
    if (NoSlash(msg->header.frame_id) != options.world_frame) {
      Drop(Topic("sparse_points"), "frame_id '" + msg->header.frame_id +
                                       "' is not the world frame '" +
                                       options.world_frame + "'");
      return;
    }
    std::vector<StreamReconstructor::StampedPoint> pts;
    pts.reserve(msg->points.size());
    for (const auto& p : msg->points) {
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
    stream->SetSparsePoints(pts);
  }

  // Pose of the frame from tf or the pose topic; false (and counted) when
  // there is none within the timeout.
  bool LookupPose(const Frame& f, Camera* cam) {
    if (options.pose_source == "tf") {
      if (f.frame_id.empty()) {
        Drop(Topic("image"), "image has an empty frame_id (needed for tf)");
        return false;
      }
      geometry_msgs::TransformStamped T;
      try {
        // Wait in wall time (tf2's own timeout runs on ROS time, which
        // stands still when /clock pauses), polling the buffer.
        const auto deadline = std::chrono::steady_clock::now() +
                              std::chrono::duration<double>(options.tf_timeout);
        while (!tf_buffer->canTransform(options.world_frame, f.frame_id,
                                        f.stamp) &&
               std::chrono::steady_clock::now() < deadline) {
          {
            std::lock_guard<std::mutex> lock(mutex);
            if (stop) break;
          }
          std::this_thread::sleep_for(std::chrono::milliseconds(2));
        }
        T = tf_buffer->lookupTransform(options.world_frame, f.frame_id,
                                       f.stamp);
      } catch (const tf2::TransformException& e) {
        Drop("tf",
             "no transform " + options.world_frame + " <- " + f.frame_id +
                 " at the image stamp within tf_timeout",
             e.what());
        return false;
      }
      try {
        SetCameraPose(T.transform, cam);
      } catch (const Error& e) {
        Drop("tf", "invalid pose", e.what());
        return false;
      }
      return true;
    }
    // Pose topic: the pose whose stamp is closest, within the tolerance.
    const auto deadline = std::chrono::steady_clock::now() +
                          std::chrono::duration<double>(options.tf_timeout);
    geometry_msgs::PoseStampedConstPtr best;
    std::unique_lock<std::mutex> lock(mutex);
    for (;;) {
      double best_dt = options.pose_sync_tolerance;
      for (const auto& p : poses) {
        const double dt = std::abs((p->header.stamp - f.stamp).toSec());
        if (dt <= best_dt) {
          best_dt = dt;
          best = p;
        }
      }
      if (best || stop) break;
      if (cv.wait_until(lock, deadline) == std::cv_status::timeout) break;
    }
    lock.unlock();
    if (!best) {
      Drop(Topic("pose"),
           "no pose within pose_sync_tolerance of the image "
           "stamp within tf_timeout");
      return false;
    }
    if (NoSlash(best->header.frame_id) != options.world_frame) {
      Drop(Topic("pose"), "pose frame_id '" + best->header.frame_id +
                              "' is not the world frame '" +
                              options.world_frame + "'");
      return false;
    }
    try {
      SetCameraPose(best->pose, cam);
    } catch (const Error& e) {
      Drop(Topic("pose"), "invalid pose", e.what());
      return false;
    }
    return true;
  }

  void Process(Frame f) {
    const std::string image_topic =
        this->image_topic + (f.raw ? "" : "/" + options.image_transport);
    // The camera's optical frame: ~camera_frame, else the image's.
    f.frame_id = NoSlash(options.camera_frame.empty() ? f.frame_id
                                                      : options.camera_frame);
    f.info = InfoFor(f);
    if (!f.info) return;
    const double stamp = f.stamp.toSec();
    if (last_stamp >= 0 && stamp <= last_stamp &&
        last_stamp - stamp <= options.stream.stamp_reset_threshold) {
      Drop(image_topic, "stamp out of order (not after the previous frame)");
      return;
    }
    Camera cam;
    Distortion dist;
    try {
      CameraFromCameraInfo(*f.info, &cam, &dist, rectified);
    } catch (const Error& e) {
      Drop(info_topic, "invalid camera_info", e.what());
      return;
    }
    cv::Mat image;
    try {
      image = f.raw ? ImageToLinearRgb(*f.raw, options.linearize)
                    : CompressedToLinearRgb(*f.compressed, options.linearize);
    } catch (const Error& e) {
      Drop(image_topic, "invalid image", e.what());
      return;
    }
    if (image.cols != cam.width || image.rows != cam.height) {
      Drop(
          image_topic, "image size differs from camera_info",
          Msg(image.cols, "x", image.rows, " vs ", cam.width, "x", cam.height));
      return;
    }
    // Undistorted with maps built once per camera_info (a rectified
    // input passes through: the camera is P's).
    try {
      image = undistorter->Apply(*f.info, image, &cam);
    } catch (const Error& e) {
      Drop(info_topic, "invalid camera_info", e.what());
      return;
    }
    if (!LookupPose(f, &cam)) return;
    StreamReconstructor::FrameStatus status;
    try {
      status = stream->AddFrame(f.stamp.toNSec(), f.frame_id, cam, image);
    } catch (const Error& e) {
      Drop(image_topic, "rejected frame", e.what());
      return;
    }
    ReportEvictions(stream->Stats().evicted_waiting);
    switch (status) {
      case StreamReconstructor::FrameStatus::kOutOfOrder:
        Drop(image_topic, "stamp out of order (not after the previous frame)");
        return;
      case StreamReconstructor::FrameStatus::kReset:
        ++reset_count;
        ROS_WARN(
            "%s: time or pose jump at stamp %.3f: keyframes and tracks "
            "reset, starting again from this frame",
            pnh.getNamespace().c_str(), stamp);
        break;
      default:
        break;
    }
    last_stamp = stamp;
  }

  void FrontEnd() {
    for (;;) {
      Frame f;
      {
        std::unique_lock<std::mutex> lock(mutex);
        cv.wait(lock, [this] { return stop || !queue.empty(); });
        if (stop) return;
        f = std::move(queue.front());
        queue.pop_front();
      }
      try {
        Process(f);
      } catch (const std::exception& e) {
        Drop(Topic("image"), "unexpected error", e.what());
      }
    }
  }

  void Publish(const StreamResult& r) {
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
    view->worker_index = options.stream.worker_index;
    view->revision = r.revision;
    FillDepthView(r.depth, options.world_frame, view.get());
    if (!r.image.empty())
      view->image = ColorToMsg(r.image, r.depth.width(), r.depth.height());
    view->image.header = header;
    // Lazy outputs: only built / sent when someone listens. Every image
    // and camera_info has the source image's header (stamp and frame).
    view->depth.header = view->confidence.header = view->normals.header =
        view->camera_info.header = header;
    if (depth_pub.getNumSubscribers() > 0) {
      if (options.depth_encoding == "16UC1") {
        sensor_msgs::Image mm = DepthToMsg16(r.depth.depth);
        mm.header = header;
        depth_pub.publish(mm, view->camera_info);
      } else {
        depth_pub.publish(view->depth, view->camera_info);
      }
    }
    if (confidence_pub.getNumSubscribers() > 0)
      confidence_pub.publish(view->confidence, view->camera_info);
    if (normals_pub.getNumSubscribers() > 0) normals_pub.publish(view->normals);
    if (points_pub.getNumSubscribers() > 0) {
      sensor_msgs::PointCloud2 pc =
          CloudToMsg(DepthMapToCloud(r.depth, r.image));
      pc.header.stamp = header.stamp;
      pc.header.frame_id = options.world_frame;
      points_pub.publish(pc);
    }
    view_pub.publish(view);
    ROS_INFO(
        "%s: keyframe %u (rev %u): %d depth samples, %zu neighbours, "
        "%.2f s",
        pnh.getNamespace().c_str(), r.keyframe_id, r.revision,
        r.depth.CountValid(), r.neighbor_ids.size(), r.seconds);
  }

  void Diagnose(diagnostic_updater::DiagnosticStatusWrapper& stat) {
    const StreamStats s = stream->Stats();
    size_t queued = 0;
    uint64_t recv = 0;
    {
      std::lock_guard<std::mutex> lock(mutex);
      queued = queue.size();
      recv = received;
    }
    const uint64_t dropped = drops.Total();
    ReportEvictions(s.evicted_waiting);
    if (dropped > 0 || s.evicted_waiting > 0) {
      stat.summaryf(diagnostic_msgs::DiagnosticStatus::WARN,
                    "%lu frames dropped (see dropped: entries), %lu "
                    "keyframes evicted before reconstruction",
                    static_cast<unsigned long>(dropped),
                    static_cast<unsigned long>(s.evicted_waiting));
    } else {
      stat.summary(diagnostic_msgs::DiagnosticStatus::OK, "running");
    }
    stat.add("frames received", recv);
    stat.add("input queue length", queued);
    stat.add("input queue size", options.input_queue_size);
    stat.add("keyframes held", s.keyframes);
    stat.add("keyframe store MB", s.store_mb);
    stat.add("keyframes created", s.keyframes_total);
    stat.add("reconstructions pending", s.pending);
    stat.add("keyframes waiting", s.waiting);
    stat.add("depth maps", s.reconstructed);
    stat.add("depth maps redone", s.redone);
    stat.add("reconstructions failed", s.failed);
    stat.add("keyframes evicted before reconstruction", s.evicted_waiting);
    stat.add("stream resets", s.resets);
    stat.addf("session", "%.6f", s.session);  // stamp that started it
    stat.add("sparse points", s.sparse_points);
    stat.add("tracker MB", s.tracker_mb);
    stat.add("last seconds per depth map", s.last_seconds);
    stat.add("mean seconds per depth map", s.mean_seconds);
    stat.add("frames dropped", dropped);
    for (const auto& [reason, n] : drops.Counts())
      stat.add("dropped: " + reason, n);
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
  // Frame ids as tf2 wants them (leading '/' stripped, warned once).
  m.options.world_frame = m.NoSlash(m.options.world_frame);
  if (!m.options.camera_frame.empty())
    m.options.camera_frame = m.NoSlash(m.options.camera_frame);
  m.drops.set_throttle(m.options.error_throttle);
  m.evictions.set_throttle(m.options.error_throttle);
  const DepthNodeOptions& o = m.options;

  m.stream = std::make_unique<StreamReconstructor>(
      o.stream, [&m](const StreamResult& r) { m.Publish(r); },
      [&m](const std::string& e) {
        m.Drop("reconstruction", "keyframe failed", e);
      });

  m.private_it = std::make_unique<image_transport::ImageTransport>(m.pnh);
  m.depth_pub = m.private_it->advertiseCamera("depth/image_rect", 2);
  m.confidence_pub = m.private_it->advertiseCamera("confidence/image", 2);
  m.normals_pub = m.private_it->advertise("normals/image", 2);
  m.points_pub = m.pnh.advertise<sensor_msgs::PointCloud2>("points", 2);
  m.view_pub = m.pnh.advertise<wild_mvs::DepthView>("depth_view", 20);

  if (o.pose_source == "tf") {
    m.tf_buffer = std::make_unique<tf2_ros::Buffer>(ros::Duration(30.0));
    m.tf_listener =
        std::make_unique<tf2_ros::TransformListener>(*m.tf_buffer, m.nh, true);
  } else {
    m.pose_sub = m.nh.subscribe("pose", 50, &Impl::OnPose, &m);
  }
  if (o.sparse_source == "topic")
    m.points_sub =
        m.nh.subscribe("sparse_points", 2, &Impl::OnSparsePoints, &m);
  // Inputs. camera_info sits beside the image (image_transport's
  // CameraSubscriber convention) unless `camera_info` is remapped itself.
  m.image_topic = m.nh.resolveName("image");
  m.info_topic = m.nh.resolveName("camera_info");
  if (m.info_topic == m.nh.resolveName("camera_info", false))
    m.info_topic = image_transport::getCameraInfoTopic(m.image_topic);
  auto ends_with = [](const std::string& s, const std::string& tail) {
    return s.size() >= tail.size() &&
           s.compare(s.size() - tail.size(), tail.size(), tail) == 0;
  };
  m.rectified = o.rectified || ends_with(m.image_topic, "/image_rect") ||
                ends_with(m.image_topic, "/image_rect_color");
  m.undistorter = std::make_unique<Undistorter>(m.rectified);
  m.info_sub = m.nh.subscribe(m.info_topic, 20, &Impl::OnInfo, &m);
  m.it = std::make_unique<image_transport::ImageTransport>(m.nh);
  const std::vector<std::string> plugins = m.it->getLoadableTransports();
  const bool have_plugin = std::find(plugins.begin(), plugins.end(),
                                     o.image_transport) != plugins.end();
  if (o.image_transport == "raw" || have_plugin) {
    m.image_sub = m.it->subscribe(m.image_topic, 5, &Impl::OnImage, &m,
                                  image_transport::TransportHints(
                                      o.image_transport, ros::TransportHints(),
                                      m.pnh, "image_transport_hints"));
  } else if (o.image_transport == "compressed") {
    // No compressed plugin installed (Debian 12 ships none): take
    // <image>/compressed and decode it here. "image" is remapped as a
    // whole name, so it is resolved before appending.
    m.compressed_sub = m.nh.subscribe(m.image_topic + "/compressed", 5,
                                      &Impl::OnCompressed, &m);
  } else {
    std::string names;
    for (const std::string& p : plugins) names += " " + p;
    throw Error(Msg("image_transport = '", o.image_transport,
                    "': no such image_transport plugin is installed "
                    "(loadable:",
                    names, ")"));
  }

  m.updater = std::make_unique<diagnostic_updater::Updater>(
      m.nh, m.pnh, m.pnh.getNamespace());
  m.updater->setHardwareID("wild_mvs_depth");
  m.updater->add("depth_node", &m, &Impl::Diagnose);
  m.diag_timer = m.nh.createSteadyTimer(
      ros::WallDuration(o.diagnostics_period),
      [&m](const ros::SteadyTimerEvent&) { m.updater->force_update(); });
  m.tick_timer = m.nh.createSteadyTimer(
      ros::WallDuration(0.2),
      [&m](const ros::SteadyTimerEvent&) { m.stream->Tick(); });
  m.frontend = std::thread([&m] { m.FrontEnd(); });
  ROS_INFO(
      "%s: worker %d of %d, images %s (%s%s), camera_info %s (%s), pose "
      "from %s, sparse points from %s, world frame '%s'",
      pnh.getNamespace().c_str(), o.stream.worker_index, o.stream.worker_count,
      m.image_topic.c_str(), o.image_transport.c_str(),
      m.rectified ? ", rectified" : "", m.info_topic.c_str(),
      o.camera_info_latest ? "latest" : "paired by stamp",
      o.pose_source.c_str(), o.sparse_source.c_str(), o.world_frame.c_str());
}

DepthNode::~DepthNode() {
  Impl& m = *impl_;
  m.tick_timer.stop();
  m.diag_timer.stop();
  {
    std::lock_guard<std::mutex> lock(m.mutex);
    m.stop = true;
  }
  m.cv.notify_all();
  if (m.frontend.joinable()) m.frontend.join();
  m.image_sub.shutdown();
  m.compressed_sub.shutdown();
  const StreamStats s = m.stream->Stats();
  std::fprintf(stderr,
               "depth node: %lu frames received, %lu keyframes, %lu depth "
               "maps, %lu frames dropped, %lu keyframes evicted before a "
               "depth map, %lu stream resets\n",
               static_cast<unsigned long>(m.received),
               static_cast<unsigned long>(s.keyframes_total),
               static_cast<unsigned long>(s.reconstructed),
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
      node_ =
          std::make_unique<DepthNode>(getNodeHandle(), getPrivateNodeHandle());
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
