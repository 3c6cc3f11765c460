// Copyright wild_mvs authors.
#include "wild_mvs/ros/keyframe_link.h"

#include <boost/make_shared.hpp>
#include <chrono>

#include "wild_mvs/core/error.h"
#include "wild_mvs/ros/conversions.h"

namespace wild_mvs {
namespace ros1 {

namespace {
double SteadySeconds() {
  return std::chrono::duration<double>(
             std::chrono::steady_clock::now().time_since_epoch())
      .count();
}
}  // namespace

// --- the selector ----------------------------------------------------------

KeyframeAnnouncer::KeyframeAnnouncer(const ros::NodeHandle& private_nh,
                                     const std::string& world_frame,
                                     int history)
    : pnh_(private_nh),
      world_frame_(world_frame),
      history_(static_cast<size_t>(std::max(history, 1))) {
  keyframe_pub_ = pnh_.advertise<wild_mvs::SelectedKeyframe>("keyframes", 50);
  index_pub_ = pnh_.advertise<wild_mvs::KeyframeIndex>("keyframe_index", 10);
  get_srv_ =
      pnh_.advertiseService("get_keyframe", &KeyframeAnnouncer::OnGet, this);
}

wild_mvs::SparsePoints SparsePointsToMsg(
    const std::vector<StreamReconstructor::StampedPoint>& points,
    const std::string& world_frame) {
  wild_mvs::SparsePoints msg;
  msg.header.frame_id = world_frame;
  msg.points.reserve(points.size());
  for (const StreamReconstructor::StampedPoint& p : points) {
    wild_mvs::TrackedPoint t;
    t.position.x = p.xyz.x();
    t.position.y = p.xyz.y();
    t.position.z = p.xyz.z();
    for (const StreamReconstructor::StampedObservation& o : p.observations) {
      t.stamps.push_back(ros::Time(o.stamp));
      // Core pixels -> ROS pixel convention (-0.5).
      t.x.push_back(static_cast<float>(o.xy.x() - 0.5));
      t.y.push_back(static_cast<float>(o.xy.y() - 0.5));
    }
    msg.points.push_back(std::move(t));
  }
  return msg;
}

void KeyframeAnnouncer::Publish(
    const StreamReconstructor::KeyframeInfo& info, const DepthFrame& f,
    const Camera& camera,
    const std::vector<StreamReconstructor::StampedPoint>& points) {
  auto msg = boost::make_shared<wild_mvs::SelectedKeyframe>();
  msg->header.stamp.fromNSec(info.stamp_ns);
  msg->header.frame_id = f.frame_id;
  msg->keyframe_id = info.id;
  msg->session.fromNSec(info.session_ns);
  if (f.raw) msg->image = *f.raw;
  if (f.compressed) msg->compressed = *f.compressed;
  msg->camera_info = *f.info;
  msg->rectified = f.rectified;
  msg->camera_pose.header.stamp = msg->header.stamp;
  msg->camera_pose.header.frame_id = world_frame_;
  msg->camera_pose.pose = PoseFromCamera(camera);
  msg->points = SparsePointsToMsg(points, world_frame_);
  msg->points.header.stamp = msg->header.stamp;
  std::lock_guard<std::mutex> lock(mutex_);
  history_.Add(info.session_ns, info.id, msg);
  ++published_;
  keyframe_pub_.publish(wild_mvs::SelectedKeyframeConstPtr(msg));
  PublishIndexLocked();
}

void KeyframeAnnouncer::PublishIndex() {
  std::lock_guard<std::mutex> lock(mutex_);
  PublishIndexLocked();
}

void KeyframeAnnouncer::PublishIndexLocked() {
  const auto& held = history_.entries();
  if (held.empty()) return;
  auto index = boost::make_shared<wild_mvs::KeyframeIndex>();
  index->header = held.back().value->header;
  index->session = held.back().value->session;
  index->first_id = held.front().id;
  for (const auto& k : held) index->stamps.push_back(k.value->header.stamp);
  index_pub_.publish(wild_mvs::KeyframeIndexConstPtr(index));
}

bool KeyframeAnnouncer::OnGet(wild_mvs::GetKeyframe::Request& req,
                              wild_mvs::GetKeyframe::Response& res) {
  std::lock_guard<std::mutex> lock(mutex_);
  const wild_mvs::SelectedKeyframeConstPtr* k =
      history_.Find(req.session.toNSec(), req.keyframe_id);
  if (k) {
    res.found = true;
    res.keyframe = **k;
    ++served_;
    return true;
  }
  res.found = false;
  res.message =
      Msg("keyframe ", req.keyframe_id, " of session ", req.session.toNSec(),
          " is not among the selector's newest ", history_.capacity());
  return true;
}

uint64_t KeyframeAnnouncer::published() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return published_;
}

uint64_t KeyframeAnnouncer::served() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return served_;
}

// --- a worker --------------------------------------------------------------

KeyframeReceiver::KeyframeReceiver(const ros::NodeHandle& nh,
                                   double repair_delay, ProcessFn process,
                                   DropFn drop)
    : nh_(nh),
      sequencer_(repair_delay),
      process_(std::move(process)),
      drop_(std::move(drop)) {
  get_client_ = nh_.serviceClient<wild_mvs::GetKeyframe>("get_keyframe");
}

std::string KeyframeReceiver::keyframes_topic() const {
  return nh_.resolveName("keyframes");
}

KeyframeReceiver::Stats KeyframeReceiver::stats() const {
  std::lock_guard<std::mutex> lock(stats_mutex_);
  return stats_;
}

void KeyframeReceiver::OnKeyframe(
    const wild_mvs::SelectedKeyframeConstPtr& msg) {
  {
    std::lock_guard<std::mutex> lock(stats_mutex_);
    ++stats_.received;
  }
  if (!sequencer_.OnKeyframe(msg->session.toNSec(), msg->keyframe_id)) {
    std::lock_guard<std::mutex> lock(stats_mutex_);
    ++stats_.repeated;  // fetched already
    return;
  }
  Fetch(msg->keyframe_id);
  Take(msg);
}

void KeyframeReceiver::OnIndex(const wild_mvs::KeyframeIndexConstPtr& msg) {
  Fetch(sequencer_.OnIndex(msg->session.toNSec(), msg->first_id,
                           msg->stamps.size(), SteadySeconds()));
}

void KeyframeReceiver::Take(const wild_mvs::SelectedKeyframeConstPtr& msg) {
  sequencer_.Taken(msg->keyframe_id);
  process_(msg);
}

void KeyframeReceiver::Fetch(uint32_t end) {
  for (uint32_t id = sequencer_.next_id(); id < end; ++id) {
    wild_mvs::GetKeyframe srv;
    srv.request.session.fromNSec(sequencer_.session());
    srv.request.keyframe_id = id;
    const bool called = get_client_.call(srv);
    if (!called || !srv.response.found) {
      {
        std::lock_guard<std::mutex> lock(stats_mutex_);
        ++stats_.lost;
      }
      drop_(keyframes_topic(),
            "keyframe missed and not to be had from the selector",
            called ? srv.response.message
                   : Msg("keyframe ", id, ": service ",
                         get_client_.getService(), " did not answer"));
      sequencer_.Lost(id);
      continue;
    }
    {
      std::lock_guard<std::mutex> lock(stats_mutex_);
      ++stats_.fetched;
    }
    Take(boost::make_shared<const wild_mvs::SelectedKeyframe>(
        srv.response.keyframe));
  }
}

}  // namespace ros1
}  // namespace wild_mvs
