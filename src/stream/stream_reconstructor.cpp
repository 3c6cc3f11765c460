// Copyright wild_mvs authors.
#include "wild_mvs/stream/stream_reconstructor.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <opencv2/imgproc.hpp>
#include <optional>
#include <unordered_map>

#include "wild_mvs/core/global_view_selection.h"
#include "wild_mvs/pipeline/depth_controller.h"

namespace wild_mvs {

namespace {
double WallSeconds() {
  return std::chrono::duration<double>(
             std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

// Seconds for the stream's timing rules (the exact stamp is kept for the
// outputs).
double StampSeconds(uint64_t stamp_ns) {
  return static_cast<double>(stamp_ns / 1000000000ull) +
         static_cast<double>(stamp_ns % 1000000000ull) * 1e-9;
}

// What a neighbour's revision needs of a matched map: its depth and camera
// (the arrays are shared, not copied).
std::shared_ptr<const DepthMap> DepthOnly(const DepthMap& map) {
  auto d = std::make_shared<DepthMap>();
  d->view = map.view;
  d->camera = map.camera;
  d->depth = map.depth;
  return d;
}

// Filters `depth` against the `maps` neighbours' maps in `workspace`:
// consistent with as many of them as mvs.consistency asks for, or with all
// of them when fewer are held (none: nothing is confirmed). Returns the
// error, empty if none.
std::string CheckAgainstMaps(MvsOptions mvs,
                             const MemoryDepthWorkspace& workspace, int maps,
                             DepthMap* depth) {
  mvs.consistency.min_consistent =
      std::max(1, std::min(mvs.consistency.min_consistent, maps));
  try {
    *depth = DepthController(mvs, nullptr).Filter(*depth, workspace).map;
  } catch (const std::exception& e) {
    return e.what();
  }
  return "";
}
}  // namespace

void StreamOptions::Check() const {
  keyframes.Check();
  store.Check();
  Require(num_threads >= 1, "num_threads = ", num_threads, " must be >= 1");
  Require(max_pending >= 1, "max_pending = ", max_pending, " must be >= 1");
  Require(worker_count >= 1, "worker_count = ", worker_count, " must be >= 1");
  Require(worker_index >= 0 && worker_index < worker_count,
          "worker_index = ", worker_index,
          " must be in [0, worker_count = ", worker_count, ")");
  Require(min_neighbors >= 1, "min_neighbors = ", min_neighbors,
          " must be >= 1");
  Require(lookahead >= 0, "lookahead = ", lookahead, " must be >= 0");
  Require(std::isfinite(idle_flush) && idle_flush >= 0,
          "idle_flush = ", idle_flush, " must be >= 0 (seconds)");
  Require(max_image_size == 0 || max_image_size >= 16,
          "max_image_size = ", max_image_size, " must be 0 (off) or >= 16");
  Require(std::isfinite(max_pose_jump) && max_pose_jump >= 0,
          "max_pose_jump = ", max_pose_jump, " must be >= 0 (0 = off)");
  mvs.Check();
  if (use_tracker) tracker.Check();
}

StreamReconstructor::StreamReconstructor(const StreamOptions& options,
                                         ResultCallback on_result,
                                         ErrorCallback on_error)
    : options_(options),
      on_result_(std::move(on_result)),
      on_error_(std::move(on_error)),
      store_(options.store) {
  options_.Check();
  if (options_.use_tracker)
    tracker_ = std::make_unique<SparseTracker>(options_.tracker, nullptr);
  dispatcher_ = std::make_unique<ThreadPool>(1);
  if (options_.reconstruct) {  // a selector revises nothing
    revision_dispatcher_ =
        std::make_unique<ThreadPool>(1, ThreadPool::Priority::kBackground);
  }
  if (options_.reconstruct && options_.num_threads > 1) {
    inner_pool_ = std::make_unique<ThreadPool>(options_.num_threads - 1);
    revision_pool_ = std::make_unique<ThreadPool>(
        options_.num_threads - 1, ThreadPool::Priority::kBackground);
  }
  last_keyframe_wall_ = WallSeconds();
}

StreamReconstructor::~StreamReconstructor() { Shutdown(); }

void StreamReconstructor::Shutdown() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (shut_down_) return;
    shut_down_ = true;
    stopping_ = true;
    ++generation_;
  }
  // A running depth map stops within a few pixels per tile (a node shutting
  // down must end within roslaunch's SIGINT-to-SIGKILL escalation).
  cancel_ = true;
  // Queued tasks return at once; waits for a running one.
  dispatcher_.reset();
  revision_dispatcher_.reset();
  inner_pool_.reset();
  revision_pool_.reset();
}

void StreamReconstructor::ClearLocked() {
  store_.Clear();
  points_.clear();
  stamped_points_.clear();
  in_flight_.clear();
  maps_.clear();
  unrevised_.clear();
  held_.clear();
  previewing_.clear();
  rematched_.clear();
  early_newest_.clear();
  revising_.clear();
  last_keyframe_interval_ = 0;
  ++generation_;
  next_id_ = 0;  // ids restart in the new session
  session_ = -1;
  pose_jump_session_ = false;
  session_ns_ = 0;
  have_last_center_ = false;
  if (options_.use_tracker)
    tracker_ = std::make_unique<SparseTracker>(options_.tracker, nullptr);
  ++stats_.resets;
  idle_cv_.notify_all();
}

void StreamReconstructor::Reset() {
  std::lock_guard<std::mutex> lock(mutex_);
  ClearLocked();
  last_stamp_ = -1;
}

namespace {

// A frame's camera and its image (CV_32FC3 of the camera's size); throws
// Error naming the frame.
void CheckFrame(const std::string& frame_id, const Camera& camera,
                const cv::Mat& image) {
  camera.Validate("frame '" + frame_id + "'");
  Require(image.type() == CV_32FC3, "frame '", frame_id,
          "': image must be CV_32FC3");
  Require(image.cols == camera.width && image.rows == camera.height, "frame '",
          frame_id, "': image is ", image.cols, "x", image.rows,
          " but its camera is ", camera.width, "x", camera.height);
}

}  // namespace

StreamReconstructor::FrameStatus StreamReconstructor::AddFrame(
    double stamp, const std::string& frame_id, const Camera& camera,
    const cv::Mat& image) {
  Require(std::isfinite(stamp) && stamp >= 0, "frame '", frame_id, "': stamp ",
          stamp, " is not a finite time >= 0");
  return AddFrame(static_cast<uint64_t>(std::llround(stamp * 1e9)), frame_id,
                  camera, image);
}

StreamReconstructor::FrameStatus StreamReconstructor::AddFrame(
    uint64_t stamp_ns, const std::string& frame_id, const Camera& camera,
    const cv::Mat& image) {
  // Checked before any state changes (the ImageFn path can only check the
  // image once the frame is admitted).
  CheckFrame(frame_id, camera, image);
  return AddFrame(stamp_ns, frame_id, camera, [&image](Camera*, cv::Mat* out) {
    *out = image;
    return true;
  });
}

StreamReconstructor::FrameStatus StreamReconstructor::AddFrame(
    uint64_t stamp_ns, const std::string& frame_id, const Camera& pose_camera,
    const ImageFn& make_image) {
  const double stamp = StampSeconds(stamp_ns);
  pose_camera.Validate("frame '" + frame_id + "'");
  Require(std::isfinite(stamp), "frame '", frame_id, "': stamp is not finite");

  // 1. The stamp and the pose alone decide whether the frame is kept (no
  // pixel has been touched yet).
  FrameStatus status = FrameStatus::kKeyframe;
  uint64_t generation = 0;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    ++stats_.frames;
    if (last_stamp_ >= 0 && stamp <= last_stamp_) {
      if (last_stamp_ - stamp > kStampResetSeconds) {
        ClearLocked();
        status = FrameStatus::kReset;
      } else {
        ++stats_.out_of_order;
        return FrameStatus::kOutOfOrder;
      }
    }
    const Eigen::Vector3d center = pose_camera.Center();
    if (status != FrameStatus::kReset && have_last_center_ &&
        options_.max_pose_jump > 0 && stamp - last_stamp_ < 1.0 &&
        (center - last_center_).norm() > options_.max_pose_jump) {
      ClearLocked();
      pose_jump_session_ = true;
      status = FrameStatus::kReset;
    }
    last_stamp_ = stamp;
    last_center_ = center;
    have_last_center_ = true;
    if (session_ < 0) {
      session_ = stamp;
      session_ns_ = stamp_ns;
    }
    if (options_.select_keyframes &&
        !store_.IsNewKeyframe(pose_camera, options_.keyframes))
      return FrameStatus::kNotKeyframe;
    generation = generation_;
  }

