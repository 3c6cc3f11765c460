// Copyright wild_mvs authors. Incremental fusion of depth views that arrive
// from one or several depth workers, out of order and across stream
// sessions (ROS-free; the fusion node converts messages and calls it).
//
// Views are keyed by their stamp (ns). A ReorderBuffer holds them until
// they may be fused, in stamp order: the oldest waiting view goes when it
// is the next keyframe id of the current session, the first (id 0) of a new
// session, a late view of a session seen before, or when it waited
// `reorder_timeout`; a view that is not its keyframe's final revision
// (FusionView::final_revision) also waits for that revision while its depth
// node is still sending: until `revision_timeout` s passed without a view of
// its session (a final revision comes some keyframes later, however slowly
// they come), and only while no view of another session waits (a depth node
// that reset sends no more revisions) and the waiting views hold less than
// `map_store_mb` (beyond it the oldest goes as it is). A later revision of a
// waiting view replaces it; a revision of a view fused already is ignored
// (counted): the fusion is incremental and never takes a view out again.
//
// Sessions (StreamResult::session): the first view of a session not seen
// before starts it. on_new_session "keep" fuses it into the same cloud;
// "reset" first saves the cloud so far to <output_path stem>_session<N>.ply
// (when output_path is set, N = 0, 1, ...) and starts a new cloud; late
// views of an earlier session are then dropped (reported).
//
// The fused views' depth maps are kept for the consistency checks in a
// DepthMapStore (bounded memory, spilled to disk). Thread-safe.
#pragma once

#include <chrono>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <opencv2/core.hpp>
#include <set>
#include <string>
#include <vector>

#include "wild_mvs/core/depth_map.h"
#include "wild_mvs/core/fusion.h"
#include "wild_mvs/core/point_cloud.h"
#include "wild_mvs/stream/depth_map_store.h"

namespace wild_mvs {

// One depth view to fuse.
struct FusionView {
  DepthMap map;   // view index and neighbours are set by the session
  cv::Mat image;  // linear RGB at the map's size (may be empty)
  uint32_t keyframe_id = 0;
  uint64_t session_ns = 0;  // StreamResult::session_ns
  uint64_t stamp_ns = 0;    // the view's key
  std::vector<uint64_t> neighbor_stamps_ns;
  int revision = 0;                               // StreamResult::revision
  bool final_revision = true;                     // no later revision follows
  std::chrono::steady_clock::time_point arrived;  // for the timeouts
};

// The waiting views and the order state (which view comes next).
class ReorderBuffer {
 public:
  using Clock = std::chrono::steady_clock;
  // max_bytes: the waiting views' budget (map and image bytes).
  ReorderBuffer(double timeout, double revision_timeout, size_t max_bytes)
      : timeout_(timeout),
        revision_timeout_(revision_timeout),
        max_bytes_(max_bytes) {}

  bool Contains(uint64_t stamp_ns) const { return waiting_.count(stamp_ns); }
  // Adds a view (its stamp must not be waiting already).
  void Insert(FusionView view);
  // Replaces the waiting view of the same stamp when `view` is a later
  // revision (it keeps the first one's arrival time); false otherwise.
  bool Replace(FusionView view);
  // Takes the oldest waiting view when it may be fused at `now` (see the
  // file comment). The caller fuses it and reports it with Fused().
  bool PopReady(Clock::time_point now, FusionView* out);
  // Takes every waiting view, oldest first.
  std::vector<FusionView> PopAll();
  void Clear();
  size_t size() const { return waiting_.size(); }
  size_t bytes() const { return bytes_; }  // held by the waiting views

  // The fusing side's progress.
  void StartSession(uint64_t session);  // becomes current, expects id 0
  void Fused(uint64_t session, uint32_t keyframe_id);
  void RestartOrder() { last_fused_id_ = -1; }  // the cloud was cleared
  bool IsCurrent(uint64_t session) const {
    return static_cast<int64_t>(session) == current_session_;
  }
  bool Seen(uint64_t session) const { return seen_sessions_.count(session); }

 private:
  // Whether `v` (waiting) may still wait for its final revision at `now`.
  bool AwaitsRevision(const FusionView& v, Clock::time_point now) const;

