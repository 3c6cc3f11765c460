// Copyright wild_mvs authors. ROS parameters <-> option structs through the
// option registry; the nodes' options register their fields here.
#include "wild_mvs/ros/params.h"

#include <cmath>
#include <set>
#include <sstream>

#include "wild_mvs/core/error.h"

namespace wild_mvs {
namespace ros1 {

namespace {

std::string Describe(const ParamSource::Value& v) {
  return std::visit(
      [](const auto& x) {
        std::ostringstream os;
        os << x;
        return os.str();
      },
      v);
}

void SetValue(const ParamSource::Value& v, OptionRegistry::Option* o) {
  if (auto* b = std::get_if<bool>(&v)) {
    o->SetBool(*b);
  } else if (auto* i = std::get_if<int>(&v)) {
    o->SetInt(*i);
  } else if (auto* d = std::get_if<double>(&v)) {
    o->SetDouble(*d);
  } else {
    const std::string& s = std::get<std::string>(v);
    // rosparam's YAML reads "inf" as a string; accept it where infinity is a
    // value (an open bounding box), and "auto" where a number may be unset.
    if (o->type() == OptionRegistry::Type::kDouble &&
        (o->allow_infinite() || o->optional())) {
      o->SetText(s);
    } else {
      o->SetString(s);
    }
  }
}

// Runs Check() and prefixes the error with where the parameters come from.
template <typename T>
void CheckOptions(const T& options, const ParamSource& params) {
  try {
    options.Check();
  } catch (const Error& e) {
    throw Error(Msg(params.Where(), ": bad parameter: ", e.what()));
  }
}

}  // namespace

bool MapParamSource::Lookup(const std::string& name, Value* value) const {
  auto it = values_.find(name);
  if (it == values_.end()) return false;
  *value = it->second;
  return true;
}

std::vector<std::string> MapParamSource::Names() const {
  std::vector<std::string> out;
  for (const auto& [k, v] : values_) out.push_back(k);
  return out;
}

std::string ParamName(const std::string& key) {
  std::string name = key;
  for (char& c : name) {
    if (c == '.') c = '/';
  }
  return name;
}

void ReadParams(const ParamSource& params, OptionRegistry* registry) {
  for (OptionRegistry::Option& o : registry->options()) {
    const std::string name = ParamName(o.key());
    ParamSource::Value v;
    if (!params.Lookup(name, &v)) continue;
    try {
      SetValue(v, &o);
    } catch (const Error& e) {
      throw Error(
          Msg(params.Where(), "/", name, " = ", Describe(v), ": ", e.what()));
    }
  }
}

std::vector<std::string> UnknownParams(const ParamSource& params,
                                       const OptionRegistry& registry) {
  std::set<std::string> known;
  for (const OptionRegistry::Option& o : registry.options()) {
    known.insert(ParamName(o.key()));
  }
  std::vector<std::string> out;
  for (const std::string& n : params.Names()) {
    if (!known.count(n)) out.push_back(n);
  }
  return out;
}

void DepthNodeOptions::Check() const {
  Require(!world_frame.empty(), "world_frame must not be empty");
  Require(pose_source == "tf" || pose_source == "topic" ||
              pose_source == "pose" || pose_source == "pose_with_covariance" ||
              pose_source == "transform" || pose_source == "odometry",
          "pose_source = '", pose_source,
          "' must be tf, pose (or topic), pose_with_covariance, transform or "
          "odometry");
  if (!camera_extrinsic.empty()) ParseCameraExtrinsic(camera_extrinsic);
  Require(!image_transport.empty() &&
              image_transport.find_first_of("/ ") == std::string::npos,
          "image_transport = '", image_transport,
          "' must name an image_transport plugin (raw, compressed, ...)");
  Require(depth_encoding == "32FC1" || depth_encoding == "16UC1",
          "depth_encoding = '", depth_encoding,
          "' must be '32FC1' (metres) or '16UC1' (millimetres)");
  Require(sparse_source == "tracker" || sparse_source == "topic" ||
              sparse_source == "none",
          "sparse_source = '", sparse_source,
          "' must be 'tracker', 'topic' or 'none'");
  Require(std::isfinite(tf_timeout) && tf_timeout >= 0 && tf_timeout <= 60,
          "tf_timeout = ", tf_timeout, " must be in [0, 60] s");
  Require(input_queue_size >= 1 && input_queue_size <= 1000,
          "input_queue_size = ", input_queue_size, " must be in [1, 1000]");
  Require(std::isfinite(diagnostics_period) && diagnostics_period > 0,
          "diagnostics_period = ", diagnostics_period, " must be > 0");
  // Keyframes are kept at this size (StreamOptions::max_image_size).
  Require(stream.mvs.max_image_size == 0 || stream.mvs.max_image_size >= 16,
          "mvs.max_image_size = ", stream.mvs.max_image_size,
          " must be 0 (as received) or >= 16");
  stream.Check();
}

const char* RoleName(DepthRole role) {
  switch (role) {
    case DepthRole::kSelector:
      return "selector";
    case DepthRole::kWorker:
      return "worker";
    case DepthRole::kStandalone:
      break;
  }
  return "standalone";
}

const char* ConfigFileName(DepthRole role) {
  switch (role) {
    case DepthRole::kSelector:
      return "keyframe_selector.yaml";
    case DepthRole::kWorker:
      return "depth_worker.yaml";
    case DepthRole::kStandalone:
      break;
  }
  return "depth_node.yaml";
}

Eigen::Isometry3d ParseCameraExtrinsic(const std::string& text) {
  std::istringstream in(text);
  double v[7];
  for (double& x : v) in >> x;
  std::string rest;
  Require(static_cast<bool>(in) && !(in >> rest), "camera_extrinsic = '", text,
          "' must be 7 numbers: x y z qx qy qz qw (the camera optical frame "
          "in the body frame)");
  for (double x : v)
    Require(std::isfinite(x), "camera_extrinsic = '", text,
            "' has a non-finite value");
  Eigen::Quaterniond q(v[6], v[3], v[4], v[5]);
  Require(std::abs(q.norm() - 1.0) < 1e-3, "camera_extrinsic = '", text,
          "': the quaternion qx qy qz qw has norm ", q.norm(), " (must be 1)");
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = q.normalized().toRotationMatrix();
  T.translation() = Eigen::Vector3d(v[0], v[1], v[2]);
  return T;
}

void FusionNodeOptions::Check() const {
  Require(!world_frame.empty(), "world_frame must not be empty");
  Require(std::isfinite(publish_period) && publish_period > 0,
          "publish_period = ", publish_period, " must be > 0");
  Require(std::isfinite(mesh_period) && mesh_period >= 0,
          "mesh_period = ", mesh_period, " must be >= 0 (0 = no mesh)");
  Require(input_queue_size >= 1 && input_queue_size <= 1000,
          "input_queue_size = ", input_queue_size, " must be in [1, 1000]");
  Require(std::isfinite(diagnostics_period) && diagnostics_period > 0,
          "diagnostics_period = ", diagnostics_period, " must be > 0");
  Require(std::isfinite(error_throttle) && error_throttle >= 0,
          "error_throttle = ", error_throttle, " must be >= 0");
  Require(
      std::isfinite(drop_window) && drop_window >= 0.1 && drop_window <= 86400,
      "drop_window = ", drop_window, " must be in [0.1, 86400] s");
  Require(max_published_points >= 0,
          "max_published_points = ", max_published_points, " must be >= 0");
  keyframes.Check();
  session.Check();
  meshing.Check();
}

void RegisterOptions(OptionRegistry* registry, const std::string& prefix,
                     DepthNodeOptions* o) {
  auto key = [&prefix](const char* name) {
    return OptionRegistry::Join(prefix, name);
  };
  registry
      ->Add(key("world_frame"), &o->world_frame,
            "fixed frame of the poses (REP 105)")
      .Note("not empty");
  if (ReadsCamera(o->role)) {
    registry
        ->Add(
            key("pose_source"), &o->pose_source,
            "tf: world_frame <- image frame_id at the image stamp; on `pose`, "
            "interpolated at the image stamp: pose (PoseStamped; topic = the "
            "same), pose_with_covariance, transform (TransformStamped), "
            "odometry (nav_msgs/Odometry)")
        .OneOf({"tf", "topic", "pose", "pose_with_covariance", "transform",
                "odometry"});
    registry->Add(key("pose_frame"), &o->pose_frame,
                  "frame the topic poses are of; \"\" = the camera (pose), the "
                  "child_frame_id (transform, odometry); a body frame needs "
                  "camera_extrinsic or tf body <- camera");
    registry
        ->Add(key("camera_extrinsic"), &o->camera_extrinsic,
              "T_body_camera \"x y z qx qy qz qw\"; \"\" = from tf "
              "(/tf_static)")
        .Note("\"\" or 7 numbers");
    registry
        ->Add(key("tf_timeout"), &o->tf_timeout,
              "s to wait for the pose of a frame")
        .Min(0)
        .Max(60);
    registry->Add(key("camera_frame"), &o->camera_frame,
                  "camera optical frame; \"\" = the image header's frame_id");
    registry
        ->Add(key("image_transport"), &o->image_transport,
              "image_transport plugin: raw, compressed (decoded here if the "
              "plugin is missing), theora, ...")
        .Note("a plugin name, no '/' or ' '");
    registry->Add(
        key("camera_info_latest"), &o->camera_info_latest,
        "false: camera_info paired by exact stamp (CameraSubscriber); "
        "true: the latest one");
    registry->Add(key("rectified"), &o->rectified,
                  "images are rectified: camera from P, D ignored (also on for "
                  "an image_rect topic)");
    registry
        ->Add(key("sparse_source"), &o->sparse_source,
              "tracker (online SIFT tracks), topic (`sparse_points`), none")
        .OneOf({"tracker", "topic", "none"});
    registry
        ->Add(key("input_queue_size"), &o->input_queue_size,
              "frames waiting for the front end; the oldest is dropped "
              "(counted) beyond it")
        .Min(1)
        .Max(1000);
  }
  if (Reconstructs(o->role)) {
    registry
        ->Add(key("depth_encoding"), &o->depth_encoding,
              "~depth/image_rect: 32FC1 metres, NaN unknown (REP 118); 16UC1 "
              "millimetres, 0 unknown")
        .OneOf({"32FC1", "16UC1"});
  }
  registry
      ->Add(key("diagnostics_period"), &o->diagnostics_period,
            "s between diagnostics")
      .Above(0);
  // The stream's keys follow the role too.
  o->stream.select_keyframes = ReadsCamera(o->role);
  o->stream.reconstruct = Reconstructs(o->role);
  RegisterOptions(registry, prefix, &o->stream);
  // The node keeps its keyframes at mvs/max_image_size (its Check()).
  registry->Find(OptionRegistry::Join(prefix, "mvs.max_image_size"))
      ->Min(16)
      .OrZero();
}

void RegisterOptions(OptionRegistry* registry, const std::string& prefix,
                     FusionNodeOptions* o) {
  auto key = [&prefix](const char* name) {
    return OptionRegistry::Join(prefix, name);
  };
  registry->Add(key("world_frame"), &o->world_frame, "fixed frame of the cloud")
      .Note("not empty");
  registry
      ->Add(key("publish_period"), &o->publish_period,
            "s, at most one (latched) cloud per period")
      .Above(0);
  registry
      ->Add(key("mesh_period"), &o->mesh_period,
            "s between mesh Markers (Poisson), 0 = no mesh")
      .Min(0);
  registry->Add(key("output_path"), &o->session.output_path,
                "PLY saved on shutdown (SIGINT / SIGTERM) when set");
  registry
      ->Add(key("input_queue_size"), &o->input_queue_size,
            "depth views waiting to be fused (oldest dropped, counted)")
      .Min(1)
      .Max(1000);
  registry
      ->Add(key("reorder_timeout"), &o->session.reorder_timeout,
            "s a view waits for a missing earlier keyframe (several workers)")
      .Min(0);
  registry
      ->Add(key("revision_timeout"), &o->session.revision_timeout,
            "a view waits for its keyframe's final revision until its depth "
            "session sent nothing for this long (s), then it is fused as it "
            "is (0 = never waits)")
      .Min(0);
  registry
      ->Add(key("on_new_session"), &o->session.on_new_session,
            "depth node reset/restarted (DepthView.session): keep = same "
            "cloud, reset = save it as <output>_session<N>.ply and start a "
            "new one")
      .OneOf({"keep", "reset"});
  registry
      ->Add(key("map_store_mb"), &o->session.map_store_mb,
            "depth maps kept in memory: fused ones beyond it spill to "
            "spill_dir, waiting ones are fused, oldest first")
      .Above(0);
  registry->Add(key("spill_dir"), &o->session.spill_dir,
                "\"\" = a temporary folder, removed at exit");
  registry
      ->Add(key("max_published_points"), &o->max_published_points,
            "rviz cloud subsample (the saved PLY has every point), 0 = all")
      .Min(0);
  registry
      ->Add(key("diagnostics_period"), &o->diagnostics_period,
            "s between diagnostics")
      .Above(0);
  registry
      ->Add(key("error_throttle"), &o->error_throttle,
            "s between repeated errors about the same problem")
      .Min(0);
  registry
      ->Add(key("drop_window"), &o->drop_window,
            "s, diagnostics WARN while drops happened within this window")
      .Min(0.1)
      .Max(86400);
  registry
      ->Add(key("keyframe_missing_after"), &o->keyframes.missing_after,
            "s after a selector announced a keyframe (`keyframe_index`) "
            "before it counts as missing without a depth view")
      .Above(0);
  registry
      ->Add(key("keyframe_ledger_size"), &o->keyframes.max_keyframes,
            "keyframes remembered for the missing / done-twice diagnostics")
      .Min(1);
  // The core's fusion options, with the node's smaller memory budgets
  // (map_cache_mb 256, pending_mb 128; the CLI's are 512 and 256).
  RegisterOptions(registry, key("fusion"), &o->session.fusion);
  RegisterOptions(registry, key("meshing"), &o->meshing);
}

DepthNodeOptions ReadDepthNodeOptions(const ParamSource& params,
                                      DepthRole role) {
  DepthNodeOptions o;
  o.role = role;
  OptionRegistry registry;
  RegisterOptions(&registry, "", &o);
  ReadParams(params, &registry);
  // A worker's sparse points come with its keyframes.
  o.stream.use_tracker = o.sparse_source == "tracker" && ReadsCamera(role);
  o.stream.max_image_size = o.stream.mvs.max_image_size;
  CheckOptions(o, params);
  return o;
}

FusionNodeOptions ReadFusionNodeOptions(const ParamSource& params) {
  FusionNodeOptions o;
  OptionRegistry registry;
  RegisterOptions(&registry, "", &o);
  ReadParams(params, &registry);
  CheckOptions(o, params);
  return o;
}

std::vector<std::string> UnknownDepthNodeParams(const ParamSource& params,
                                                DepthRole role) {
  DepthNodeOptions o;
  o.role = role;
  OptionRegistry registry;
  RegisterOptions(&registry, "", &o);
  return UnknownParams(params, registry);
}

std::vector<std::string> UnknownFusionNodeParams(const ParamSource& params) {
  FusionNodeOptions o;
  OptionRegistry registry;
  RegisterOptions(&registry, "", &o);
  return UnknownParams(params, registry);
}

}  // namespace ros1
}  // namespace wild_mvs
