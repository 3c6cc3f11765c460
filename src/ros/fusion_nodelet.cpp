// Copyright wild_mvs authors.
#include "wild_mvs/ros/fusion_nodelet.h"

#include <diagnostic_updater/diagnostic_updater.h>
#include <nodelet/nodelet.h>
#include <ros/ros.h>
#include <sensor_msgs/PointCloud2.h>
#include <std_srvs/Trigger.h>
#include <unistd.h>
#include <visualization_msgs/Marker.h>
#include <wild_mvs/DepthView.h>
#include <wild_mvs/SaveCloud.h>

#include <chrono>
#include <condition_variable>
#include <cstdio>
#include <deque>
#include <filesystem>
#include <map>
#include <mutex>
#include <pluginlib/class_list_macros.hpp>
#include <set>
#include <thread>

#include "wild_mvs/core/error.h"
#include "wild_mvs/core/fusion.h"
#include "wild_mvs/io/depth_map_io.h"
#include "wild_mvs/ros/conversions.h"
#include "wild_mvs/ros/params_ros.h"
#include "wild_mvs/stream/cloud_file.h"
#include "wild_mvs/stream/drop_counter.h"
#if __has_include("wild_mvs/core/meshing.h")
#include "wild_mvs/core/meshing.h"
#define WILD_MVS_HAVE_MESHING 1
#endif

namespace wild_mvs {
namespace ros1 {

namespace fs = std::filesystem;

struct FusionNode::Impl {
  // A view waiting to be fused, and the maps of fused views.
  struct Item {
    DepthMap map;
    cv::Mat image;  // linear RGB at the map's size (may be empty)
    uint32_t keyframe_id = 0;
    uint64_t session = 0;  // DepthView.session (ns)
    std::vector<ros::Time> neighbor_stamps;
    ros::Time stamp;
    std::chrono::steady_clock::time_point arrived;
  };
  struct Held {
    std::shared_ptr<const DepthMap> map;  // null when spilled
    cv::Mat image;
    size_t bytes = 0;
  };

  ros::NodeHandle nh, pnh;
  FusionNodeOptions options;
  DropCounter drops;
  ros::Subscriber sub;
  ros::Publisher cloud_pub, mesh_pub;
  ros::ServiceServer save_srv, reset_srv;
  // Periodic work about machine time: steady timers, so that the cloud is
  // still published when /clock pauses or stops (sim time, bag ended).
  ros::SteadyTimer publish_timer, mesh_timer, diag_timer;
  std::unique_ptr<diagnostic_updater::Updater> updater;
  std::string spill_dir;
  bool own_spill_dir = false;

  // Input queue (callback -> fusion thread).
  std::mutex queue_mutex;
  std::condition_variable queue_cv;
  std::deque<wild_mvs::DepthViewConstPtr> queue;
  bool stop = false;
  uint64_t received = 0;
  std::thread worker;

  // Fusion state (fusion thread, services, timers).
  std::mutex fusion_mutex;
  std::unique_ptr<StreamingFusion> fusion;
  std::map<int, Held> held;    // fusion view index -> map
  std::deque<int> held_order;  // oldest first (in memory)
  size_t held_bytes = 0;
  std::map<uint64_t, int> view_of_stamp;  // stamp (ns) -> view index
  std::map<uint64_t, Item> waiting;       // reorder buffer by stamp (ns)
  int64_t last_fused_id = -1;
  int64_t current_session = -1;      // DepthView.session (ns) being fused
  std::set<uint64_t> seen_sessions;  // every session fused so far
  int next_view = 0;
  uint64_t fused = 0, revisions_ignored = 0, spilled = 0, resets = 0;
  uint64_t sessions = 0, session_saves = 0;
  uint64_t cloud_version = 0, published_version = 0, meshed_version = 0;
  // Stamp of the newest view fused into the cloud: the cloud's and mesh's
  // header stamp (data time, not the clock).
  ros::Time newest_stamp;
  double last_fuse_seconds = 0;

  std::string Topic() const { return nh.resolveName("depth_view"); }

