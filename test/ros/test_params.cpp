// Copyright wild_mvs authors. ROS parameters -> option structs.
#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <cmath>
#include <functional>

#include "wild_mvs/core/error.h"
#include "wild_mvs/ros/params.h"

namespace wild_mvs {
namespace ros1 {
namespace {

TEST(Params, DefaultsAreValid) {
  MapParamSource none;
  const DepthNodeOptions d = ReadDepthNodeOptions(none);
  EXPECT_EQ(d.world_frame, "world");
  EXPECT_EQ(d.pose_source, "tf");
  EXPECT_TRUE(d.stream.use_tracker);
  EXPECT_EQ(d.stream.mvs.global.num_neighbors, 10);  // paper default kept
  const FusionNodeOptions f = ReadFusionNodeOptions(none);
  EXPECT_EQ(f.fusion.min_support, FusionOptions().min_support);
  EXPECT_EQ(f.on_new_session, "keep");
}

TEST(Params, ValuesReachTheCoreOptions) {
  MapParamSource p({{"world_frame", std::string("map")},
                    {"keyframe_min_baseline", 0.2},
                    {"keyframe_min_angle_deg", 7},  // int for a double: ok
                    {"worker_index", 1},
                    {"worker_count", 3},
                    {"sparse_source", std::string("topic")},
                    {"mvs/num_neighbors", 6},
                    {"mvs/min_ncc", 0.35},
                    {"mvs/optimize_color_scale", false},
                    {"tracker/max_features", 1500},
                    {"max_keyframe_mb", 128.0}});
  const DepthNodeOptions d = ReadDepthNodeOptions(p);
  EXPECT_EQ(d.world_frame, "map");
  EXPECT_DOUBLE_EQ(d.stream.keyframes.min_baseline, 0.2);
  EXPECT_DOUBLE_EQ(d.stream.keyframes.min_angle_deg, 7.0);
  EXPECT_EQ(d.stream.worker_index, 1);
  EXPECT_EQ(d.stream.worker_count, 3);
  EXPECT_FALSE(d.stream.use_tracker);
  EXPECT_EQ(d.stream.mvs.global.num_neighbors, 6);
  EXPECT_DOUBLE_EQ(d.stream.mvs.local.min_ncc, 0.35);
  EXPECT_FALSE(d.stream.mvs.mpgc.optimize_color_scale);
  EXPECT_EQ(d.stream.tracker.features.max_features, 1500);
  EXPECT_DOUBLE_EQ(d.stream.store.max_mb, 128.0);

  MapParamSource q({{"publish_period", 0.5},
                    {"output_path", std::string("/tmp/x.ply")},
                    {"fusion/min_support", 2},
                    {"fusion/depth_tolerance", 0.02}});
  const FusionNodeOptions f = ReadFusionNodeOptions(q);
  EXPECT_DOUBLE_EQ(f.publish_period, 0.5);
  EXPECT_EQ(f.output_path, "/tmp/x.ply");
  EXPECT_EQ(f.fusion.min_support, 2);
  EXPECT_DOUBLE_EQ(f.fusion.depth_tolerance, 0.02);
}

// config/<node>.yaml as "a/b" -> scalar text.
std::map<std::string, std::string> FlatYaml(const std::string& file) {
  std::map<std::string, std::string> out;
  std::function<void(const YAML::Node&, const std::string&)> walk =
      [&](const YAML::Node& n, const std::string& prefix) {
        for (const auto& kv : n) {
          const std::string key = prefix + kv.first.as<std::string>();
          if (kv.second.IsMap())
            walk(kv.second, key + "/");
          else
            out[key] = kv.second.as<std::string>();
        }
      };
  walk(YAML::LoadFile(file), "");
  return out;
}

// The config files say "defaults shown": every parameter of the node is in
// its file with the value the node uses when the parameter is unset.
void ExpectYamlShowsDefaults(
    const std::string& file,
    const std::map<std::string, ParamSource::Value>& defaults) {
  const auto yaml = FlatYaml(file);
  for (const auto& [name, value] : defaults) {
    SCOPED_TRACE(file + ": " + name);
    auto it = yaml.find(name);
    ASSERT_NE(it, yaml.end()) << "parameter missing from the file";
    const std::string& text = it->second;
    if (auto* b = std::get_if<bool>(&value)) {
      EXPECT_EQ(text, *b ? "true" : "false");
    } else if (auto* i = std::get_if<int>(&value)) {
      EXPECT_DOUBLE_EQ(std::stod(text), *i);
    } else if (auto* d = std::get_if<double>(&value)) {
      EXPECT_DOUBLE_EQ(std::stod(text), *d);
    } else {
      EXPECT_EQ(text, std::get<std::string>(value));
    }
  }
  for (const auto& [name, text] : yaml)
    EXPECT_TRUE(defaults.count(name)) << file << ": unknown key " << name;
}

TEST(Params, ConfigFilesShowTheDefaults) {
  const std::string dir = std::string(WILD_MVS_SOURCE_DIR) + "/config/";
  MapParamSource none;
  ExpectYamlShowsDefaults(dir + "depth_node.yaml", DepthNodeParamValues(none));
  ExpectYamlShowsDefaults(dir + "fusion_node.yaml",
                          FusionNodeParamValues(none));
  // The fusion node's memory budgets are below the core's (CLI) defaults.
  const auto f = FusionNodeParamValues(none);
  EXPECT_DOUBLE_EQ(std::get<double>(f.at("map_store_mb")), 256.0);
  EXPECT_LT(std::get<double>(f.at("fusion/map_cache_mb")),
            FusionOptions().map_cache_mb);
  EXPECT_LT(std::get<double>(f.at("fusion/pending_mb")),
            FusionOptions().pending_mb);
  // Values read from parameters are reported as read.
  const auto set =
      FusionNodeParamValues(MapParamSource({{"fusion/pending_mb", 32.0}}));
  EXPECT_DOUBLE_EQ(std::get<double>(set.at("fusion/pending_mb")), 32.0);
}

std::string ErrorOf(const MapParamSource& p) {
  try {
    ReadDepthNodeOptions(p);
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

TEST(Params, BadValuesNameTheParameter) {
  EXPECT_NE(ErrorOf(MapParamSource({{"worker_index", 2}})).find("worker_index"),
            std::string::npos);
  EXPECT_NE(ErrorOf(MapParamSource({{"pose_source", std::string("gps")}}))
                .find("pose_source"),
            std::string::npos);
  EXPECT_NE(ErrorOf(MapParamSource({{"tf_timeout", std::string("fast")}}))
                .find("tf_timeout"),
            std::string::npos);
  EXPECT_NE(
      ErrorOf(MapParamSource({{"max_keyframes", 2.5}})).find("max_keyframes"),
      std::string::npos);
  EXPECT_NE(ErrorOf(MapParamSource({{"mvs/min_ncc", 3.0}})).find("ncc"),
            std::string::npos);
  EXPECT_NE(ErrorOf(MapParamSource({{"linearize", 1}})).find("linearize"),
            std::string::npos);
  MapParamSource f({{"fusion/min_support", 0}});
  EXPECT_THROW(ReadFusionNodeOptions(f), Error);
  // Reset policy of the fusion node: keep or reset, nothing else.
  EXPECT_EQ(ReadFusionNodeOptions(
                MapParamSource({{"on_new_session", std::string("reset")}}))
                .on_new_session,
            "reset");
  try {
    ReadFusionNodeOptions(
        MapParamSource({{"on_new_session", std::string("clear")}}));
    ADD_FAILURE() << "on_new_session 'clear' accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("on_new_session"), std::string::npos);
  }
}

TEST(Params, UnknownParametersAreListed) {
  MapParamSource p(
      {{"keyframe_min_angel", 5.0}, {"world_frame", std::string("w")}});
  const auto unknown = UnknownDepthNodeParams(p);
  ASSERT_EQ(unknown.size(), 1u);
  EXPECT_EQ(unknown[0], "keyframe_min_angel");
  EXPECT_TRUE(
      UnknownFusionNodeParams(MapParamSource({{"fusion/min_support", 3}}))
          .empty());
}

}  // namespace
}  // namespace ros1
}  // namespace wild_mvs