  double timeout_;
  double revision_timeout_;
  size_t max_bytes_;
  std::map<uint64_t, FusionView> waiting_;  // by stamp (ns)
  size_t bytes_ = 0;
  // Each session's latest arrival (a view or a revision): its depth node
  // is still sending.
  std::map<uint64_t, Clock::time_point> last_arrival_;
  int64_t last_fused_id_ = -1;
  int64_t current_session_ = -1;
  std::set<uint64_t> seen_sessions_;  // every session fused so far
};

struct FusionSessionOptions {
  // A view waits at most this long (s, >= 0) for a missing earlier keyframe.
  double reorder_timeout = 2.0;
  // A view that is not its keyframe's final revision waits for it until
  // this long (s, >= 0) passed without a view of its session; 0 = never
  // waits.
  double revision_timeout = 30.0;
  // A new session: "keep" = fuse it into the same cloud; "reset" = save the
  // cloud so far (see output_path) and start a new one.
  std::string on_new_session = "keep";
  // Stem of the session saves <stem>_session<N>.ply; "" = none.
  std::string output_path;
  // Depth maps held in memory (MB, > 0): fused ones beyond it spill to
  // spill_dir; waiting ones beyond it are fused, oldest first.
  double map_store_mb = 256;
  std::string spill_dir;  // "" = a temporary folder, removed at the end
  FusionOptions fusion;
  void Check() const;
};

struct FusionSessionStats {
  size_t waiting = 0;  // views waiting for their turn
  uint64_t fused = 0;
  uint64_t revisions_replaced = 0;  // a waiting view's later revision
  uint64_t revisions_ignored = 0;   // revisions of views fused already
  uint64_t spilled = 0;             // depth maps written to the spill folder
  uint64_t resets = 0;              // Reset() calls and session resets
  uint64_t sessions = 0;
  uint64_t session_saves = 0;
  double held_mb = 0;  // depth maps held in memory, fused and waiting
  double last_fuse_seconds = 0;
  FusionStats fusion;
  size_t fusion_bytes = 0;
};

class FusionSession {
 public:
  // A dropped view or a failed spill: problem, detail.
  using DropCallback =
      std::function<void(const std::string&, const std::string&)>;
  // Messages about session saves: error?, message.
  using LogCallback = std::function<void(bool, const std::string&)>;

  // Throws Error on bad options or when the spill folder cannot be made.
  FusionSession(const FusionSessionOptions& options, DropCallback on_drop,
                LogCallback on_log = nullptr);

  // Adds a decoded view and fuses what is ready. False (counted) when a
  // view with its stamp was fused already, or is waiting with a revision
  // at least as late.
  bool Add(FusionView view);
  // Fuses the views that waited reorder_timeout (call periodically).
  void FuseReady();
  // Fuses every waiting view, ready or not, and returns the cloud (saves).
  PointCloud FlushAndCloud();
  // The cloud and the newest fused view's stamp when the cloud changed
  // since *version (or `force`); updates *version (start at 0). A snapshot
  // as of the last fused view: never waits for a view being fused.
  bool CloudIfChanged(uint64_t* version, bool force, PointCloud* cloud,
                      uint64_t* stamp_ns) const;
  // Forgets the cloud, the fused and the waiting views.
  void Reset();
  // As of the last change (never waits for a view being fused).
  FusionSessionStats Stats() const;

 private:
  void NewFusionLocked();
  void ClearLocked();
  void StartSessionLocked(uint64_t session);
  void FuseReadyLocked();
  void FuseLocked(FusionView view);

  const FusionSessionOptions options_;
  const DropCallback on_drop_;
  const LogCallback on_log_;
  // Refreshes the snapshots below (end of every change, under mutex_).
  void SnapshotLocked();
  mutable std::mutex mutex_;
  // What readers get without waiting for mutex_ (held while a view is
  // fused or a spilled map is read): the stats and the cloud as of the
  // last change. Lock order: mutex_, then snapshot_mutex_.
  mutable std::mutex snapshot_mutex_;
  FusionSessionStats stats_snapshot_;
  std::shared_ptr<const PointCloud> cloud_snapshot_;
  uint64_t snapshot_version_ = 0, snapshot_stamp_ns_ = 0;
  DepthMapStore store_;
  ReorderBuffer reorder_;
  std::unique_ptr<StreamingFusion> fusion_;
  std::map<uint64_t, int> view_of_stamp_;  // stamp (ns) -> view index
  int next_view_ = 0;
  uint64_t fused_ = 0, revisions_ignored_ = 0, resets_ = 0;
  uint64_t revisions_replaced_ = 0;
  uint64_t sessions_ = 0, session_saves_ = 0;
  uint64_t cloud_version_ = 0;
  uint64_t newest_stamp_ns_ = 0;  // newest view fused: the cloud's stamp
  double last_fuse_seconds_ = 0;
};

}  // namespace wild_mvs