  void Drop(const std::string& problem, const std::string& detail = "") {
    uint64_t n = 0;
    const std::string reason = Topic() + ": " + problem;
    if (drops.Count(reason, &n))
      ROS_ERROR("%s: dropped: %s%s%s (%lu so far; throttled)",
                pnh.getNamespace().c_str(), reason.c_str(),
                detail.empty() ? "" : ": ", detail.c_str(),
                static_cast<unsigned long>(n));
  }

  void NewFusion() {
    fusion = std::make_unique<StreamingFusion>(
        options.fusion, [this](int v) { return Provide(v); },
        [this](int v) {
          auto it = held.find(v);
          return it == held.end() ? cv::Mat() : it->second.image;
        });
  }

  std::string SpillStem(int v) const { return "view_" + std::to_string(v); }

  // Depth map of fused view v for the consistency checks (called by the
  // fusion under fusion_mutex): from memory, or read back from the spill
  // folder.
  std::shared_ptr<const DepthMap> Provide(int v) {
    auto it = held.find(v);
    Require(it != held.end(), "fusion node: unknown view ", v);
    if (it->second.map) return it->second.map;
    DepthMapFiles f = ReadDepthMapFiles(spill_dir, SpillStem(v));
    f.map.view = v;
    return std::make_shared<const DepthMap>(std::move(f.map));
  }

  void Hold(int v, DepthMap map, cv::Mat image) {
    Held h;
    h.bytes = map.depth.total() * 20 + image.total() * image.elemSize();
    h.image = std::move(image);
    h.map = std::make_shared<const DepthMap>(std::move(map));
    held_bytes += h.bytes;
    held[v] = std::move(h);
    held_order.push_back(v);
    const size_t bound = static_cast<size_t>(options.map_store_mb * 1048576.0);
    while (held_bytes > bound && held_order.size() > 1) {
      const int old = held_order.front();
      held_order.pop_front();
      Held& o = held[old];
      if (!o.map) continue;
      try {
        WriteDepthMapFiles(spill_dir, SpillStem(old), *o.map, {}, false);
        o.map.reset();
        o.image.release();
        held_bytes -= o.bytes;
        ++spilled;
      } catch (const std::exception& e) {
        Drop("cannot spill a depth map to " + spill_dir, e.what());
        break;
      }
    }
  }

  void OnView(const wild_mvs::DepthViewConstPtr& msg) {
    bool dropped = false;
    {
      std::lock_guard<std::mutex> lock(queue_mutex);
      ++received;
      if (static_cast<int>(queue.size()) >= options.input_queue_size) {
        queue.pop_front();
        dropped = true;
      }
      queue.push_back(msg);
    }
    queue_cv.notify_all();
    if (dropped)
      Drop("input queue full (views arrive faster than they are fused)");
  }

  // Decodes and validates a view; adds it to the reorder buffer.
  void Accept(const wild_mvs::DepthView& msg) {
    if (StripLeadingSlash(msg.camera_pose.header.frame_id) !=
        options.world_frame) {
      Drop("camera_pose frame '" + msg.camera_pose.header.frame_id +
           "' is not the world frame '" + options.world_frame + "'");
      return;
    }
    Item item;
    try {
      item.map = DepthMapFromDepthView(msg);
      if (!msg.image.data.empty()) {
        item.image = ImageToLinearRgb(msg.image, true);
        if (item.image.size() != item.map.depth.size()) item.image.release();
      }
    } catch (const Error& e) {
      Drop("invalid depth_view", e.what());
      return;
    }
    item.keyframe_id = msg.keyframe_id;
    item.session = msg.session.toNSec();
    item.neighbor_stamps = msg.neighbor_stamps;
    item.stamp = msg.header.stamp;
    item.arrived = std::chrono::steady_clock::now();
    std::lock_guard<std::mutex> lock(fusion_mutex);
    const uint64_t key = msg.header.stamp.toNSec();
    if (view_of_stamp.count(key) || waiting.count(key)) {
      ++revisions_ignored;  // fusion is incremental: first result stays
      return;
    }
    waiting[key] = std::move(item);
    FuseReadyLocked();
  }

