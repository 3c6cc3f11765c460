// Copyright wild_mvs authors. Multi-view stereo over a live stream of posed
// frames (ROS-free; the depth node is a thin shell around it).
//
// AddFrame() selects keyframes (baseline / viewing-angle thresholds), keeps
// them in a bounded KeyframeStore, grows the sparse tracks (the incremental
// tracker, or points given with SetSparsePoints), and schedules the
// reconstruction of every keyframe this worker owns
// (KeyframeOwner(stamp, worker_count) == worker_index) once it has enough
// good neighbours. With select_keyframes = false every frame given is a
// keyframe (a depth worker fed by a keyframe selector); with reconstruct =
// false nothing is reconstructed (the selector itself). Reconstructions run on
// an internal worker pool: AddFrame never waits for them. Results are handed
// to the result callback on a worker thread.
//
// Revisions: the offline pipeline's steps, live. A keyframe is matched as
// soon as it has enough neighbours, mostly earlier ones, and that map is
// delivered at once (revision 0). With the consistency step on
// (mvs.ablation.consistency, as offline) that first map is a preview at
// half the working size, and two revisions follow, same stamp, each a
// step of the offline pipeline. Revision 1, within `lookahead` keyframes:
// once the `lookahead` keyframes after it exist, every neighbour it was
// matched against is done (matched by this worker, owned by another,
// failed or evicted) and it has mvs.mpgc.min_active_views good
// neighbours, it is matched again at the working size over every
// keyframe held, so with neighbours on both sides, checked against the
// maps its neighbours have then (FilterByConsistency) and delivered.
// Revision 2, final: the offline filter (FilterByConsistency with
// mvs.consistency) on the maps offline would have, once its neighbours
// are matched again too; a keyframe whose revision 1 was matched while
// the store held fewer than mvs.global.num_neighbors other keyframes (a
// stream's start) is first matched again once it holds them. At the idle
// flush nothing is waited for. One revision step runs at a time, beside
// the first matches, on threads of background priority
// (ThreadPool::Priority): a first match never waits for a revision and
// takes the cores whenever it runs.
// Memory: the depth of every matched keyframe held (4 bytes per pixel), the
// first result of the keyframes not yet revised (both go with the keyframe
// when the store evicts it), and at most one first match and one revision
// step in progress.
//
// Thread-safe: AddFrame / Tick / SetSparsePoints / Reset / Stats may be
// called from any thread.
#pragma once

#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <set>
#include <string>
#include <vector>

#include "wild_mvs/core/depth_map.h"
#include "wild_mvs/core/error.h"
#include "wild_mvs/core/image.h"
#include "wild_mvs/core/option_registry.h"
#include "wild_mvs/core/reconstruct_view.h"
#include "wild_mvs/core/scene.h"
#include "wild_mvs/core/sparse_tracker.h"
#include "wild_mvs/core/thread_pool.h"
#include "wild_mvs/stream/keyframe_store.h"

