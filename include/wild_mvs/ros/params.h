// Copyright wild_mvs authors. ROS parameters become option structs by
// walking the option registry (core/option_registry.h): the key
// mvs.mpgc.drop_ncc of the command line and config/reconstruct.yaml is the
// private parameter ~mvs/mpgc/drop_ncc, so a tuned reconstruct.yaml section
// (mvs:, tracker:, fusion:) loads into a node's namespace unchanged.
//
// Parameters are private (~name). Every value is type-checked here and
// range-checked by the options' Check(): a bad value throws wild_mvs::Error
// naming the parameter and the value, so a node refuses to start with a
// clear message instead of running with a wrong setting. Unknown private
// parameters are reported as warnings (Unknown*Params) since launch files
// may carry extra keys. config/depth_node.yaml and config/fusion_node.yaml
// list every parameter with its default and range; they are written by
// wild_mvs_write_config from the same registry (a test keeps them equal).
//
// The reading goes through ParamSource so the mapping is unit-tested without
// a ROS master (MapParamSource); RosParamSource (params_ros.h) reads a
// ros::NodeHandle.
#pragma once

#include <Eigen/Geometry>
#include <map>
#include <string>
#include <variant>
#include <vector>

#include "wild_mvs/core/fusion.h"
#include "wild_mvs/core/meshing.h"
#include "wild_mvs/core/option_registry.h"
#include "wild_mvs/stream/fusion_session.h"
#include "wild_mvs/stream/keyframe_ledger.h"
#include "wild_mvs/stream/stream_reconstructor.h"

namespace wild_mvs {
namespace ros1 {

// A parameter lookup.
class ParamSource {
 public:
  using Value = std::variant<bool, int, double, std::string>;
  virtual ~ParamSource() = default;
  // The value of private parameter `name` ("mvs/mpgc/drop_ncc"), or false
  // when it is unset.
  virtual bool Lookup(const std::string& name, Value* value) const = 0;
  // Names (without the private prefix) of every private parameter that is
  // set, for the unknown-key check.
  virtual std::vector<std::string> Names() const = 0;
  // Where the parameters come from, for messages ("/depth_node").
  virtual std::string Where() const = 0;
};

// In-memory parameters (tests, tools).
class MapParamSource : public ParamSource {
 public:
  explicit MapParamSource(std::map<std::string, Value> values = {})
      : values_(std::move(values)) {}
  void Set(const std::string& name, Value v) { values_[name] = std::move(v); }
  bool Lookup(const std::string& name, Value* value) const override;
  std::vector<std::string> Names() const override;
  std::string Where() const override { return "parameters"; }