  // 2. Only a keyframe's image is converted (outside the lock).
  Camera camera = pose_camera;
  cv::Mat image;
  if (!make_image(&camera, &image)) return FrameStatus::kDropped;
  CheckFrame(frame_id, camera, image);

  KeyframePtr kf;
  std::vector<KeyframePtr> evicted;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    // Reset() while the image was converted: the frame belongs to the
    // session that ended.
    if (generation != generation_) return FrameStatus::kNotKeyframe;
    kf = std::make_shared<Keyframe>();
    kf->id = next_id_++;
    kf->stamp = stamp;
    kf->stamp_ns = stamp_ns;
    kf->frame_id = frame_id;
    kf->camera = camera;
    kf->image = image;
    const int longest = std::max(camera.width, camera.height);
    if (options_.max_image_size > 0 && longest > options_.max_image_size) {
      const double f = double(options_.max_image_size) / longest;
      kf->camera = camera.Scaled(f);
      cv::resize(image, kf->image,
                 cv::Size(kf->camera.width, kf->camera.height), 0, 0,
                 cv::INTER_AREA);
      kf->image_scale = double(kf->camera.width) / camera.width;
    }
    kf->owned =
        options_.reconstruct &&
        KeyframeOwner(stamp_ns, options_.worker_count) == options_.worker_index;
    evicted = store_.Add(kf);
    for (const KeyframePtr& e : evicted) {
      if (!e->done() && !in_flight_.count(e->id)) ++stats_.evicted_waiting;
      ForgetLocked(e->id);
    }
    ++stats_.keyframes_total;
    const double now = WallSeconds();
    if (last_keyframe_wall_ > 0)
      last_keyframe_interval_ = now - last_keyframe_wall_;
    last_keyframe_wall_ = now;
    idle_scheduled_ = false;
  }

  if (tracker_) {
    // Only the front-end thread touches the tracker (see AddFrame).
    for (const KeyframePtr& e : evicted) tracker_->RemoveView(int(e->id));
    try {
      tracker_->AddView(int(kf->id), kf->camera, kf->image);
    } catch (const std::exception& e) {
      if (on_error_)
        on_error_(Msg("tracker: keyframe ", kf->id, ": ", e.what()));
    }
    std::vector<SparsePoint> pts = tracker_->Points();
    const double tracker_mb = tracker_->bytes() / (1024.0 * 1024.0);
    std::lock_guard<std::mutex> lock(mutex_);
    points_ = std::move(pts);
    stats_.tracker_mb = tracker_mb;
  }
  std::lock_guard<std::mutex> lock(mutex_);
  ScheduleLocked();
  return status;
}