namespace wild_mvs {

// A frame stamped more than this many seconds before the previous one
// resets the stream (a bag loop); smaller steps back are dropped.
constexpr double kStampResetSeconds = 1.0;
// A keyframe's first map is matched at half the working size when that is
// at least this many pixels (longest side) and a revision follows.
constexpr int kMinPreviewSize = 64;

struct StreamOptions {
  KeyframeSelectionOptions keyframes;
  KeyframeStoreOptions store;
  // Threads inside one reconstruction (image tiles). Reconstructions run one
  // at a time on a dispatcher thread, never on the caller's thread.
  int num_threads = 2;   // config/depth_node.yaml shows the same
  int max_pending = 2;   // reconstructions queued or running; more wait
  int worker_index = 0;  // this worker owns the keyframes with
  int worker_count = 1;  // KeyframeOwner(stamp, worker_count) == worker_index
  // Set by the depth node's role (not parameters of their own; they decide
  // which of the others are, RegisterOptions):
  bool select_keyframes = true;  // false: every frame is a keyframe
  bool reconstruct = true;       // false: select and track only
  // Good neighbours of a keyframe = the views the core's global view
  // selection (mvs.global) picks for it over the store with a positive
  // score (shared sparse points, parallax and resolution weights).
  // Good neighbours before a keyframe's first map, >= 1. With a revision to
  // follow (mvs.ablation.consistency) the first map is a preview and MPGC
  // asks it for no more active views than it has good neighbours (so a
  // stream's first keyframe is previewed as soon as a second one arrives).
  // A preview from fewer than mvs.mpgc.min_active_views neighbours (a
  // two-view match has no third view to reject a wrong depth) is held
  // until its neighbours' previews exist and is delivered checked against
  // them (FilterByConsistency: a left-right check for two views). Without
  // a revision to follow, or in a session that a pose jump started
  // (max_pose_jump: it may be a glitch that ends a frame later, its frames
  // consistent with each other but not with the world), or in a worker
  // (select_keyframes false: it follows sessions without their cause), a
  // keyframe waits for mvs.mpgc.min_active_views neighbours.
  int min_neighbors = 1;
  // A keyframe is matched as soon as it has min_neighbors good neighbours.
  // Its revision 1 waits for `lookahead` later keyframes (>= 0). The idle
  // flush (nothing waited for) comes when no keyframe arrived for
  // `idle_flush` s (wall time, >= 0) and for twice the interval between
  // the last two keyframes (the stream paused, not merely slowed down).
  int lookahead = 2;
  double idle_flush = 1.0;
  // Longest image side kept, pixels, 0 or >= 16 (input downscaled at
  // arrival); 0 = as received. Not a parameter of its own: the depth node
  // sets it from mvs.max_image_size (the working-size cap of the core).
  int max_image_size = 0;
  // A camera jump larger than this (metres) between consecutive frames less
  // than 1 s apart is a pose reset (tracking lost, relocalised): the stream
  // restarts (store and tracks cleared). 0 = no limit (never a reset).
  double max_pose_jump = 0.0;
  bool use_tracker = true;  // false: sparse points come from SetSparsePoints
  MvsOptions mvs;           // the core's per-view MVS options
  TrackerOptions tracker;   // the incremental tracker (use_tracker)
  void Check() const;
};
// Registers the fields under `prefix` (option_registry.h); the depth node
// uses prefix "" (num_threads, ..., mvs/..., tracker/...). max_image_size
// and the fields the node's role sets are not registered, and only the
// fields the role reads are: keyframe selection, pose jumps and the
// tracker with select_keyframes; scheduling, workers, matching and
// consistency with reconstruct; the store and mvs.max_image_size always. Of the
// core's options (mvs, its consistency, tracker) only kStreamCoreKeys are: the
// thresholds a robot's user tunes (the CLI's keys of the same name). The
// others (the wide-window thresholds, the one-view-occluder test, the
// bilateral weights, the consistency tolerances, the tracker's geometry
// and its feature image size, which mvs.max_image_size decides for a
// stream) keep the library defaults.
extern const char* const kStreamCoreKeys[12];
void RegisterOptions(OptionRegistry* registry, const std::string& prefix,
                     StreamOptions* options);

// One reconstructed keyframe.
struct StreamResult {
  uint32_t keyframe_id = 0;  // 0, 1, ... within the session
  // Stamp of the first frame of the stream session the keyframe belongs to.
  // A session starts with the first frame and again after every reset
  // (time or pose jump, Reset()); keyframe ids restart at 0. Depth maps
  // never use keyframes of another session. Workers fed the same stream
  // agree on sessions and ids; a restarted node starts a new session.
  double session = 0;
  double stamp = 0;
  // The same stamps, exact (ns since the epoch of the image header's
  // ros::Time): outputs carry these bit for bit, never the doubles.
  uint64_t session_ns = 0;
  uint64_t stamp_ns = 0;
  std::string frame_id;
  // 0 = first map; 1 = matched again with later keyframes, checked against
  // the neighbours' maps then held; 2 = final (see the file comment)
  int revision = 0;
  bool final_revision = true;  // no later revision of this keyframe follows
  std::vector<uint32_t> neighbor_ids;        // keyframe ids matched against
  std::vector<double> neighbor_stamps;       // and their stamps
  std::vector<uint64_t> neighbor_stamps_ns;  // exact (ns)
  cv::Mat image;                             // the keyframe image (linear RGB)
  DepthMap depth;                            // camera = keyframe camera at the
                                             // depth map's resolution
  double seconds = 0;                        // wall time of the reconstruction
};

struct StreamStats {
  size_t keyframes = 0;  // held in the store
  double store_mb = 0;
  uint64_t frames = 0;           // frames given to AddFrame
  uint64_t keyframes_total = 0;  // keyframes created
  int pending = 0;               // reconstructions queued or running
  int waiting = 0;               // ready keyframes waiting for a free slot
  uint64_t reconstructed = 0;    // depth maps matched (revision 0)
  uint64_t early_revised = 0;    // revisions 1 delivered
  uint64_t revised = 0;          // final revisions delivered (revision 2)
  int unrevised = 0;    // revision 0 delivered, the final to come (queued,
                        // running or waiting for the neighbours)
  uint64_t failed = 0;  // reconstructions that threw
  uint64_t evicted_waiting = 0;  // owned keyframes evicted before their
                                 // depth map (store too small for the rate)
  uint64_t stale_results = 0;    // results discarded after a Reset
  uint64_t out_of_order = 0;     // frames with non-increasing stamps
  uint64_t resets = 0;
  // Scheduling passes that evaluated the keyframes' neighbourhoods (a
  // snapshot of the store each): only when something changed.
  uint64_t scheduling_passes = 0;
  uint64_t cancelled = 0;  // depth maps stopped by Shutdown()
  int running = 0;         // depth maps being computed now
  double session = -1;     // stamp that started the current session (-1: none)
  size_t sparse_points = 0;
  // Memory of the online tracker (SparseTracker::bytes()): it keeps a few
  // bytes per feature of every keyframe ever added, also after eviction.
  double tracker_mb = 0;
  double last_seconds = 0, mean_seconds = 0;  // per depth map
};

class MemoryDepthWorkspace;  // pipeline/depth_workspace.h

class StreamReconstructor {
 public:
  using ResultCallback = std::function<void(const StreamResult&)>;
  using ErrorCallback = std::function<void(const std::string&)>;