  // Fuses waiting views in stamp order: the oldest goes when it is the next
  // keyframe id of the current session, the first (id 0) of a new session,
  // a late view of an earlier session, or waited reorder_timeout.
  void FuseReadyLocked() {
    const auto now = std::chrono::steady_clock::now();
    while (!waiting.empty()) {
      auto it = waiting.begin();
      Item& item = it->second;
      const int64_t session = static_cast<int64_t>(item.session);
      const bool next =
          session == current_session
              ? static_cast<int64_t>(item.keyframe_id) == last_fused_id + 1
              : (seen_sessions.count(item.session) || item.keyframe_id == 0);
      const double waited =
          std::chrono::duration<double>(now - item.arrived).count();
      if (!next && waited < options.reorder_timeout) break;
      FuseLocked(it->first, std::move(item));
      waiting.erase(it);
    }
  }

  // Forgets the cloud and every fused view (~reset, on_new_session reset).
  void ClearLocked() {
    NewFusion();
    held.clear();
    held_order.clear();
    held_bytes = 0;
    view_of_stamp.clear();
    newest_stamp = ros::Time();
    last_fused_id = -1;
    ++cloud_version;
  }

  // The session policy (FusionNodeOptions::on_new_session) when the first
  // view of a new depth-node session is fused.
  void StartSessionLocked(uint64_t session) {
    const bool had_views = !view_of_stamp.empty();
    const uint64_t finished = sessions > 0 ? sessions - 1 : 0;  // its index
    ++sessions;
    if (options.on_new_session == "reset" && had_views) {
      if (!options.output_path.empty()) {
        std::string stem = options.output_path;
        if (stem.size() > 4 && stem.compare(stem.size() - 4, 4, ".ply") == 0)
          stem.resize(stem.size() - 4);
        const std::string path =
            stem + "_session" + std::to_string(finished) + ".ply";
        try {
          SaveCloudPly(path, fusion->Cloud());
          ++session_saves;
          ROS_INFO("%s: new depth session: saved the previous cloud to %s",
                   pnh.getNamespace().c_str(), path.c_str());
        } catch (const std::exception& e) {
          ROS_ERROR("%s: saving the previous session's cloud failed: %s",
                    pnh.getNamespace().c_str(), e.what());
        }
      }
      ClearLocked();
      ++resets;
    }
    current_session = static_cast<int64_t>(session);
    seen_sessions.insert(session);
    last_fused_id = -1;
  }

  void FuseLocked(uint64_t key, Item item) {
    if (static_cast<int64_t>(item.session) != current_session) {
      if (!seen_sessions.count(item.session)) {
        StartSessionLocked(item.session);
      } else if (options.on_new_session == "reset") {
        Drop("view of an earlier depth session after a cloud reset");
        return;
      }
    }
    const int v = next_view++;
    const ros::Time stamp = item.stamp;
    view_of_stamp[key] = v;
    item.map.view = v;
    item.map.neighbors.clear();
    for (const ros::Time& s : item.neighbor_stamps) {
      auto n = view_of_stamp.find(s.toNSec());
      if (n != view_of_stamp.end()) item.map.neighbors.push_back(n->second);
    }
    if (static_cast<int64_t>(item.session) == current_session)
      last_fused_id = item.keyframe_id;
    Hold(v, std::move(item.map), std::move(item.image));
    const auto t0 = std::chrono::steady_clock::now();
    try {
      fusion->AddView(v);
      ++fused;
      ++cloud_version;
      newest_stamp = std::max(newest_stamp, stamp);
    } catch (const std::exception& e) {
      Drop("fusion rejected the view", e.what());
    }
    last_fuse_seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - t0)
            .count();
  }

  void Work() {
    for (;;) {
      wild_mvs::DepthViewConstPtr msg;
      {
        std::unique_lock<std::mutex> lock(queue_mutex);
        queue_cv.wait(lock, [this] { return stop || !queue.empty(); });
        if (stop) return;
        msg = queue.front();
        queue.pop_front();
      }
      try {
        Accept(*msg);
      } catch (const std::exception& e) {
        Drop("unexpected error", e.what());
      }
    }
  }

  void PublishCloud(bool force) {
    PointCloud cloud;
    ros::Time stamp;
    {
      std::lock_guard<std::mutex> lock(fusion_mutex);
      FuseReadyLocked();
      if (!force && published_version == cloud_version) return;
      published_version = cloud_version;
      cloud = fusion->Cloud();
      stamp = newest_stamp;
    }
    sensor_msgs::PointCloud2 msg =
        CloudToMsg(cloud, static_cast<size_t>(options.max_published_points));
    msg.header.stamp = stamp;
    msg.header.frame_id = options.world_frame;
    cloud_pub.publish(msg);
  }