void StreamReconstructor::SetOptions(const StreamOptions& options) {
  options.Check();
  std::lock_guard<std::mutex> lock(mutex_);
  options_.keyframes = options.keyframes;
  options_.mvs = options.mvs;
  // The new thresholds may make waiting keyframes ready.
  ScheduleLocked();
}

StreamOptions StreamReconstructor::Options() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return options_;
}

bool StreamReconstructor::IsOutOfOrder(uint64_t stamp_ns) const {
  const double stamp = StampSeconds(stamp_ns);
  std::lock_guard<std::mutex> lock(mutex_);
  return last_stamp_ >= 0 && stamp <= last_stamp_ &&
         last_stamp_ - stamp <= kStampResetSeconds;
}

void StreamReconstructor::SetSparsePoints(
    const std::vector<StampedPoint>& points) {
  std::lock_guard<std::mutex> lock(mutex_);
  stamped_points_ = points;
  ScheduleLocked();
}

StreamReconstructor::Snapshot StreamReconstructor::MakeSnapshotLocked() const {
  Snapshot snap;
  snap.keyframes = store_.All();
  std::unordered_map<uint32_t, int> index;
  std::vector<std::pair<double, int>> by_stamp;
  for (size_t i = 0; i < snap.keyframes.size(); ++i) {
    const KeyframePtr& k = snap.keyframes[i];
    View v;
    v.name = "keyframe_" + std::to_string(k->id);
    v.camera = k->camera;
    snap.scene.views.push_back(v);
    index[k->id] = static_cast<int>(i);
    by_stamp.emplace_back(k->stamp, static_cast<int>(i));
  }
  snap.scene.source = "keyframe store";
  for (const SparsePoint& p : points_) {
    SparsePoint q = p;
    q.track.clear();
    for (const Observation& o : p.track) {
      auto it = index.find(static_cast<uint32_t>(o.view));
      if (it == index.end()) continue;
      Observation r = o;
      r.view = it->second;
      q.track.push_back(r);
    }
    if (q.track.size() >= 2) snap.scene.points.push_back(std::move(q));
  }
  // Points given by stamp (sparse_points topic).
  std::sort(by_stamp.begin(), by_stamp.end());
  auto find_stamp = [&](double s) -> int {
    auto it = std::lower_bound(by_stamp.begin(), by_stamp.end(),
                               std::make_pair(s - 1e-4, -1));
    if (it != by_stamp.end() && std::abs(it->first - s) <= 1e-4)
      return it->second;
    return -1;
  };
  for (const StampedPoint& p : stamped_points_) {
    SparsePoint q;
    q.xyz = p.xyz;
    for (const StampedObservation& o : p.observations) {
      const int v = find_stamp(o.stamp);
      if (v < 0) continue;
      const KeyframePtr& k = snap.keyframes[v];
      Observation r;
      r.view = v;
      if (std::isfinite(o.xy.x()) && std::isfinite(o.xy.y())) {
        r.xy = o.xy * k->image_scale;
      } else if (!k->camera.Project(p.xyz, &r.xy)) {
        continue;
      }
      if (!k->camera.InImage(r.xy)) continue;
      q.track.push_back(r);
    }
    if (q.track.size() >= 2) snap.scene.points.push_back(std::move(q));
  }
  snap.points_per_view = snap.scene.PointsPerView();
  return snap;
}

StreamReconstructor::Neighborhood StreamReconstructor::Evaluate(
    const Snapshot& snap, int index, bool idle) const {
  Neighborhood nb;
  if (snap.scene.views.size() < 2) return nb;
  GlobalViewSelection sel = SelectGlobalViews(
      snap.scene, index, snap.points_per_view, options_.mvs.global);
  // Frustum-overlap fallbacks count when there are no sparse points at all
  // or the stream is idle; otherwise the keyframe waits for shared
  // features (a later keyframe may bring them).
  if (!sel.fallbacks.empty() && !snap.scene.points.empty() && !idle) return nb;
  for (double s : sel.scores) {
    if (s > 0) {
      ++nb.good;
      nb.score += s;
    }
  }
  return nb;
}

bool StreamReconstructor::IdleLocked() const {
  // The stream paused, not merely slowed down: no keyframe for idle_flush s
  // and for twice the interval between the last two.
  const double quiet = WallSeconds() - last_keyframe_wall_;
  return quiet >= options_.idle_flush && quiet >= 2 * last_keyframe_interval_;
}

void StreamReconstructor::ScheduleLocked() {
  ready_waiting_ = 0;
  const bool idle = IdleLocked();
  if (idle) idle_scheduled_ = true;
  ScheduleMatchingLocked(idle);
  if (idle) FlushHeldPreviewsLocked();
  ScheduleRevisionsLocked(idle);
}