  StreamReconstructor(const StreamOptions& options, ResultCallback on_result,
                      ErrorCallback on_error = nullptr);
  ~StreamReconstructor();  // Shutdown()
  // Stops for good: queued reconstructions are dropped and a running one is
  // cancelled (it stops within a few pixels per tile; nothing is
  // delivered); returns once it has. Stats() stays valid.
  void Shutdown();

  enum class FrameStatus {
    kKeyframe,     // kept as a keyframe
    kNotKeyframe,  // too close to the last keyframe
    kOutOfOrder,   // stamp not after the previous frame's: dropped
    kReset,        // pose or time jump: the stream restarted with it
    kDropped,      // a keyframe whose image the ImageFn could not make
  };
  // Makes a kept frame's image: sets *image (CV_32FC3 linear RGB of the
  // camera's size) and may change the camera's intrinsics (undistortion);
  // false drops the frame (the function reports why).
  using ImageFn = std::function<bool(Camera* camera, cv::Mat* image)>;
  // A new frame: camera (pose + intrinsics of `image`) and image (CV_32FC3
  // linear RGB of the camera's size). Call from one thread at a time (the
  // node's front end): the tracker runs here. A stamp more than
  // kStampResetSeconds before the previous one resets the stream (bag
  // loop, restarted clock); other stamps not after the previous one are
  // kOutOfOrder. Throws Error on an invalid camera or image.
  // `stamp_ns` is the image's exact stamp (ros::Time::toNSec()); the
  // results carry it unchanged.
  FrameStatus AddFrame(uint64_t stamp_ns, const std::string& frame_id,
                       const Camera& camera, const cv::Mat& image);
  // The same, deciding on the stamp and the pose first: `make_image` is
  // called (without a lock held) only for a frame kept as a keyframe, so
  // that the frames in between are never decoded or undistorted.
  // `pose_camera` needs only its pose for that decision.
  FrameStatus AddFrame(uint64_t stamp_ns, const std::string& frame_id,
                       const Camera& pose_camera, const ImageFn& make_image);
  // The same with a stamp in seconds (rounded to ns; tests and tools).
  FrameStatus AddFrame(double stamp, const std::string& frame_id,
                       const Camera& camera, const cv::Mat& image);
  // Live tuning: takes the keyframe selection (keyframes) and the MVS
  // options (mvs) of `options` (the other fields need a restart and are
  // ignored). Throws Error (Check()) and keeps the old ones when invalid.
  // Keyframes reconstructed from now on use them.
  void SetOptions(const StreamOptions& options);
  StreamOptions Options() const;
  // True when AddFrame would return kOutOfOrder for a frame with this stamp
  // (the node drops such frames before converting them).
  bool IsOutOfOrder(uint64_t stamp_ns) const;
  // Replaces the sparse points (use_tracker = false). Observations refer to
  // frames by stamp; stamps that are not keyframes are ignored.
  struct StampedObservation {
    double stamp;
    Eigen::Vector2d xy;  // core pixel convention; NaN = project
  };
  struct StampedPoint {
    Eigen::Vector3d xyz;
    std::vector<StampedObservation> observations;
  };
  void SetSparsePoints(const std::vector<StampedPoint>& points);
  // Call periodically: flushes keyframes waiting longer than idle_flush
  // (cheap when nothing changed: no snapshot, no view selection).
  void Tick();
  // Forgets every keyframe and track (results of running reconstructions
  // are discarded).
  void Reset();
  // Blocks until nothing is queued or running (tests, shutdown).
  void WaitIdle();
  StreamStats Stats() const;

