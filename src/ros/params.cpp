// Copyright wild_mvs authors. Parameter name -> option field, in one table
// per node. The names are documented in config/*.yaml.
#include "wild_mvs/ros/params.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <set>

#include "wild_mvs/core/error.h"

namespace wild_mvs {
namespace ros1 {

namespace {

const char* TypeName(const ParamSource::Value& v) {
  switch (v.index()) {
    case 0:
      return "bool";
    case 1:
      return "int";
    case 2:
      return "double";
    default:
      return "string";
  }
}

std::string Describe(const ParamSource::Value& v) {
  return std::visit(
      [](const auto& x) {
        std::ostringstream os;
        os << x;
        return os.str();
      },
      v);
}

// A table of (name, field) bindings; Apply reads every bound parameter.
class Binder {
 public:
  explicit Binder(const ParamSource& src) : src_(src) {}
  template <typename T>
  void Bind(const std::string& name, T* field) {
    names_.push_back(name);
    src_.Get(name, field);
    values_[name] = ParamSource::Value(*field);
  }
  const std::vector<std::string>& names() const { return names_; }
  // Every bound parameter's value after reading (the default when unset).
  const std::map<std::string, ParamSource::Value>& values() const {
    return values_;
  }

 private:
  const ParamSource& src_;
  std::vector<std::string> names_;
  std::map<std::string, ParamSource::Value> values_;
};

void BindMvs(Binder& b, MvsOptions* m) {
  b.Bind("mvs/num_neighbors", &m->global.num_neighbors);
  b.Bind("mvs/max_parallax_deg", &m->global.max_parallax_deg);
  b.Bind("mvs/min_baseline_deg", &m->global.min_baseline_deg);
  b.Bind("mvs/rescaling", &m->rescaling.enabled);
  b.Bind("mvs/min_scale", &m->rescaling.min_scale);
  b.Bind("mvs/max_scale", &m->rescaling.max_scale);
  b.Bind("mvs/local_view_selection", &m->local.enabled);
  b.Bind("mvs/num_active", &m->local.num_active);
  b.Bind("mvs/max_epipolar_angle_deg", &m->local.max_epipolar_angle_deg);
  b.Bind("mvs/min_ncc", &m->local.min_ncc);
  b.Bind("mvs/window", &m->mpgc.window);
  b.Bind("mvs/drop_ncc", &m->mpgc.drop_ncc);
  b.Bind("mvs/convergence_eps", &m->mpgc.convergence_eps);
  b.Bind("mvs/max_iterations", &m->mpgc.max_iterations);
  b.Bind("mvs/min_facing", &m->mpgc.min_facing);
  b.Bind("mvs/min_active_views", &m->mpgc.min_active_views);
  b.Bind("mvs/optimize_normal", &m->mpgc.optimize_normal);
  b.Bind("mvs/optimize_color_scale", &m->mpgc.optimize_color_scale);
  b.Bind("mvs/tile_size", &m->growing.tile_size);
  b.Bind("mvs/seeds_from_neighbors", &m->growing.seeds_from_neighbors);
  b.Bind("mvs/revisit_margin", &m->growing.revisit_margin);
  b.Bind("mvs/sweep_step", &m->sweep.step);
  b.Bind("mvs/sweep_num_depths", &m->sweep.num_depths);
  b.Bind("mvs/use_color", &m->use_color);
  b.Bind("mvs/max_image_size", &m->max_image_size);
}

void BindTracker(Binder& b, TrackerOptions* t) {
  b.Bind("tracker/max_features", &t->features.max_features);
  b.Bind("tracker/feature_downscale", &t->features.downscale);
  b.Bind("tracker/max_neighbors", &t->max_neighbors);
  b.Bind("tracker/min_overlap", &t->min_overlap);
  b.Bind("tracker/scene_depth", &t->scene_depth);
  b.Bind("tracker/max_epipolar_distance", &t->max_epipolar_distance);
  b.Bind("tracker/ratio", &t->ratio);
  b.Bind("tracker/max_reprojection_error", &t->max_reprojection_error);
  b.Bind("tracker/min_triangulation_angle_deg",
         &t->min_triangulation_angle_deg);
}

void BindFusion(Binder& b, FusionOptions* f) {
  b.Bind("fusion/min_support", &f->min_support);
  b.Bind("fusion/min_confidence", &f->min_confidence);
  b.Bind("fusion/depth_tolerance", &f->depth_tolerance);
  b.Bind("fusion/reprojection_tolerance_px", &f->reprojection_tolerance_px);
  b.Bind("fusion/normal_tolerance_deg", &f->normal_tolerance_deg);
  b.Bind("fusion/cell_scale", &f->cell_scale);
  b.Bind("fusion/max_neighbors", &f->max_neighbors);
  b.Bind("fusion/map_cache_mb", &f->map_cache_mb);
  b.Bind("fusion/pending_mb", &f->pending_mb);
}

std::vector<std::string> BindDepth(Binder& b, DepthNodeOptions* o) {
  b.Bind("world_frame", &o->world_frame);
  b.Bind("pose_source", &o->pose_source);
  b.Bind("tf_timeout", &o->tf_timeout);
  b.Bind("pose_sync_tolerance", &o->pose_sync_tolerance);
  b.Bind("camera_frame", &o->camera_frame);
  b.Bind("image_transport", &o->image_transport);
  b.Bind("camera_info_latest", &o->camera_info_latest);
  b.Bind("rectified", &o->rectified);
  b.Bind("depth_encoding", &o->depth_encoding);
  b.Bind("sparse_source", &o->sparse_source);
  b.Bind("input_queue_size", &o->input_queue_size);
  b.Bind("diagnostics_period", &o->diagnostics_period);
  b.Bind("error_throttle", &o->error_throttle);
  b.Bind("linearize", &o->linearize);
  StreamOptions& s = o->stream;
  b.Bind("keyframe_min_baseline", &s.keyframes.min_baseline);
  b.Bind("keyframe_min_angle_deg", &s.keyframes.min_angle_deg);
  b.Bind("max_keyframes", &s.store.max_keyframes);
  b.Bind("max_keyframe_mb", &s.store.max_mb);
  b.Bind("num_threads", &s.num_threads);
  b.Bind("max_pending", &s.max_pending);
  b.Bind("worker_index", &s.worker_index);
  b.Bind("worker_count", &s.worker_count);
  b.Bind("min_neighbors", &s.min_neighbors);
  b.Bind("lookahead", &s.lookahead);
  b.Bind("idle_flush", &s.idle_flush);
  b.Bind("redo_min_gain", &s.redo_min_gain);
  b.Bind("max_redo", &s.max_redo);
  b.Bind("max_image_size", &s.max_image_size);
  b.Bind("max_pose_jump", &s.max_pose_jump);
  b.Bind("stamp_reset_threshold", &s.stamp_reset_threshold);
  BindMvs(b, &s.mvs);
  BindTracker(b, &s.tracker);
  s.use_tracker = o->sparse_source == "tracker";
  return b.names();
}

std::vector<std::string> BindFusionNode(Binder& b, FusionNodeOptions* o) {
  b.Bind("world_frame", &o->world_frame);
  b.Bind("publish_period", &o->publish_period);
  b.Bind("mesh_period", &o->mesh_period);
  b.Bind("output_path", &o->output_path);
  b.Bind("input_queue_size", &o->input_queue_size);
  b.Bind("diagnostics_period", &o->diagnostics_period);
  b.Bind("error_throttle", &o->error_throttle);
  b.Bind("max_published_points", &o->max_published_points);
  b.Bind("reorder_timeout", &o->reorder_timeout);
  b.Bind("on_new_session", &o->on_new_session);
  b.Bind("map_store_mb", &o->map_store_mb);
  b.Bind("spill_dir", &o->spill_dir);
  BindFusion(b, &o->fusion);
  return b.names();
}

std::vector<std::string> Unknown(const ParamSource& params,
                                 const std::vector<std::string>& known) {
  const std::set<std::string> k(known.begin(), known.end());
  std::vector<std::string> out;
  for (const std::string& n : params.Names())
    if (!k.count(n)) out.push_back(n);
  return out;
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

void ParamSource::Get(const std::string& name, bool* v) const {
  Value x;
  if (!Lookup(name, &x)) return;
  if (auto* b = std::get_if<bool>(&x)) {
    *v = *b;
    return;
  }
  throw Error(Msg(Where(), "/", name, " = ", Describe(x), " is a ", TypeName(x),
                  ", expected a bool"));
}

void ParamSource::Get(const std::string& name, int* v) const {
  Value x;
  if (!Lookup(name, &x)) return;
  if (auto* i = std::get_if<int>(&x)) {
    *v = *i;
    return;
  }
  if (auto* d = std::get_if<double>(&x)) {
    if (std::isfinite(*d) && *d == std::round(*d) && std::abs(*d) < 2e9) {
      *v = static_cast<int>(*d);
      return;
    }
  }
  throw Error(Msg(Where(), "/", name, " = ", Describe(x), " is a ", TypeName(x),
                  ", expected an integer"));
}

void ParamSource::Get(const std::string& name, double* v) const {
  Value x;
  if (!Lookup(name, &x)) return;
  if (auto* d = std::get_if<double>(&x)) {
    *v = *d;
    return;
  }
  if (auto* i = std::get_if<int>(&x)) {
    *v = *i;
    return;
  }
  throw Error(Msg(Where(), "/", name, " = ", Describe(x), " is a ", TypeName(x),
                  ", expected a number"));
}

void ParamSource::Get(const std::string& name, std::string* v) const {
  Value x;
  if (!Lookup(name, &x)) return;
  if (auto* s = std::get_if<std::string>(&x)) {
    *v = *s;
    return;
  }
  throw Error(Msg(Where(), "/", name, " = ", Describe(x), " is a ", TypeName(x),
                  ", expected a string"));
}

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

void DepthNodeOptions::Check() const {
  Require(!world_frame.empty(), "world_frame must not be empty");
  Require(pose_source == "tf" || pose_source == "topic", "pose_source = '",
          pose_source, "' must be 'tf' or 'topic'");
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
  Require(std::isfinite(pose_sync_tolerance) && pose_sync_tolerance >= 0,
          "pose_sync_tolerance = ", pose_sync_tolerance, " must be >= 0");
  Require(input_queue_size >= 1 && input_queue_size <= 1000,
          "input_queue_size = ", input_queue_size, " must be in [1, 1000]");
  Require(std::isfinite(diagnostics_period) && diagnostics_period > 0,
          "diagnostics_period = ", diagnostics_period, " must be > 0");
  Require(std::isfinite(error_throttle) && error_throttle >= 0,
          "error_throttle = ", error_throttle, " must be >= 0");
  stream.Check();
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
  Require(max_published_points >= 0,
          "max_published_points = ", max_published_points, " must be >= 0");
  Require(std::isfinite(reorder_timeout) && reorder_timeout >= 0,
          "reorder_timeout = ", reorder_timeout, " must be >= 0");
  Require(on_new_session == "keep" || on_new_session == "reset",
          "on_new_session = '", on_new_session, "' must be 'keep' or 'reset'");
  Require(std::isfinite(map_store_mb) && map_store_mb > 0,
          "map_store_mb = ", map_store_mb, " must be > 0");
  fusion.Check();
}

DepthNodeOptions ReadDepthNodeOptions(const ParamSource& params) {
  DepthNodeOptions o;
  Binder b(params);
  BindDepth(b, &o);
  CheckOptions(o, params);
  return o;
}

FusionNodeOptions ReadFusionNodeOptions(const ParamSource& params) {
  FusionNodeOptions o;
  Binder b(params);
  BindFusionNode(b, &o);
  CheckOptions(o, params);
  return o;
}

namespace {
// Every bound parameter's value after reading `params` into fresh options.
template <typename Options, typename BindFn>
std::map<std::string, ParamSource::Value> Values(const ParamSource& params,
                                                 BindFn bind) {
  Options o;
  Binder b(params);
  bind(b, &o);
  return b.values();
}
}  // namespace

std::map<std::string, ParamSource::Value> DepthNodeParamValues(
    const ParamSource& params) {
  return Values<DepthNodeOptions>(params, BindDepth);
}

std::map<std::string, ParamSource::Value> FusionNodeParamValues(
    const ParamSource& params) {
  return Values<FusionNodeOptions>(params, BindFusionNode);
}

std::vector<std::string> UnknownDepthNodeParams(const ParamSource& params) {
  DepthNodeOptions o;
  MapParamSource empty;
  Binder b(empty);
  return Unknown(params, BindDepth(b, &o));
}

std::vector<std::string> UnknownFusionNodeParams(const ParamSource& params) {
  FusionNodeOptions o;
  MapParamSource empty;
  Binder b(empty);
  return Unknown(params, BindFusionNode(b, &o));
}

}  // namespace ros1
}  // namespace wild_mvs