void StreamReconstructor::FlushHeldPreviewsLocked() {
  if (stopping_ || held_.empty() || preview_flush_pending_) return;
  // On the dispatcher: after the first matches queued before it.
  preview_flush_pending_ = true;
  const uint64_t gen = generation_;
  dispatcher_->Submit([this, gen] {
    DeliverCheckedPreviews(gen, /*idle=*/true);
    std::lock_guard<std::mutex> lock(mutex_);
    preview_flush_pending_ = false;
    ScheduleLocked();
    idle_cv_.notify_all();
  });
}

void StreamReconstructor::ScheduleMatchingLocked(bool idle) {
  if (stopping_ || store_.size() < 2) return;
  // The snapshot (every keyframe and sparse point) only when some keyframe
  // could be scheduled.
  auto schedulable = [this](const KeyframePtr& kf) {
    if (!kf->owned || in_flight_.count(kf->id)) return false;
    return kf->reconstructions == 0;
  };
  const std::vector<KeyframePtr> all = store_.All();
  if (std::none_of(all.begin(), all.end(), schedulable)) return;
  ++stats_.scheduling_passes;
  const Snapshot snap = MakeSnapshotLocked();
  for (size_t i = 0; i < snap.keyframes.size(); ++i) {
    const KeyframePtr& kf = snap.keyframes[i];
    if (!kf->owned || in_flight_.count(kf->id)) continue;
    if (kf->reconstructions > 0) continue;
    const Neighborhood nb = Evaluate(snap, static_cast<int>(i), idle);
    // A final first map needs the active views MPGC asks for; a preview
    // asks for no more than it has (RunReconstruction), except in a session
    // a pose jump started, which may be a glitch that ends a frame later
    // (a worker fed by a selector does not know why a session began).
    const bool few_views_ok = options_.mvs.ablation.consistency &&
                              options_.select_keyframes && !pose_jump_session_;
    const int needed = few_views_ok
                           ? options_.min_neighbors
                           : std::max(options_.min_neighbors,
                                      options_.mvs.mpgc.min_active_views);
    if (nb.good < needed) continue;
    if (static_cast<int>(in_flight_.size()) >= options_.max_pending) {
      ++ready_waiting_;  // ready, waits for a free slot
      continue;
    }
    in_flight_.insert(kf->id);
    const uint32_t id = kf->id;
    const uint64_t gen = generation_;
    const int good = nb.good;
    dispatcher_->Submit(
        [this, id, gen, good] { RunReconstruction(id, gen, good); });
  }
}

void StreamReconstructor::ScheduleRevisionsLocked(bool idle) {
  // One revision step at a time, beside the first matches (a new
  // keyframe's map is what a robot waits for: the revisions' threads have
  // background priority).
  if (stopping_ || !revising_.empty()) return;
  // A neighbour is settled for a step when the store no longer holds it,
  // another worker owns it, its matching failed, or it reached that step:
  // matched (`rematched` false) or matched again over a full
  // neighbourhood (true).
  auto settled = [this](uint32_t n, bool rematched) {
    const KeyframePtr k = store_.Get(n);
    if (!k || !k->owned) return true;
    if (k->reconstructions > 0 && !maps_.count(n)) return true;  // failed
    return rematched ? rematched_.count(n) > 0
                     : k->done() && !in_flight_.count(n);
  };
  const KeyframePtr newest = store_.Newest();
  const uint32_t newest_id = newest ? newest->id : 0;
  // The oldest ready revision 1 first (what a robot waits for), else the
  // oldest ready step towards a final revision.
  bool chosen = false;
  uint32_t chosen_id = 0;
  RevisionStep chosen_step = RevisionStep::kFinal;
  // Whether keyframe `id` has as many good neighbours over the store as
  // MPGC asks for (a revision 1 from fewer would be worse than the
  // preview; the snapshot is made once, when first needed).
  std::optional<Snapshot> snap;
  auto enough_neighbors = [&](uint32_t id) {
    if (!snap) snap = MakeSnapshotLocked();
    for (size_t i = 0; i < snap->keyframes.size(); ++i)
      if (snap->keyframes[i]->id == id)
        return Evaluate(*snap, static_cast<int>(i), false).good >=
               options_.mvs.mpgc.min_active_views;
    return false;
  };
  for (const auto& [id, pending] : unrevised_) {
    // Not before its preview went out (revision 0 comes first).
    if (held_.count(id) || previewing_.count(id)) continue;
    const std::vector<uint32_t>& nbs = pending.neighbor_ids;
    const uint32_t rid = id;
    auto all_settled = [&](bool rematched) {
      return std::all_of(nbs.begin(), nbs.end(), [&](uint32_t n) {
        return n == rid || settled(n, rematched);
      });
    };
    auto early = early_newest_.find(id);
    // At the idle flush, a keyframe whose store is as at revision 1 has
    // nothing new to be matched against.
    if (idle && early != early_newest_.end() && early->second == newest_id)
      rematched_.insert(id);
    RevisionStep step;
    bool ready;
    if (early == early_newest_.end()) {
      // Revision 1: matched again once the `lookahead` keyframes after it
      // exist (neighbours on both sides), the neighbours of its first
      // match are matched and it has the neighbours MPGC asks for.
      step = RevisionStep::kEarly;
      ready = static_cast<int64_t>(newest_id) - static_cast<int64_t>(id) >=
                  options_.lookahead &&
              all_settled(false) && (idle || enough_neighbors(id));
    } else if (!rematched_.count(id)) {
      // Matched again over a full neighbourhood (revision 1 had fewer
      // keyframes to choose from: a stream's start).
      step = RevisionStep::kRematch;
      ready = FullStoreLocked() && all_settled(false);
    } else {
      // Revision 2, final: checked against its neighbours' maps once those
      // are matched again too (the maps the offline filter would see).
      step = RevisionStep::kFinal;
      ready = all_settled(true);
      // Even at the idle flush, never against a neighbour's map that is
      // still to be matched again.
      if (std::any_of(nbs.begin(), nbs.end(), [this, rid](uint32_t n) {
            return n != rid && unrevised_.count(n) && !rematched_.count(n);
          }))
        continue;
    }
    if (!ready && !idle) continue;
    if (chosen && step != RevisionStep::kEarly) continue;
    chosen = true;
    chosen_id = id;
    chosen_step = step;
    if (step == RevisionStep::kEarly) break;
  }
  if (!chosen) return;
  revising_.insert(chosen_id);
  const uint64_t gen = generation_;
  revision_dispatcher_->Submit(
      [this, id = chosen_id, gen, step = chosen_step, idle] {
        if (step == RevisionStep::kFinal) {
          RunRevisionFilter(id, gen);
        } else {
          RunRevisionMatch(id, gen, step, idle);
        }
      });
}