  // Good-neighbour count of keyframe `id` (tests).
  int GoodNeighbors(uint32_t id) const;

  // The newest keyframe (a selector publishes it after AddFrame kept a
  // frame): false when the store is empty.
  struct KeyframeInfo {
    uint32_t id = 0;
    uint64_t session_ns = 0;  // see StreamResult::session
    uint64_t stamp_ns = 0;
  };
  bool Newest(KeyframeInfo* info) const;
  // The sparse points as stamped points (the tracker's, or those given
  // with SetSparsePoints; pixels in the received images' core convention),
  // restricted to the keyframes held: what a selector hands its workers
  // (SetSparsePoints).
  std::vector<StampedPoint> TrackedPoints() const;
  // Starts the session a keyframe selector announced (a worker follows
  // the selector's sessions, so that its results carry the selector's
  // session): when `session_ns` is not the current one, every keyframe and
  // track is forgotten as by Reset() and the session is `session_ns`.
  // Returns true when a new session started.
  bool FollowSession(uint64_t session_ns);
  // The id the next keyframe gets (a worker numbers its keyframes as the
  // selector did); ignored unless larger than every id given so far.
  void SetNextKeyframeId(uint32_t id);

 private:
  struct Neighborhood {
    int good = 0;
    double score = 0;
  };
  // The store as a Scene (view i = keyframes[i]) with the sparse points
  // remapped to it.
  struct Snapshot {
    std::vector<KeyframePtr> keyframes;
    Scene scene;
    std::vector<std::vector<int>> points_per_view;
  };
  Snapshot MakeSnapshotLocked() const;
  // The keyframe's neighbours as global view selection finds them. Its
  // frustum-overlap fallback (no shared sparse feature) counts only when
  // the scene has no sparse points or `idle` (no later keyframe to wait
  // for: the offline tool takes it at once).
  Neighborhood Evaluate(const Snapshot& snap, int index, bool idle) const;
  void ScheduleLocked();  // matching, then revisions
  void ScheduleMatchingLocked(bool idle);
  // `good`: the good neighbours the keyframe had when it was scheduled.
  void RunReconstruction(uint32_t id, uint64_t generation, int good);
  // Submits the revisions whose neighbours are done (see the file comment).
  void ScheduleRevisionsLocked(bool idle);
  // Delivers the held previews (held_) whose neighbours all have a map
  // or never will, each checked against those maps; `idle`: also those
  // whose missing neighbours are not queued for matching.
  void DeliverCheckedPreviews(uint64_t generation, bool idle);
  // At the idle flush: DeliverCheckedPreviews(idle) on the dispatcher.
  void FlushHeldPreviewsLocked();
  // A keyframe's revision steps, in order (see the file comment).
  enum class RevisionStep {
    kEarly,    // matched again, checked, delivered as revision 1
    kRematch,  // matched again over a full neighbourhood
    kFinal,    // checked against the neighbours' final maps: revision 2
  };
  // kEarly or kRematch; `idle`: scheduled by the idle flush.
  void RunRevisionMatch(uint32_t id, uint64_t generation, RevisionStep step,
                        bool idle);
  void RunRevisionFilter(uint32_t id, uint64_t generation);  // kFinal
  // Hands a revision to the result callback (unless it failed or a Reset
  // came meanwhile: counted), then schedules the next step.
  void DeliverRevision(uint64_t generation, const std::string& error,
                       const StreamResult& result);
  // The store holds as many other keyframes as the view selection picks.
  bool FullStoreLocked() const;
  // No keyframe for idle_flush s and for twice the last keyframe interval.
  bool IdleLocked() const;
  // Matches keyframe `ref` of `snap` (ReconstructView over the snapshot):
  // sets result->depth and its neighbours; returns the neighbour score.
  double MatchKeyframe(const Snapshot& snap, int ref, const MvsOptions& mvs,
                       ThreadPool* pool, StreamResult* result);
  // Puts the maps held (maps_) of `result`'s neighbours into `workspace`
  // (keyed by keyframe id, shared, not copied); returns how many.
  int NeighborMapsLocked(const StreamResult& result,
                         MemoryDepthWorkspace* workspace) const;
  void ForgetLocked(uint32_t id);           // a keyframe left the store
  void EndRevisionStepLocked(uint32_t id);  // then schedules the next
  void ClearLocked();