  void PublishMesh() {
#ifdef WILD_MVS_HAVE_MESHING
    PointCloud cloud;
    ros::Time stamp;
    {
      std::lock_guard<std::mutex> lock(fusion_mutex);
      if (meshed_version == cloud_version) return;
      meshed_version = cloud_version;
      cloud = fusion->Cloud();
      stamp = newest_stamp;
    }
    if (cloud.size() < 100 || !cloud.has_normal()) return;
    try {
      MeshingOptions mo;
      mo.depth = 8;
      Mesh mesh = MeshPointCloud(cloud, mo);
      visualization_msgs::Marker m = MeshToMarker(mesh);
      m.header.stamp = stamp;
      m.header.frame_id = options.world_frame;
      m.ns = "wild_mvs";
      mesh_pub.publish(m);
    } catch (const std::exception& e) {
      ROS_WARN_THROTTLE(30, "%s: meshing failed: %s",
                        pnh.getNamespace().c_str(), e.what());
    }
#endif
  }

  size_t Save(const std::string& path) {
    PointCloud cloud;
    {
      std::lock_guard<std::mutex> lock(fusion_mutex);
      // Views still waiting for an earlier keyframe are fused first.
      for (auto& [key, item] : waiting) FuseLocked(key, std::move(item));
      waiting.clear();
      cloud = fusion->Cloud();
    }
    SaveCloudPly(path, cloud);
    return cloud.size();
  }