bool StreamReconstructor::FullStoreLocked() const {
  // A full neighbourhood, as offline: the store holds as many other
  // keyframes as the view selection picks.
  return static_cast<int>(store_.size()) >
         std::min(options_.mvs.global.num_neighbors,
                  options_.store.max_keyframes - 1);
}

int StreamReconstructor::NeighborMapsLocked(
    const StreamResult& result, MemoryDepthWorkspace* workspace) const {
  int held = 0;
  for (uint32_t n : result.neighbor_ids) {
    auto m = maps_.find(n);
    if (m == maps_.end() || n == result.keyframe_id) continue;
    workspace->Put(DepthWorkspace::Stage::kRaw, static_cast<int>(n), m->second);
    ++held;
  }
  return held;
}

void StreamReconstructor::EndRevisionStepLocked(uint32_t id) {
  // Out of revising_ and the next step scheduled under the same lock:
  // WaitIdle never sees a gap between two steps.
  revising_.erase(id);
  ScheduleLocked();
  idle_cv_.notify_all();
}

void StreamReconstructor::ForgetLocked(uint32_t id) {
  maps_.erase(id);
  early_newest_.erase(id);
  unrevised_.erase(id);
  held_.erase(id);
  rematched_.erase(id);
}

double StreamReconstructor::MatchKeyframe(const Snapshot& snap, int ref,
                                          const MvsOptions& mvs,
                                          ThreadPool* pool,
                                          StreamResult* result) {
  const std::vector<KeyframePtr>& kfs = snap.keyframes;
  ImageCache cache([&kfs](int v) { return kfs.at(v)->image; }, 512);
  ViewProblem problem;
  problem.scene = &snap.scene;
  problem.ref = ref;
  problem.images = &cache;
  problem.points_per_view = &snap.points_per_view;
  ViewResult matched = DepthController(mvs, pool, &cancel_).Match(problem);
  result->depth = std::move(matched.map);
  const ViewReport& report = matched.report;
  result->depth.view = static_cast<int>(kfs[ref]->id);
  result->depth.neighbors.clear();
  result->neighbor_ids.clear();
  result->neighbor_stamps.clear();
  result->neighbor_stamps_ns.clear();
  for (int n : report.neighbors) {
    if (n < 0 || n >= static_cast<int>(kfs.size())) continue;
    result->neighbor_ids.push_back(kfs[n]->id);
    result->neighbor_stamps.push_back(kfs[n]->stamp);
    result->neighbor_stamps_ns.push_back(kfs[n]->stamp_ns);
    result->depth.neighbors.push_back(static_cast<int>(kfs[n]->id));
  }
  double score = 0;
  for (double s : report.neighbor_scores) score += s;
  return score;
}

void StreamReconstructor::RunRevisionMatch(uint32_t id, uint64_t generation,
                                           RevisionStep step, bool idle) {
  StreamResult result;
  Snapshot snap;
  int ref = -1;
  MvsOptions mvs;
  bool full = false;
  uint32_t newest_id = 0;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    auto it = unrevised_.find(id);
    if (stopping_ || generation != generation_ || it == unrevised_.end()) {
      EndRevisionStepLocked(id);
      return;
    }
    result = it->second;
    snap = MakeSnapshotLocked();
    for (size_t i = 0; i < snap.keyframes.size(); ++i)
      if (snap.keyframes[i]->id == id) ref = static_cast<int>(i);
    if (const KeyframePtr newest = store_.Newest()) newest_id = newest->id;
    full = FullStoreLocked();
    mvs = options_.mvs;
    ++stats_.running;
  }
  // Matched again over every keyframe held: its neighbours on both sides
  // exist now (the offline view selection).
  std::string error;
  try {
    if (ref >= 0) MatchKeyframe(snap, ref, mvs, revision_pool_.get(), &result);
  } catch (const Cancelled&) {
    std::lock_guard<std::mutex> lock(mutex_);
    --stats_.running;
    ++stats_.cancelled;
    revising_.erase(id);
    idle_cv_.notify_all();
    return;  // shutting down
  } catch (const std::exception& e) {
    error = e.what();  // the first map stays; the filter still runs
  }
  if (!error.empty() && on_error_)
    on_error_(Msg("keyframe ", id, ": matching again failed: ", error));
  const bool matched = ref >= 0 && error.empty();
  MemoryDepthWorkspace workspace;
  int maps = 0;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    --stats_.running;
    auto it = unrevised_.find(id);
    if (generation != generation_ || it == unrevised_.end()) {
      EndRevisionStepLocked(id);
      return;
    }
    if (matched) {
      it->second = result;
      maps_[id] = DepthOnly(result.depth);
    }
    if (step == RevisionStep::kEarly) early_newest_[id] = newest_id;
    // Over a full neighbourhood this is the final match (so is any at the
    // idle flush, and a failed one: the map it has stays).
    if (full || idle || !matched) rematched_.insert(id);
    if (step != RevisionStep::kEarly || !matched) {
      EndRevisionStepLocked(id);
      return;
    }
    maps = NeighborMapsLocked(result, &workspace);
    mvs = options_.mvs;
  }
  // Revision 1: checked against the maps its neighbours have now (the
  // newest ones' first maps among them) and delivered at once.
  error = CheckAgainstMaps(mvs, workspace, maps, &result.depth);
  result.revision = 1;
  result.final_revision = false;
  DeliverRevision(generation, error, result);
}