 private:
  std::map<std::string, Value> values_;
};

// The parameter name of a registry key: "mvs.mpgc.drop_ncc" ->
// "mvs/mpgc/drop_ncc".
std::string ParamName(const std::string& key);
// Sets every registered option whose parameter is set; throws Error naming
// "<where>/<param>" when a value's type does not fit (an int is accepted for
// a double, an integral double for an int). Ranges are left to Check().
void ReadParams(const ParamSource& params, OptionRegistry* registry);
// Set parameters that name no registered option (typos), e.g.
// "keyframe_min_angel".
std::vector<std::string> UnknownParams(const ParamSource& params,
                                       const OptionRegistry& registry);

// The depth node's fixed input settings: roscpp queues of the pose, image,
// camera_info and `keyframes` subscriptions (their overflows are counted,
// from roscpp's bus statistics); a topic pose this close (s) to the image
// stamp is used as is when no two poses around the stamp can be
// interpolated; poses are interpolated only between poses at most
// kPoseMaxGap s apart; a selector keeps the newest kKeyframeHistory
// keyframes for ~get_keyframe.
constexpr int kPoseQueueSize = 100;
constexpr int kImageQueueSize = 5;
constexpr int kCameraInfoQueueSize = 20;
constexpr int kKeyframeQueueSize = 50;
constexpr double kPoseSyncTolerance = 0.01;
constexpr double kPoseMaxGap = 0.2;
constexpr int kKeyframeHistory = 40;
// The depth node's fixed housekeeping: seconds between repeated ROS_ERRORs
// about the same kind of problem; seconds of drops that keep diagnostics
// WARN (the counts are totals); seconds a worker waits for a keyframe the
// index announced before fetching it from `get_keyframe`.
constexpr double kErrorThrottle = 5.0;
constexpr double kDropWindow = 60.0;
constexpr double kRepairDelay = 1.0;

// The parts a depth node plays; each is a nodelet (and a node executable)
// of its own:
//   kStandalone (wild_mvs/DepthNodelet, depth_node): selects keyframes from
//   `image` and reconstructs the ones it owns (KeyframeOwner of
//   worker_index / worker_count; all of them with the default count 1);
//   kSelector (wild_mvs/KeyframeSelectorNodelet, keyframe_selector_node):
//   selects keyframes from `image` and tracks them, then publishes each
//   keyframe with its pose and the sparse tracks on ~keyframes (and
//   ~keyframe_index, ~get_keyframe); reconstructs none;
//   kWorker (wild_mvs/DepthWorkerNodelet, depth_worker_node): takes every
//   keyframe from a selector's `keyframes` topic and reconstructs the ones
//   it owns. A gap in the keyframe ids, or a keyframe `keyframe_index`
//   announced that has not arrived after kRepairDelay, is fetched from the
//   selector's `get_keyframe`.
enum class DepthRole { kStandalone, kSelector, kWorker };
// "standalone", "selector", "worker" (diagnostics, messages).
const char* RoleName(DepthRole role);
// The file in config/ that lists the role's parameters with their
// defaults: depth_node.yaml, keyframe_selector.yaml, depth_worker.yaml.
const char* ConfigFileName(DepthRole role);
// The camera input (image, camera_info, pose, sparse points): standalone
// and selector. Reconstruction (depth maps out): standalone and worker.
inline bool ReadsCamera(DepthRole r) { return r != DepthRole::kWorker; }
inline bool Reconstructs(DepthRole r) { return r != DepthRole::kSelector; }

// Options of the depth node (its ROS-side settings plus the stream
// reconstructor's and the core's options).
struct DepthNodeOptions {
  std::string world_frame = "world";  // fixed frame of the poses (REP 105)
  // Where the camera's pose comes from:
  //   "tf": tf2 lookup world_frame <- image frame_id at the image stamp;
  //   on the `pose` topic, in world_frame: "pose" (geometry_msgs/
  //   PoseStamped; "topic" is the same), "pose_with_covariance"
  //   (PoseWithCovarianceStamped), "transform" (TransformStamped) or
  //   "odometry" (nav_msgs/Odometry). Topic poses are interpolated at the
  //   image stamp (slerp + lerp between the poses around it).
  std::string pose_source = "tf";
  double tf_timeout = 0.2;  // s to wait for tf / a pose, [0, 60]
  // The frame the topic's poses are of: "" = the camera optical frame for
  // pose / pose_with_covariance, the messages' child_frame_id for
  // transform / odometry. When it is not the camera frame (a robot body),
  // T_world_camera = T_world_body * T_body_camera with the extrinsic below.
  std::string pose_frame;
  // T_body_camera as "x y z qx qy qz qw" (the camera optical frame in the
  // body frame); "" = looked up in tf (/tf_static) body <- camera frame.
  std::string camera_extrinsic;
  // Camera optical frame of the images; "" = the image header's frame_id.
  // Set it when a driver stamps images with another frame (e.g. a body or
  // link frame); tf must give world_frame <- camera_frame.
  std::string camera_frame;
  // image_transport plugin for `image`: "raw", or any installed plugin
  // ("theora", ...). "compressed" (`image/compressed`) is decoded here with
  // cv::imdecode when the compressed plugin is not installed.
  std::string image_transport = "raw";
  // camera_info is paired with the image of the same stamp (image_transport
  // CameraSubscriber convention: `camera_info` beside the image topic).
  // true: use the latest camera_info instead, for drivers that publish it
  // once or at another rate.
  bool camera_info_latest = false;
  // The images are rectified: the camera is P's, D is ignored (never
  // undistorted twice). Also on when the image topic ends in image_rect or
  // image_rect_color.
  bool rectified = false;
  // ~depth/image_rect encoding: "32FC1" (metres, NaN = unknown, REP 118) or
  // "16UC1" (millimetres, 0 = unknown).
  std::string depth_encoding = "32FC1";
  // "tracker": sparse tracks built online; "topic": wild_mvs/SparsePoints on
  // `sparse_points`.
  // "none": no sparse points (frustum-overlap neighbours, sweep seeds).
  std::string sparse_source = "tracker";
  int input_queue_size = 5;  // frames waiting for the front end; the oldest
                             // is dropped (counted) beyond it
  double diagnostics_period = 1.0;  // s between diagnostics, > 0
  // The node's part (docs/ROS.md, "Several depth workers"): set by the
  // nodelet, not a parameter; it decides which parameters are registered.
  DepthRole role = DepthRole::kStandalone;
  // Keyframes, store, scheduling, core options. stream.max_image_size is
  // stream.mvs.max_image_size (ReadDepthNodeOptions): one parameter,
  // mvs/max_image_size, sets the size keyframes are kept at and caps the
  // working size.
  StreamOptions stream;
  void Check() const;
};

// ~camera_extrinsic "x y z qx qy qz qw" as T_body_camera; throws Error
// naming the parameter when it is not 7 numbers or q is not a rotation.
Eigen::Isometry3d ParseCameraExtrinsic(const std::string& text);

struct FusionNodeOptions {
  std::string world_frame = "world";
  double publish_period = 1.0;  // s, at most one cloud per period (latched)
  double mesh_period = 0.0;     // s, mesh Marker period; 0 = no mesh
  int input_queue_size = 10;    // depth views waiting to be fused
  double diagnostics_period = 1.0;
  double error_throttle = 5.0;  // s between repeated errors about a problem
  // Diagnostics WARN while there were drops within the last drop_window s
  // (the totals are kept too).
  double drop_window = 60.0;
  // Cloud published for rviz: at most this many points (uniform subsample);
  // the saved PLY always has all points. 0 = no limit.
  int max_published_points = 500000;
  // A keyframe a selector announced (`keyframe_index`) without a depth view
  // after this many seconds is named missing in diagnostics; a second
  // first depth view of a keyframe is named done twice.
  KeyframeLedgerOptions keyframes;
  // Reordering, revisions, the session policy, the depth map store and the
  // core's fusion options (FusionSessionOptions); its fields are top-level
  // parameters (output_path, reorder_timeout, revision_timeout,
  // on_new_session, map_store_mb, spill_dir) and the section fusion/.
  // output_path is also where the cloud is saved on shutdown. The node's
  // fusion memory budgets are smaller than the core's (the node shares its
  // robot with other processes): map cache 256 MB (the core's default 512),
  // pending samples 128 MB (256). With map_store_mb the node's bounded
  // memory is 640 MB plus the cloud.
  FusionSessionOptions session = NodeSessionDefaults();
  // The mesh Marker's Poisson reconstruction and trimming: the core's
  // meshing options, the section meshing/ (the CLI's meshing.* keys, the
  // same defaults, so the live mesh is the offline mesh of the same cloud).
  MeshingOptions meshing;
  void Check() const;

