// Copyright wild_mvs authors.
#include "wild_mvs/ros/live_params.h"

#include <dynamic_reconfigure/ConfigDescription.h>
#include <ros/console.h>

#include <cmath>
#include <limits>

#include "wild_mvs/core/error.h"
#include "wild_mvs/ros/params.h"

namespace wild_mvs {
namespace ros1 {
namespace {

using Option = OptionRegistry::Option;
using Type = OptionRegistry::Type;

const char* DrType(Type t) {
  switch (t) {
    case Type::kBool:
      return "bool";
    case Type::kInt:
      return "int";
    case Type::kDouble:
      return "double";
    case Type::kString:
      return "str";
  }
  return "str";
}

// Appends `o`'s entry to `c` with value v (bools and strings ignore v).
void AddValue(const Option& o, double v, dynamic_reconfigure::Config* c) {
  const std::string name = ParamName(o.key());
  switch (o.type()) {
    case Type::kBool: {
      dynamic_reconfigure::BoolParameter p;
      p.name = name;
      p.value = o.GetBool();
      c->bools.push_back(p);
      break;
    }
    case Type::kInt: {
      dynamic_reconfigure::IntParameter p;
      p.name = name;
      p.value = static_cast<int>(v);
      c->ints.push_back(p);
      break;
    }
    case Type::kDouble: {
      dynamic_reconfigure::DoubleParameter p;
      p.name = name;
      p.value = v;
      c->doubles.push_back(p);
      break;
    }
    case Type::kString: {
      dynamic_reconfigure::StrParameter p;
      p.name = name;
      p.value = o.GetString();
      c->strs.push_back(p);
      break;
    }
  }
}

double Value(const Option& o) {
  return o.type() == Type::kInt      ? o.GetInt()
         : o.type() == Type::kDouble ? o.GetDouble()
                                     : 0.0;
}

// The slider bounds of rqt_reconfigure from the registry's range.
double Bound(const Option& o, bool upper) {
  const OptionRegistry::Range& r = o.range();
  const bool has = upper ? r.has_max : r.has_min;
  if (!upper && has && r.or_zero && r.min > 0) return 0;  // "0 or >= min"
  if (has) return upper ? r.max : r.min;
  if (o.type() == Type::kInt)
    return upper ? std::numeric_limits<int>::max()
                 : std::numeric_limits<int>::min();
  return upper ? std::numeric_limits<double>::infinity()
               : -std::numeric_limits<double>::infinity();
}

void AddDefaultGroup(dynamic_reconfigure::Config* c) {
  dynamic_reconfigure::GroupState g;
  g.name = "Default";
  g.state = true;
  g.id = 0;
  g.parent = 0;
  c->groups.push_back(g);
}

}  // namespace

LiveParams::LiveParams(const ros::NodeHandle& private_nh,
                       OptionRegistry* registry,
                       const std::vector<std::string>& keys,
                       std::function<void()> apply)
    : pnh_(private_nh), registry_(registry), apply_(std::move(apply)) {
  dynamic_reconfigure::ConfigDescription d;
  dynamic_reconfigure::Group group;
  group.name = "Default";
  group.type = "";
  group.id = 0;
  group.parent = 0;
  for (const std::string& key : keys) {
    Option* o = registry_->Find(key);
    Require(o != nullptr, "live parameters: unknown option key '", key, "'");
    Require(!o->optional(), "live parameters: '", key,
            "' may be unset, which dynamic_reconfigure cannot show");
    options_.push_back(o);
    dynamic_reconfigure::ParamDescription p;
    p.name = ParamName(key);
    p.type = DrType(o->type());
    p.level = 0;
    p.description = o->help();
    const std::string range = o->RangeText();
    if (!range.empty()) p.description += " (" + range + ")";
    group.parameters.push_back(p);
    AddValue(*o, Bound(*o, false), &d.min);
    AddValue(*o, Bound(*o, true), &d.max);
    AddValue(*o, Value(*o), &d.dflt);
  }
  d.groups.push_back(group);
  AddDefaultGroup(&d.min);
  AddDefaultGroup(&d.max);
  AddDefaultGroup(&d.dflt);
  descriptions_pub_ = pnh_.advertise<dynamic_reconfigure::ConfigDescription>(
      "parameter_descriptions", 1, true);
  updates_pub_ =
      pnh_.advertise<dynamic_reconfigure::Config>("parameter_updates", 1, true);
  descriptions_pub_.publish(d);
  {
    std::lock_guard<std::mutex> lock(mutex_);
    PublishLocked();
  }
  set_srv_ = pnh_.advertiseService("set_parameters", &LiveParams::OnSet, this);
}

dynamic_reconfigure::Config LiveParams::CurrentLocked() const {
  dynamic_reconfigure::Config c;
  for (const Option* o : options_) AddValue(*o, Value(*o), &c);
  AddDefaultGroup(&c);
  return c;
}

dynamic_reconfigure::Config LiveParams::Current() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return CurrentLocked();
}

std::string LiveParams::last_error() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return last_error_;
}