void StreamReconstructor::DeliverRevision(uint64_t generation,
                                          const std::string& error,
                                          const StreamResult& result) {
  const uint32_t id = result.keyframe_id;
  bool deliver = false;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (result.final_revision) unrevised_.erase(id);
    if (generation != generation_) {
      ++stats_.stale_results;
    } else if (!error.empty()) {
      ++stats_.failed;
    } else {
      ++(result.final_revision ? stats_.revised : stats_.early_revised);
      deliver = true;
    }
  }
  if (!error.empty() && on_error_)
    on_error_(Msg("keyframe ", id, ": revision ", result.revision,
                  " failed: ", error));
  if (deliver && on_result_) on_result_(result);
  std::lock_guard<std::mutex> lock(mutex_);
  EndRevisionStepLocked(id);
}

void StreamReconstructor::RunRevisionFilter(uint32_t id, uint64_t generation) {
  StreamResult result;
  // The neighbours' maps the offline filter would see (keyed by keyframe
  // id, as the map's neighbours), shared, not copied.
  MemoryDepthWorkspace workspace;
  MvsOptions mvs;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    auto it = unrevised_.find(id);
    if (stopping_ || generation != generation_ || it == unrevised_.end()) {
      EndRevisionStepLocked(id);
      return;
    }
    result = it->second;
    NeighborMapsLocked(result, &workspace);
    mvs = options_.mvs;
  }
  const auto t0 = std::chrono::steady_clock::now();
  std::string error;
  try {
    result.depth =
        DepthController(mvs, nullptr).Filter(result.depth, workspace).map;
  } catch (const std::exception& e) {
    error = e.what();
  }
  result.revision = 2;
  result.final_revision = true;
  result.seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0)
          .count();
  DeliverRevision(generation, error, result);
}

void StreamReconstructor::Tick() {
  std::lock_guard<std::mutex> lock(mutex_);
  // Every event (keyframe, sparse points, finished map, reset) schedules at
  // once; the only thing time changes is the idle flush, done once per
  // quiet spell.
  const bool idle = IdleLocked();
  if (!idle || idle_scheduled_) return;
  ScheduleLocked();
  idle_scheduled_ = true;
}