  static FusionSessionOptions NodeSessionDefaults() {
    FusionSessionOptions s;
    s.fusion.map_cache_mb = 256;
    s.fusion.pending_mb = 128;
    return s;
  }
};

// The nodes' option structs in the registry. The depth node's own options
// and its StreamOptions are top-level parameters (world_frame, num_threads,
// keyframe_min_baseline, ...); StreamOptions::mvs and ::tracker are the
// sections mvs/, consistency/ and tracker/ with the core keys the node reads
// (kStreamCoreKeys), FusionNodeOptions::session.fusion is fusion/,
// with the core's keys (mvs/mpgc/drop_ncc). `prefix` is "" for a node.
// A depth node registers only the keys its options->role reads (the
// camera input's with ReadsCamera, the matching's with Reconstructs).
void RegisterOptions(OptionRegistry* registry, const std::string& prefix,
                     DepthNodeOptions* options);
void RegisterOptions(OptionRegistry* registry, const std::string& prefix,
                     FusionNodeOptions* options);
// (StreamOptions and the keyframe options register beside their structs in
// src/stream.)

// Reads the options of a node of `role` (defaults for unset parameters),
// checks them, and throws Error naming "<where>/<param>" or the option on a
// bad value.
DepthNodeOptions ReadDepthNodeOptions(const ParamSource& params,
                                      DepthRole role);
FusionNodeOptions ReadFusionNodeOptions(const ParamSource& params);
// Private parameters that the node does not know (typos), e.g.
// "keyframe_min_angel".
// A key another role reads is unknown here too (a worker has no
// pose_source).
std::vector<std::string> UnknownDepthNodeParams(const ParamSource& params,
                                                DepthRole role);
std::vector<std::string> UnknownFusionNodeParams(const ParamSource& params);

}  // namespace ros1
}  // namespace wild_mvs