  StreamOptions options_;
  ResultCallback on_result_;
  ErrorCallback on_error_;
  mutable std::mutex mutex_;
  std::condition_variable idle_cv_;
  KeyframeStore store_;
  // Sparse points; Observation::view holds a keyframe id.
  std::vector<SparsePoint> points_;
  std::vector<StampedPoint> stamped_points_;  // SetSparsePoints
  bool stopping_ = false;
  std::unique_ptr<SparseTracker> tracker_;
  std::set<uint32_t> in_flight_;  // queued or running
  // Revisions: the depth (and camera) of the matched keyframes held, the
  // first results waiting for their revision, and revisions in flight.
  std::map<uint32_t, std::shared_ptr<const DepthMap>> maps_;
  std::map<uint32_t, StreamResult> unrevised_;
  // Held keyframes matched again over a full neighbourhood (or at the idle
  // flush), and those whose revision 1 went out, with the newest keyframe
  // id it was matched with.
  std::set<uint32_t> rematched_;
  std::map<uint32_t, uint32_t> early_newest_;
  // Previews from fewer than mvs.mpgc.min_active_views neighbours, waiting
  // for their neighbours' maps (DeliverCheckedPreviews).
  std::map<uint32_t, StreamResult> held_;
  std::set<uint32_t> previewing_;       // taken from held_, being delivered
  bool preview_flush_pending_ = false;  // FlushHeldPreviewsLocked queued
  std::set<uint32_t> revising_;
  int ready_waiting_ = 0;
  uint32_t next_id_ = 0;
  uint64_t generation_ = 0;
  bool idle_scheduled_ = false;
  std::atomic<bool> cancel_{false};    // set by Shutdown()
  bool shut_down_ = false;             // the idle
                                       // flush ran since the last keyframe
  double last_keyframe_wall_ = 0;      // steady clock, s
  double last_keyframe_interval_ = 0;  // s between the last two keyframes
  double last_stamp_ = -1;
  double session_ = -1;             // see StreamResult::session
  bool pose_jump_session_ = false;  // the current session began at a jump
  uint64_t session_ns_ = 0;
  bool have_last_center_ = false;
  Eigen::Vector3d last_center_{0, 0, 0};
  StreamStats stats_;
  double total_seconds_ = 0;
  // First matches: one at a time on the dispatcher, its tiles on the
  // inner pool. Revision steps: one at a time on the revision dispatcher
  // and pool, both of background priority, so that a first match never
  // waits for a revision and gets the cores whenever it runs.
  std::unique_ptr<ThreadPool> dispatcher_;
  std::unique_ptr<ThreadPool> inner_pool_;
  std::unique_ptr<ThreadPool> revision_dispatcher_;
  std::unique_ptr<ThreadPool> revision_pool_;
};

}  // namespace wild_mvs