void StreamReconstructor::RunReconstruction(uint32_t id, uint64_t generation,
                                            int good) {
  Snapshot snap;
  KeyframePtr kf;
  int ref = -1;
  double session = 0;
  uint64_t session_ns = 0;
  MvsOptions mvs;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (stopping_ || generation != generation_) {
      in_flight_.erase(id);
      idle_cv_.notify_all();
      return;
    }
    kf = store_.Get(id);
    if (!kf) {  // evicted while queued
      in_flight_.erase(id);
      ++stats_.evicted_waiting;
      idle_cv_.notify_all();
      return;
    }
    snap = MakeSnapshotLocked();
    for (size_t i = 0; i < snap.keyframes.size(); ++i)
      if (snap.keyframes[i]->id == id) ref = static_cast<int>(i);
    session = session_;
    session_ns = session_ns_;
    mvs = options_.mvs;  // SetOptions may change it meanwhile
    ++stats_.running;
  }
  const bool check_first =
      mvs.ablation.consistency && good < mvs.mpgc.min_active_views;
  // With a revision to follow, the first map is a preview at half the
  // working size (a quarter of the pixels) without the coarse fill (its
  // own half-size pass would delay it): out fast, replaced by the
  // full-size revision, which has it.
  if (mvs.ablation.consistency) {
    const int longest = std::max(kf->image.cols, kf->image.rows);
    const int working = mvs.max_image_size > 0
                            ? std::min(longest, mvs.max_image_size)
                            : longest;
    if (working / 2 >= kMinPreviewSize) {
      mvs.max_image_size = working / 2;
      mvs.ablation.coarse_fill = false;
    }
    // As many active views as it has neighbours: at a stream's start, a
    // two-view preview rather than none until a fourth keyframe arrives.
    mvs.mpgc.min_active_views =
        std::max(1, std::min(mvs.mpgc.min_active_views, good));
  }
  StreamResult result;
  result.keyframe_id = id;
  result.session = session;
  result.session_ns = session_ns;
  result.stamp = kf->stamp;
  result.stamp_ns = kf->stamp_ns;
  result.frame_id = kf->frame_id;
  result.image = kf->image;
  std::string error;
  double score = 0;
  const auto t0 = std::chrono::steady_clock::now();
  try {
    score = MatchKeyframe(snap, ref, mvs, inner_pool_.get(), &result);
  } catch (const Cancelled&) {
    std::lock_guard<std::mutex> lock(mutex_);
    --stats_.running;
    ++stats_.cancelled;
    in_flight_.erase(id);
    idle_cv_.notify_all();
    return;  // shutting down: nothing to deliver
  } catch (const std::exception& e) {
    error = e.what();
  }
  result.seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0)
          .count();
  bool deliver = false;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    --stats_.running;
    if (generation != generation_) {
      ++stats_.stale_results;
    } else if (!error.empty()) {
      ++stats_.failed;
      ++kf->reconstructions;  // do not retry in a loop
    } else {
      result.revision = 0;
      // With the consistency step a revision follows (ScheduleRevisions).
      result.final_revision = !mvs.ablation.consistency;
      if (!result.final_revision) {
        maps_[id] = DepthOnly(result.depth);
        unrevised_[id] = result;
      }
      ++kf->reconstructions;
      kf->neighbor_score = score;
      ++stats_.reconstructed;
      total_seconds_ += result.seconds;
      stats_.last_seconds = result.seconds;
      stats_.mean_seconds = total_seconds_ / stats_.reconstructed;
      if (check_first) {
        held_[id] = result;
      } else {
        deliver = true;
      }
    }
  }
  if (!error.empty() && on_error_)
    on_error_(Msg("keyframe ", id, ": reconstruction failed: ", error));
  if (deliver && on_result_) on_result_(result);
  // This map may be what held previews wait for. Still in in_flight_:
  // WaitIdle returns only after they are delivered.
  DeliverCheckedPreviews(generation, /*idle=*/false);
  std::lock_guard<std::mutex> lock(mutex_);
  in_flight_.erase(id);
  ScheduleLocked();
  idle_cv_.notify_all();
}

void StreamReconstructor::DeliverCheckedPreviews(uint64_t generation,
                                                 bool idle) {
  for (;;) {
    StreamResult result;
    MemoryDepthWorkspace workspace;
    MvsOptions mvs;
    int maps = 0;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      if (stopping_ || generation != generation_) return;
      // A neighbour is done when it has a map, or never will here (left
      // the store, owned by another worker, its matching failed; at the
      // idle flush also: not queued for matching).
      auto done = [this, idle](uint32_t n) {
        if (maps_.count(n)) return true;
        const KeyframePtr k = store_.Get(n);
        return !k || !k->owned || k->reconstructions > 0 ||
               (idle && !in_flight_.count(n));
      };
      auto it = std::find_if(held_.begin(), held_.end(), [&](const auto& h) {
        const std::vector<uint32_t>& n = h.second.neighbor_ids;
        return std::all_of(n.begin(), n.end(), done);
      });
      if (it == held_.end()) return;
      result = std::move(it->second);
      held_.erase(it);
      previewing_.insert(result.keyframe_id);
      maps = NeighborMapsLocked(result, &workspace);
      mvs = options_.mvs;
    }
    const std::string error =
        CheckAgainstMaps(mvs, workspace, maps, &result.depth);
    if (!error.empty()) {
      if (on_error_)
        on_error_(Msg("keyframe ", result.keyframe_id,
                      ": checking its preview failed: ", error));
    } else if (on_result_) {
      on_result_(result);
    }
    // Its revision may go now (ScheduleRevisionsLocked waits for this).
    std::lock_guard<std::mutex> lock(mutex_);
    previewing_.erase(result.keyframe_id);
  }
}

void StreamReconstructor::WaitIdle() {
  std::unique_lock<std::mutex> lock(mutex_);
  idle_cv_.wait(lock, [this] {
    return in_flight_.empty() && revising_.empty() && previewing_.empty() &&
           !preview_flush_pending_;
  });
}

StreamStats StreamReconstructor::Stats() const {
  std::lock_guard<std::mutex> lock(mutex_);
  StreamStats s = stats_;
  s.keyframes = store_.size();
  s.store_mb = store_.bytes() / (1024.0 * 1024.0);
  s.pending = static_cast<int>(in_flight_.size());
  s.unrevised = static_cast<int>(unrevised_.size());
  s.waiting = ready_waiting_;
  s.sparse_points = points_.size() + stamped_points_.size();
  s.session = session_;
  return s;
}

int StreamReconstructor::GoodNeighbors(uint32_t id) const {
  std::lock_guard<std::mutex> lock(mutex_);
  const Snapshot snap = MakeSnapshotLocked();
  for (size_t i = 0; i < snap.keyframes.size(); ++i)
    if (snap.keyframes[i]->id == id)
      return Evaluate(snap, static_cast<int>(i), false).good;
  return 0;
}

bool StreamReconstructor::Newest(KeyframeInfo* info) const {
  std::lock_guard<std::mutex> lock(mutex_);
  const KeyframePtr k = store_.Newest();
  if (!k) return false;
  info->id = k->id;
  info->session_ns = session_ns_;
  info->stamp_ns = k->stamp_ns;
  return true;
}

