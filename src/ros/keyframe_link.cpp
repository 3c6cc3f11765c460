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
      history_size_(static_cast<size_t>(std::max(history, 1))) {
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
  msg->camera_pose.header.stamp = msg->header.stamp;
  msg->camera_pose.header.frame_id = world_frame_;
  msg->camera_pose.pose = PoseFromCamera(camera);
  msg->points = SparsePointsToMsg(points, world_frame_);
  msg->points.header.stamp = msg->header.stamp;
  std::lock_guard<std::mutex> lock(mutex_);
  // The history holds consecutive ids of one session.
  if (!history_.empty() &&
      (history_.back()->session != msg->session ||
       history_.back()->keyframe_id + 1 != msg->keyframe_id))
    history_.clear();
  history_.push_back(msg);
  while (history_.size() > history_size_) history_.pop_front();
  ++published_;
  keyframe_pub_.publish(wild_mvs::SelectedKeyframeConstPtr(msg));
  PublishIndexLocked();
}

void KeyframeAnnouncer::PublishIndex() {
  std::lock_guard<std::mutex> lock(mutex_);
  PublishIndexLocked();
}

void KeyframeAnnouncer::PublishIndexLocked() {
  if (history_.empty()) return;
  auto index = boost::make_shared<wild_mvs::KeyframeIndex>();
  index->header = history_.back()->header;
  index->session = history_.back()->session;
  index->first_id = history_.front()->keyframe_id;
  for (const wild_mvs::SelectedKeyframeConstPtr& k : history_)
    index->stamps.push_back(k->header.stamp);
  index_pub_.publish(wild_mvs::KeyframeIndexConstPtr(index));
}

bool KeyframeAnnouncer::OnGet(wild_mvs::GetKeyframe::Request& req,
                              wild_mvs::GetKeyframe::Response& res) {
  std::lock_guard<std::mutex> lock(mutex_);
  for (const wild_mvs::SelectedKeyframeConstPtr& k : history_) {
    if (k->session == req.session && k->keyframe_id == req.keyframe_id) {
      res.found = true;
      res.keyframe = *k;
      ++served_;
      return true;
    }
  }
  res.found = false;
  res.message =
      Msg("keyframe ", req.keyframe_id, " of session ", req.session.toNSec(),
          " is not among the selector's newest ", history_size_);
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
      repair_delay_(repair_delay),
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
  const uint64_t session = msg->session.toNSec();
  if (!have_session_ || session != session_ns_) {
    // The selector's first or next session: from the oldest keyframe of it
    // the index listed, else from its start.
    uint32_t first = 0;
    for (const auto& [key, t] : announced_)
      if (key.first == session) {
        first = key.second;
        break;
      }
    have_session_ = true;
    session_ns_ = session;
    next_id_ = std::min(first, msg->keyframe_id);
  }
  if (msg->keyframe_id < next_id_) {
    std::lock_guard<std::mutex> lock(stats_mutex_);
    ++stats_.repeated;  // fetched already
    return;
  }
  Fetch(session, msg->keyframe_id);
  Take(msg);
}

void KeyframeReceiver::OnIndex(const wild_mvs::KeyframeIndexConstPtr& msg) {
  if (msg->stamps.empty()) return;
  const uint64_t session = msg->session.toNSec();
  const uint32_t last =
      msg->first_id + static_cast<uint32_t>(msg->stamps.size()) - 1;
  const bool current = have_session_ && session == session_ns_;
  if (current && last < next_id_) return;  // nothing new
  // Keyframes of another session than the current one are remembered only
  // from the newest session announced (a bag loop or a selector reset).
  for (auto it = announced_.begin(); it != announced_.end();) {
    const bool stale = it->first.first != session &&
                       !(have_session_ && it->first.first == session_ns_);
    it = stale ? announced_.erase(it) : std::next(it);
  }
  const double now = SteadySeconds();
  const uint32_t from =
      current ? std::max(next_id_, msg->first_id) : msg->first_id;
  bool due = false;
  for (uint32_t id = from; id <= last; ++id) {
    const auto [it, fresh] =
        announced_.emplace(std::make_pair(session, id), now);
    if (!fresh && now - it->second >= repair_delay_) due = true;
  }
  if (!due) return;
  if (!current) {  // nothing of this session arrived in time
    have_session_ = true;
    session_ns_ = session;
    next_id_ = msg->first_id;
  }
  Fetch(session, last + 1);
}

void KeyframeReceiver::Take(const wild_mvs::SelectedKeyframeConstPtr& msg) {
  next_id_ = msg->keyframe_id + 1;
  for (auto it = announced_.begin(); it != announced_.end();) {
    const bool done =
        it->first.first == session_ns_ && it->first.second < next_id_;
    it = done ? announced_.erase(it) : std::next(it);
  }
  process_(msg);
}

void KeyframeReceiver::Fetch(uint64_t session_ns, uint32_t end) {
  for (uint32_t id = next_id_; id < end; ++id) {
    wild_mvs::GetKeyframe srv;
    srv.request.session.fromNSec(session_ns);
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
      next_id_ = id + 1;
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