void LiveParams::PublishLocked() {
  const dynamic_reconfigure::Config c = CurrentLocked();
  updates_pub_.publish(c);
  // The parameter server follows, as dynamic_reconfigure's servers do.
  for (const Option* o : options_) {
    const std::string name = ParamName(o->key());
    switch (o->type()) {
      case Type::kBool:
        pnh_.setParam(name, o->GetBool());
        break;
      case Type::kInt:
        pnh_.setParam(name, o->GetInt());
        break;
      case Type::kDouble:
        pnh_.setParam(name, o->GetDouble());
        break;
      case Type::kString:
        pnh_.setParam(name, o->GetString());
        break;
    }
  }
}

bool LiveParams::OnSet(dynamic_reconfigure::Reconfigure::Request& req,
                       dynamic_reconfigure::Reconfigure::Response& res) {
  std::lock_guard<std::mutex> lock(mutex_);
  std::vector<std::string> saved;
  for (const Option* o : options_) saved.push_back(o->Text());
  // Sets the offered option of each requested parameter (a name that is
  // not offered is refused: a typo must not pass).
  auto set_all = [this](const auto& params, auto set) {
    for (const auto& p : params) {
      Option* found = nullptr;
      for (Option* o : options_)
        if (ParamName(o->key()) == p.name) found = o;
      Require(found, "'", p.name, "' is not a live parameter");
      set(found, p.value);
    }
  };
  std::string problem;
  try {
    set_all(req.config.bools, [](Option* o, bool v) { o->SetBool(v); });
    set_all(req.config.ints, [](Option* o, int v) { o->SetInt(v); });
    set_all(req.config.doubles, [](Option* o, double v) { o->SetDouble(v); });
    set_all(req.config.strs,
            [](Option* o, const std::string& v) { o->SetString(v); });
    apply_();  // Check() of the whole struct, then handed to the node
  } catch (const Error& e) {
    problem = e.what();
  }
  if (!problem.empty()) {
    for (size_t i = 0; i < options_.size(); ++i) options_[i]->SetText(saved[i]);
    last_error_ = problem;
    ROS_ERROR("%s: live parameter change refused (values kept): %s",
              pnh_.getNamespace().c_str(), problem.c_str());
  } else {
    ROS_INFO("%s: live parameters changed", pnh_.getNamespace().c_str());
  }
  PublishLocked();
  res.config = CurrentLocked();
  return true;
}

DepthLiveParams::DepthLiveParams(
    const ros::NodeHandle& private_nh, const DepthNodeOptions& options,
    std::function<void(const StreamOptions&)> apply)
    : live_(options) {
  RegisterOptions(&registry_, "", &live_);
  // Those of the node's role (a worker selects no keyframes, a selector
  // matches nothing).
  std::vector<std::string> keys;
  for (const char* k :
       {"keyframe_min_baseline", "keyframe_min_angle_deg", "mvs.max_image_size",
        "mvs.global.num_neighbors", "mvs.local.min_ncc", "mvs.mpgc.drop_ncc",
        "mvs.growing.revisit_margin"})
    if (registry_.Has(k)) keys.push_back(k);
  params_ =
      std::make_unique<LiveParams>(private_nh, &registry_, keys, [this, apply] {
        live_.Check();
        apply(live_.stream);
      });
}

}  // namespace ros1
}  // namespace wild_mvs
