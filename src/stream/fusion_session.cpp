// Copyright wild_mvs authors.
#include "wild_mvs/stream/fusion_session.h"

#include <algorithm>
#include <cmath>
#include <exception>

#include "wild_mvs/core/error.h"
#include "wild_mvs/stream/cloud_file.h"

namespace wild_mvs {

namespace {

size_t ViewBytes(const FusionView& v) {
  return DepthMapStore::HeldBytes(v.map, v.image);
}

}  // namespace

void ReorderBuffer::Insert(FusionView view) {
  Clock::time_point& last = last_arrival_[view.session_ns];
  last = std::max(last, view.arrived);
  bytes_ += ViewBytes(view);
  const uint64_t key = view.stamp_ns;
  waiting_[key] = std::move(view);
}

bool ReorderBuffer::Replace(FusionView view) {
  auto it = waiting_.find(view.stamp_ns);
  if (it == waiting_.end() || view.revision <= it->second.revision)
    return false;
  Clock::time_point& last = last_arrival_[view.session_ns];
  last = std::max(last, view.arrived);
  view.arrived = it->second.arrived;
  bytes_ += ViewBytes(view);
  bytes_ -= ViewBytes(it->second);
  it->second = std::move(view);
  return true;
}

void ReorderBuffer::Clear() {
  waiting_.clear();
  bytes_ = 0;
}

bool ReorderBuffer::AwaitsRevision(const FusionView& v,
                                   Clock::time_point now) const {
  if (v.final_revision) return false;
  // A revision never comes once the depth node started another session
  // (its reset forgets the revisions to come).
  for (const auto& [key, w] : waiting_)
    if (w.session_ns != v.session_ns) return false;
  // Insert recorded v's session (and its arrival) before v could wait.
  const Clock::time_point since = last_arrival_.at(v.session_ns);
  return std::chrono::duration<double>(now - since).count() < revision_timeout_;
}

bool ReorderBuffer::PopReady(Clock::time_point now, FusionView* out) {
  if (waiting_.empty()) return false;
  auto it = waiting_.begin();
  const FusionView& v = it->second;
  const bool next =
      IsCurrent(v.session_ns)
          ? static_cast<int64_t>(v.keyframe_id) == last_fused_id_ + 1
          : (Seen(v.session_ns) || v.keyframe_id == 0);
  const double waited = std::chrono::duration<double>(now - v.arrived).count();
  // Over budget, the oldest goes whatever it waits for.
  if (bytes_ <= max_bytes_) {
    if (!next && waited < timeout_) return false;
    if (AwaitsRevision(v, now)) return false;
  }
  bytes_ -= ViewBytes(it->second);
  *out = std::move(it->second);
  waiting_.erase(it);
  return true;
}

std::vector<FusionView> ReorderBuffer::PopAll() {
  std::vector<FusionView> out;
  out.reserve(waiting_.size());
  for (auto& [key, view] : waiting_) out.push_back(std::move(view));
  Clear();
  return out;
}

void ReorderBuffer::StartSession(uint64_t session) {
  current_session_ = static_cast<int64_t>(session);
  seen_sessions_.insert(session);
  last_fused_id_ = -1;
}

void ReorderBuffer::Fused(uint64_t session, uint32_t keyframe_id) {
  if (IsCurrent(session)) last_fused_id_ = keyframe_id;
}

void FusionSessionOptions::Check() const {
  Require(std::isfinite(reorder_timeout) && reorder_timeout >= 0,
          "reorder_timeout = ", reorder_timeout, " must be >= 0");
  Require(std::isfinite(revision_timeout) && revision_timeout >= 0,
          "revision_timeout = ", revision_timeout, " must be >= 0");
  Require(on_new_session == "keep" || on_new_session == "reset",
          "on_new_session = '", on_new_session, "' must be 'keep' or 'reset'");
  Require(std::isfinite(map_store_mb) && map_store_mb > 0,
          "map_store_mb = ", map_store_mb, " must be > 0");
  fusion.Check();
}

FusionSession::FusionSession(const FusionSessionOptions& options,
                             DropCallback on_drop, LogCallback on_log)
    : options_((options.Check(), options)),
      on_drop_(std::move(on_drop)),
      on_log_(std::move(on_log)),
      store_(options.map_store_mb, options.spill_dir),
      reorder_(options.reorder_timeout, options.revision_timeout,
               static_cast<size_t>(options.map_store_mb * 1048576.0)) {
  NewFusionLocked();
  SnapshotLocked();
}

void FusionSession::NewFusionLocked() {
  fusion_ = std::make_unique<StreamingFusion>(
      options_.fusion, [this](int v) { return store_.Map(v); },
      [this](int v) { return store_.Image(v); });
}

bool FusionSession::Add(FusionView view) {
  std::lock_guard<std::mutex> lock(mutex_);
  const uint64_t key = view.stamp_ns;
  if (view_of_stamp_.count(key)) {
    ++revisions_ignored_;  // fused already: the fusion is incremental
    SnapshotLocked();
    return false;
  }
  if (reorder_.Contains(key)) {
    if (!reorder_.Replace(std::move(view))) {
      ++revisions_ignored_;
      SnapshotLocked();
      return false;
    }
    ++revisions_replaced_;
  } else {
    reorder_.Insert(std::move(view));
  }
  FuseReadyLocked();
  SnapshotLocked();
  return true;
}

void FusionSession::FuseReady() {
  std::lock_guard<std::mutex> lock(mutex_);
  FuseReadyLocked();
  SnapshotLocked();
}

void FusionSession::FuseReadyLocked() {
  const auto now = std::chrono::steady_clock::now();
  FusionView view;
  while (reorder_.PopReady(now, &view)) FuseLocked(std::move(view));
}

PointCloud FusionSession::FlushAndCloud() {
  std::lock_guard<std::mutex> lock(mutex_);
  // Views still waiting for an earlier keyframe are fused first.
  for (FusionView& view : reorder_.PopAll()) FuseLocked(std::move(view));
  SnapshotLocked();
  return fusion_->Cloud();
}

bool FusionSession::CloudIfChanged(uint64_t* version, bool force,
                                   PointCloud* cloud,
                                   uint64_t* stamp_ns) const {
  // From the snapshot: never waits for a view being fused.
  std::shared_ptr<const PointCloud> snap;
  {
    std::lock_guard<std::mutex> lock(snapshot_mutex_);
    if (!force && *version == snapshot_version_) return false;
    *version = snapshot_version_;
    *stamp_ns = snapshot_stamp_ns_;
    snap = cloud_snapshot_;
  }
  *cloud = snap ? *snap : PointCloud();
  return true;
}

void FusionSession::Reset() {
  std::lock_guard<std::mutex> lock(mutex_);
  ClearLocked();
  reorder_.Clear();
  ++resets_;
  SnapshotLocked();
}

void FusionSession::SnapshotLocked() {
  FusionSessionStats s;
  s.waiting = reorder_.size();
  s.fused = fused_;
  s.revisions_ignored = revisions_ignored_;
  s.revisions_replaced = revisions_replaced_;
  s.spilled = store_.spilled();
  s.resets = resets_;
  s.sessions = sessions_;
  s.session_saves = session_saves_;
  s.held_mb = (store_.bytes() + reorder_.bytes()) / 1048576.0;
  s.fusion = fusion_->stats();
  s.fusion_bytes = fusion_->bytes();
  s.last_fuse_seconds = last_fuse_seconds_;
  std::shared_ptr<const PointCloud> cloud;
  bool changed = false;
  {
    std::lock_guard<std::mutex> lock(snapshot_mutex_);
    changed = snapshot_version_ != cloud_version_;
  }
  // The copy is made outside the snapshot lock (readers never wait for it).
  if (changed) cloud = std::make_shared<const PointCloud>(fusion_->Cloud());
  std::lock_guard<std::mutex> lock(snapshot_mutex_);
  stats_snapshot_ = s;
  if (changed) {
    cloud_snapshot_ = std::move(cloud);
    snapshot_version_ = cloud_version_;
    snapshot_stamp_ns_ = newest_stamp_ns_;
  }
}

void FusionSession::ClearLocked() {
  NewFusionLocked();
  store_.Clear();
  view_of_stamp_.clear();
  newest_stamp_ns_ = 0;
  reorder_.RestartOrder();
  ++cloud_version_;
}

void FusionSession::StartSessionLocked(uint64_t session) {
  const bool had_views = !view_of_stamp_.empty();
  const uint64_t finished = sessions_ > 0 ? sessions_ - 1 : 0;  // its index
  ++sessions_;
  if (options_.on_new_session == "reset" && had_views) {
    if (!options_.output_path.empty()) {
      std::string stem = options_.output_path;
      if (stem.size() > 4 && stem.compare(stem.size() - 4, 4, ".ply") == 0)
        stem.resize(stem.size() - 4);
      const std::string path =
          stem + "_session" + std::to_string(finished) + ".ply";
      try {
        SaveCloudPly(path, fusion_->Cloud());
        ++session_saves_;
        if (on_log_)
          on_log_(false,
                  "new depth session: saved the previous cloud to " + path);
      } catch (const std::exception& e) {
        if (on_log_)
          on_log_(true, std::string("saving the previous session's cloud "
                                    "failed: ") +
                            e.what());
      }
    }
    ClearLocked();
    ++resets_;
  }
  reorder_.StartSession(session);
}

void FusionSession::FuseLocked(FusionView item) {
  if (!reorder_.IsCurrent(item.session_ns)) {
    if (!reorder_.Seen(item.session_ns)) {
      StartSessionLocked(item.session_ns);
    } else if (options_.on_new_session == "reset") {
      if (on_drop_)
        on_drop_("view of an earlier depth session after a cloud reset", "");
      return;
    }
  }
  const int v = next_view_++;
  view_of_stamp_[item.stamp_ns] = v;
  item.map.view = v;
  item.map.neighbors.clear();
  for (uint64_t s : item.neighbor_stamps_ns) {
    auto n = view_of_stamp_.find(s);
    if (n != view_of_stamp_.end()) item.map.neighbors.push_back(n->second);
  }
  reorder_.Fused(item.session_ns, item.keyframe_id);
  store_.Hold(v, std::move(item.map), std::move(item.image), on_drop_);
  const auto t0 = std::chrono::steady_clock::now();
  try {
    fusion_->AddView(v);
    ++fused_;
    ++cloud_version_;
    newest_stamp_ns_ = std::max(newest_stamp_ns_, item.stamp_ns);
  } catch (const std::exception& e) {
    if (on_drop_) on_drop_("fusion rejected the view", e.what());
  }
  last_fuse_seconds_ =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0)
          .count();
}

FusionSessionStats FusionSession::Stats() const {
  std::lock_guard<std::mutex> lock(snapshot_mutex_);
  return stats_snapshot_;
}

}  // namespace wild_mvs