  bool OnSave(wild_mvs::SaveCloud::Request& req,
              wild_mvs::SaveCloud::Response& res) {
    const std::string path = req.path.empty() ? options.output_path : req.path;
    if (path.empty()) {
      res.success = false;
      res.message = "no path given and ~output_path is not set";
      return true;
    }
    try {
      res.num_points = Save(path);
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
    {
      std::lock_guard<std::mutex> lock(fusion_mutex);
      ClearLocked();
      waiting.clear();
      ++resets;
    }
    PublishCloud(true);
    res.success = true;
    res.message = "fused cloud cleared";
    return true;
  }

  void Diagnose(diagnostic_updater::DiagnosticStatusWrapper& stat) {
    size_t queued = 0;
    uint64_t recv = 0;
    {
      std::lock_guard<std::mutex> lock(queue_mutex);
      queued = queue.size();
      recv = received;
    }
    std::lock_guard<std::mutex> lock(fusion_mutex);
    const FusionStats& fs = fusion->stats();
    const uint64_t dropped = drops.Total();
    if (dropped > 0)
      stat.summaryf(diagnostic_msgs::DiagnosticStatus::WARN,
                    "%lu depth views dropped",
                    static_cast<unsigned long>(dropped));
    else
      stat.summary(diagnostic_msgs::DiagnosticStatus::OK, "running");
    stat.add("views received", recv);
    stat.add("input queue length", queued);
    stat.add("views waiting for order", waiting.size());
    stat.add("views fused", fused);
    stat.add("revisions ignored", revisions_ignored);
    stat.add("points", fs.points);
    stat.add("pending samples", fs.pending);
    stat.add("fusion bytes", fusion->bytes());
    stat.add("held depth map MB", held_bytes / 1048576.0);
    stat.add("depth maps spilled", spilled);
    stat.add("last seconds per view", last_fuse_seconds);
    stat.add("resets", resets);
    stat.add("depth sessions", sessions);
    stat.add("session clouds saved", session_saves);
    stat.add("views dropped", dropped);
    for (const auto& [reason, n] : drops.Counts())
      stat.add("dropped: " + reason, n);
  }
};

FusionNode::FusionNode(const ros::NodeHandle& nh, const ros::NodeHandle& pnh)
    : impl_(std::make_unique<Impl>()) {
  Impl& m = *impl_;
  m.nh = nh;
  m.pnh = pnh;
  RosParamSource params(pnh);
  m.options = ReadFusionNodeOptions(params);
  for (const std::string& n : UnknownFusionNodeParams(params))
    ROS_WARN(
        "%s: unknown parameter '%s' (ignored; see config/fusion_node.yaml)",
        pnh.getNamespace().c_str(), n.c_str());
  if (StripLeadingSlash(m.options.world_frame) != m.options.world_frame) {
    // tf2 frame ids have no leading '/'.
    const std::string w = StripLeadingSlash(m.options.world_frame);
    ROS_WARN("%s: world_frame '%s' starts with '/': using '%s'",
             pnh.getNamespace().c_str(), m.options.world_frame.c_str(),
             w.c_str());
    m.options.world_frame = w;
  }
  m.drops.set_throttle(m.options.error_throttle);
  const FusionNodeOptions& o = m.options;
  if (o.spill_dir.empty()) {
    std::string tmpl =
        (fs::temp_directory_path() / "wild_mvs_fusion_XXXXXX").string();
    Require(mkdtemp(tmpl.data()) != nullptr,
            "fusion node: cannot create a temporary folder for spilled maps");
    m.spill_dir = tmpl;
    m.own_spill_dir = true;
  } else {
    m.spill_dir = o.spill_dir;
    fs::create_directories(m.spill_dir);
  }
  m.NewFusion();
  m.cloud_pub = m.pnh.advertise<sensor_msgs::PointCloud2>("cloud", 1, true);
  if (o.mesh_period > 0)
    m.mesh_pub = m.pnh.advertise<visualization_msgs::Marker>("mesh", 1, true);
  m.save_srv = m.pnh.advertiseService("save", &Impl::OnSave, &m);
  m.reset_srv = m.pnh.advertiseService("reset", &Impl::OnReset, &m);
  m.sub = m.nh.subscribe("depth_view", o.input_queue_size, &Impl::OnView, &m);
  m.publish_timer = m.nh.createSteadyTimer(
      ros::WallDuration(o.publish_period),
      [&m](const ros::SteadyTimerEvent&) { m.PublishCloud(false); });
  if (o.mesh_period > 0)
    m.mesh_timer = m.nh.createSteadyTimer(
        ros::WallDuration(o.mesh_period),
        [&m](const ros::SteadyTimerEvent&) { m.PublishMesh(); });
  m.updater = std::make_unique<diagnostic_updater::Updater>(
      m.nh, m.pnh, m.pnh.getNamespace());
  m.updater->setHardwareID("wild_mvs_fusion");
  m.updater->add("fusion_node", &m, &Impl::Diagnose);
  m.diag_timer = m.nh.createSteadyTimer(
      ros::WallDuration(o.diagnostics_period),
      [&m](const ros::SteadyTimerEvent&) { m.updater->force_update(); });
  m.worker = std::thread([&m] { m.Work(); });
}

size_t FusionNode::Save(const std::string& path) { return impl_->Save(path); }

FusionNode::~FusionNode() {
  Impl& m = *impl_;
  m.sub.shutdown();
  m.publish_timer.stop();
  m.mesh_timer.stop();
  m.diag_timer.stop();
  // Views already queued are fused before the final save.
  {
    std::unique_lock<std::mutex> lock(m.queue_mutex);
    m.stop = true;
  }
  m.queue_cv.notify_all();
  if (m.worker.joinable()) m.worker.join();
  for (const auto& msg : m.queue) {
    try {
      m.Accept(*msg);
    } catch (const std::exception&) {
    }
  }
  if (!m.options.output_path.empty()) {
    try {
      const size_t n = m.Save(m.options.output_path);
      ROS_INFO("%s: saved %zu points to %s on shutdown",
               m.pnh.getNamespace().c_str(), n, m.options.output_path.c_str());
      std::fprintf(stderr, "fusion node: saved %zu points to %s\n", n,
                   m.options.output_path.c_str());
    } catch (const std::exception& e) {
      ROS_ERROR("%s: saving on shutdown failed: %s",
                m.pnh.getNamespace().c_str(), e.what());
      std::fprintf(stderr, "fusion node: saving on shutdown failed: %s\n",
                   e.what());
    }
  }
  if (m.own_spill_dir) {
    std::error_code ec;
    fs::remove_all(m.spill_dir, ec);
  }
}

class FusionNodelet : public nodelet::Nodelet {
 private:
  void onInit() override {
    try {
      node_ =
          std::make_unique<FusionNode>(getNodeHandle(), getPrivateNodeHandle());
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