std::vector<StreamReconstructor::StampedPoint>
StreamReconstructor::TrackedPoints() const {
  std::lock_guard<std::mutex> lock(mutex_);
  std::unordered_map<uint32_t, KeyframePtr> held;
  for (const KeyframePtr& k : store_.All()) held[k->id] = k;
  std::vector<StampedPoint> out;
  for (const SparsePoint& p : points_) {
    StampedPoint q;
    q.xyz = p.xyz;
    for (const Observation& o : p.track) {
      auto it = held.find(static_cast<uint32_t>(o.view));
      if (it == held.end()) continue;
      // Keyframe pixels back to the received image's (MakeSnapshotLocked
      // scales them again).
      q.observations.push_back(
          {it->second->stamp, o.xy / it->second->image_scale});
    }
    if (q.observations.size() >= 2) out.push_back(std::move(q));
  }
  // Points given by stamp (SetSparsePoints), on the keyframes held.
  std::vector<double> stamps;
  for (const auto& [id, k] : held) stamps.push_back(k->stamp);
  std::sort(stamps.begin(), stamps.end());
  auto is_held = [&stamps](double s) {
    auto it = std::lower_bound(stamps.begin(), stamps.end(), s - 1e-4);
    return it != stamps.end() && std::abs(*it - s) <= 1e-4;
  };
  for (const StampedPoint& p : stamped_points_) {
    StampedPoint q;
    q.xyz = p.xyz;
    for (const StampedObservation& o : p.observations)
      if (is_held(o.stamp)) q.observations.push_back(o);
    if (q.observations.size() >= 2) out.push_back(std::move(q));
  }
  return out;
}

bool StreamReconstructor::FollowSession(uint64_t session_ns) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (session_ >= 0 && session_ns_ == session_ns) return false;
  if (session_ >= 0 || store_.size() > 0) ClearLocked();
  last_stamp_ = -1;
  session_ns_ = session_ns;
  session_ = StampSeconds(session_ns);
  return true;
}

void StreamReconstructor::SetNextKeyframeId(uint32_t id) {
  std::lock_guard<std::mutex> lock(mutex_);
  next_id_ = std::max(next_id_, id);
}

const char* const kStreamCoreKeys[] = {"mvs.max_image_size",
                                       "mvs.global.num_neighbors",
                                       "mvs.local.num_active",
                                       "mvs.local.min_ncc",
                                       "mvs.mpgc.window",
                                       "mvs.mpgc.drop_ncc",
                                       "mvs.mpgc.min_active_views",
                                       "mvs.growing.revisit_margin",
                                       "mvs.sweep.below_seeds",
                                       "consistency.min_consistent",
                                       "tracker.features.max_features",
                                       "tracker.min_track_length"};

void RegisterOptions(OptionRegistry* registry, const std::string& prefix,
                     StreamOptions* o) {
  auto key = [&prefix](const char* name) {
    return OptionRegistry::Join(prefix, name);
  };
  if (o->select_keyframes) {
    registry
        ->Add(key("max_pose_jump"), &o->max_pose_jump,
              "m between frames < 1 s apart that count as a pose reset, 0 = no "
              "limit (never a reset)")
        .Min(0);
    RegisterOptions(registry, prefix, &o->keyframes);
  }
  RegisterOptions(registry, prefix, &o->store);
  if (o->reconstruct) {
    registry
        ->Add(key("num_threads"), &o->num_threads,
              "threads inside one reconstruction")
        .Min(1);
    registry
        ->Add(key("max_pending"), &o->max_pending,
              "reconstructions queued or running")
        .Min(1);
    registry
        ->Add(key("min_neighbors"), &o->min_neighbors,
              "good neighbours (global view selection) before a keyframe's "
              "first map (a preview when a revision follows)")
        .Min(1);
    registry
        ->Add(key("lookahead"), &o->lookahead,
              "later keyframes a keyframe's revision 1 waits for (or the "
              "idle flush)")
        .Min(0);
    registry
        ->Add(key("idle_flush"), &o->idle_flush,
              "s without a new keyframe (and at least twice the last "
              "keyframe interval) after which waiting keyframes are matched "
              "and revised")
        .Min(0);
    registry
        ->Add(key("worker_index"), &o->worker_index,
              "several workers: this one reconstructs the keyframes whose "
              "stamp hashes to it (KeyframeOwner)")
        .Min(0)
        .Note("< worker_count");
    registry
        ->Add(key("worker_count"), &o->worker_count, "number of depth workers")
        .Min(1);
  }
  // use_tracker follows the node's sparse_source. Of the core's options
  // (the CLI's mvs.*, consistency.* and tracker.* keys) only those of
  // kStreamCoreKeys are offered; the others keep the library defaults.
  OptionRegistry core;
  RegisterOptions(&core, key("mvs"), &o->mvs);
  // The revisions' consistency step: the CLI's consistency.* keys.
  RegisterOptions(&core, key("consistency"), &o->mvs.consistency);
  RegisterOptions(&core, key("tracker"), &o->tracker);
  for (const char* k : kStreamCoreKeys) {
    const std::string name = k;
    const bool tracker = name.compare(0, 8, "tracker.") == 0;
    const bool size = name == "mvs.max_image_size";
    if (size || (tracker ? o->select_keyframes : o->reconstruct))
      registry->Add(*core.Find(key(k)));
  }
}

}  // namespace wild_mvs
