// Copyright wild_mvs authors. ROS parameters -> option structs.
#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <set>

#include "option_ranges.h"
#include "wild_mvs/core/error.h"
#include "wild_mvs/io/option_yaml.h"
#include "wild_mvs/ros/params.h"

namespace wild_mvs {
namespace ros1 {
namespace {

TEST(Params, DefaultsAreValid) {
  MapParamSource none;
  const DepthNodeOptions d = ReadDepthNodeOptions(none, DepthRole::kStandalone);
  EXPECT_EQ(d.world_frame, "world");
  EXPECT_EQ(d.pose_source, "tf");
  EXPECT_TRUE(d.stream.use_tracker);
  EXPECT_EQ(d.stream.mvs.global.num_neighbors, 10);  // paper default kept
  const FusionNodeOptions f = ReadFusionNodeOptions(none);
  EXPECT_EQ(f.session.fusion.min_support, FusionOptions().min_support);
  EXPECT_EQ(f.session.on_new_session, "keep");
  // The live mesh is the offline mesh: the core's meshing defaults.
  EXPECT_EQ(f.meshing.depth, MeshingOptions().depth);
  EXPECT_DOUBLE_EQ(f.meshing.trim_distance, MeshingOptions().trim_distance);
}

TEST(Params, ValuesReachTheCoreOptions) {
  MapParamSource p({{"world_frame", std::string("map")},
                    {"keyframe_min_baseline", 0.2},
                    {"keyframe_min_angle_deg", 7},  // int for a double: ok
                    {"worker_index", 1},
                    {"worker_count", 3},
                    {"sparse_source", std::string("topic")},
                    {"mvs/global/num_neighbors", 6},
                    {"mvs/local/min_ncc", 0.35},
                    {"consistency/min_consistent", 2},
                    {"tracker/features/max_features", 1500},
                    {"max_keyframe_mb", 128.0},
                    {"mvs/mpgc/min_active_views", 2},
                    {"mvs/sweep/below_seeds", 7},
                    {"mvs/max_image_size", 320}});
  const DepthNodeOptions d = ReadDepthNodeOptions(p, DepthRole::kStandalone);
  EXPECT_EQ(d.world_frame, "map");
  EXPECT_DOUBLE_EQ(d.stream.keyframes.min_baseline, 0.2);
  EXPECT_DOUBLE_EQ(d.stream.keyframes.min_angle_deg, 7.0);
  EXPECT_EQ(d.stream.worker_index, 1);
  EXPECT_EQ(d.stream.worker_count, 3);
  EXPECT_FALSE(d.stream.use_tracker);
  EXPECT_EQ(d.stream.mvs.global.num_neighbors, 6);
  EXPECT_DOUBLE_EQ(d.stream.mvs.local.min_ncc, 0.35);
  EXPECT_EQ(d.stream.mvs.consistency.min_consistent, 2);
  EXPECT_EQ(d.stream.tracker.features.max_features, 1500);
  EXPECT_DOUBLE_EQ(d.stream.store.max_mb, 128.0);
  EXPECT_EQ(d.stream.mvs.mpgc.min_active_views, 2);
  EXPECT_EQ(d.stream.mvs.sweep.below_seeds, 7);
  // One size parameter: the working-size cap and the size keyframes are
  // kept at.
  EXPECT_EQ(d.stream.mvs.max_image_size, 320);
  EXPECT_EQ(d.stream.max_image_size, 320);

  MapParamSource q({{"publish_period", 0.5},
                    {"output_path", std::string("/tmp/x.ply")},
                    {"fusion/min_support", 2},
                    {"fusion/depth_tolerance", 0.02},
                    {"meshing/depth", 7},
                    {"meshing/min_component_faces", 20}});
  const FusionNodeOptions f = ReadFusionNodeOptions(q);
  EXPECT_DOUBLE_EQ(f.publish_period, 0.5);
  EXPECT_EQ(f.session.output_path, "/tmp/x.ply");
  EXPECT_EQ(f.session.fusion.min_support, 2);
  EXPECT_DOUBLE_EQ(f.session.fusion.depth_tolerance, 0.02);
  EXPECT_EQ(f.meshing.depth, 7);
  EXPECT_EQ(f.meshing.min_component_faces, 20);
}

// What rosparam makes of a YAML document loaded into a namespace: nested
// maps become a/b/c; scalars are typed the YAML way (bool, int, double,
// else string).
MapParamSource ParamsFromYaml(const YAML::Node& root) {
  MapParamSource out;
  std::function<void(const YAML::Node&, const std::string&)> walk =
      [&](const YAML::Node& n, const std::string& prefix) {
        for (const auto& kv : n) {
          const std::string key = prefix + kv.first.as<std::string>();
          if (kv.second.IsMap()) {
            walk(kv.second, key + "/");
            continue;
          }
          const std::string text = kv.second.Scalar();
          const bool quoted = kv.second.Tag() == "!";
          int i = 0;
          double d = 0;
          if (!quoted && (text == "true" || text == "false")) {
            out.Set(key, text == "true");
          } else if (!quoted && YAML::convert<int>::decode(kv.second, i) &&
                     text.find_first_of(".eE") == std::string::npos) {
            out.Set(key, i);
          } else if (!quoted && YAML::convert<double>::decode(kv.second, d)) {
            out.Set(key, d);
          } else {
            out.Set(key, text);
          }
        }
      };
  walk(root, "");
  return out;
}

// "mvs/mpgc/window" -> "mvs.mpgc.window".
std::string DottedKey(std::string name) {
  std::replace(name.begin(), name.end(), '/', '.');
  return name;
}

std::string Dir() { return std::string(WILD_MVS_SOURCE_DIR) + "/config/"; }

// The keys a role registers, by name.
std::set<std::string> RoleKeys(DepthRole role) {
  DepthNodeOptions o;
  o.role = role;
  OptionRegistry r;
  RegisterOptions(&r, "", &o);
  std::set<std::string> keys;
  for (const auto& opt : r.options()) keys.insert(opt.key());
  return keys;
}

// Each role registers only the keys it reads: the selector none of the
// matching's, the worker none of the camera input's or the keyframe
// selection's; together they are the standalone node's.
TEST(Params, RolesRegisterTheKeysTheyRead) {
  const std::set<std::string> standalone = RoleKeys(DepthRole::kStandalone);
  const std::set<std::string> selector = RoleKeys(DepthRole::kSelector);
  const std::set<std::string> worker = RoleKeys(DepthRole::kWorker);
  for (const char* k : {"pose_source", "image_transport", "rectified",
                        "sparse_source", "keyframe_min_baseline",
                        "max_pose_jump", "tracker.features.max_features"}) {
    EXPECT_TRUE(selector.count(k)) << k;
    EXPECT_FALSE(worker.count(k)) << k;
  }
  for (const char* k :
       {"depth_encoding", "num_threads", "lookahead", "worker_index",
        "mvs.mpgc.window", "consistency.min_consistent"}) {
    EXPECT_FALSE(selector.count(k)) << k;
    EXPECT_TRUE(worker.count(k)) << k;
  }
  for (const char* k : {"world_frame", "diagnostics_period", "max_keyframes",
                        "mvs.max_image_size"}) {
    EXPECT_TRUE(selector.count(k)) << k;
    EXPECT_TRUE(worker.count(k)) << k;
  }
  std::set<std::string> both = selector;
  both.insert(worker.begin(), worker.end());
  EXPECT_EQ(both, standalone);
  // A key of another role is unknown (warned about) and not read.
  const MapParamSource p(
      {{"pose_source", std::string("odometry")}, {"mvs/mpgc/window", 7}});
  EXPECT_EQ(UnknownDepthNodeParams(p, DepthRole::kWorker),
            std::vector<std::string>{"pose_source"});
  EXPECT_EQ(ReadDepthNodeOptions(p, DepthRole::kWorker).pose_source, "tf");
  EXPECT_EQ(UnknownDepthNodeParams(p, DepthRole::kSelector),
            std::vector<std::string>{"mvs/mpgc/window"});
  EXPECT_EQ(
      ReadDepthNodeOptions(p, DepthRole::kSelector).stream.mvs.mpgc.window,
      MpgcOptions().window);
  // The role sets the stream's part and whether it tracks.
  const DepthNodeOptions sel =
      ReadDepthNodeOptions(MapParamSource(), DepthRole::kSelector);
  EXPECT_TRUE(sel.stream.select_keyframes);
  EXPECT_FALSE(sel.stream.reconstruct);
  EXPECT_TRUE(sel.stream.use_tracker);
  const DepthNodeOptions wrk =
      ReadDepthNodeOptions(MapParamSource(), DepthRole::kWorker);
  EXPECT_FALSE(wrk.stream.select_keyframes);
  EXPECT_TRUE(wrk.stream.reconstruct);
  EXPECT_FALSE(wrk.stream.use_tracker);
  EXPECT_STREQ(RoleName(DepthRole::kWorker), "worker");
}

// Each role's config file (generated: test/ros/test_config_files.sh) loads
// without an unknown key and lists every key of the role.
TEST(Params, RoleConfigFilesListTheRolesKeys) {
  for (DepthRole role :
       {DepthRole::kStandalone, DepthRole::kSelector, DepthRole::kWorker}) {
    const MapParamSource file =
        ParamsFromYaml(YAML::LoadFile(Dir() + ConfigFileName(role)));
    EXPECT_TRUE(UnknownDepthNodeParams(file, role).empty()) << RoleName(role);
    ReadDepthNodeOptions(file, role);  // valid
    std::set<std::string> names;
    for (const std::string& n : file.Names()) names.insert(DottedKey(n));
    EXPECT_EQ(names, RoleKeys(role)) << RoleName(role);
  }
}

// The config files list every parameter with its default (they are
// generated: test/ros/test_config_files.sh); loaded as rosparam would, every
// key is known and the values read back to the defaults.
TEST(Params, ConfigFilesLoadAsTheDefaults) {
  const MapParamSource depth =
      ParamsFromYaml(YAML::LoadFile(Dir() + "depth_node.yaml"));
  EXPECT_TRUE(UnknownDepthNodeParams(depth, DepthRole::kStandalone).empty());
  const DepthNodeOptions d =
      ReadDepthNodeOptions(depth, DepthRole::kStandalone);
  EXPECT_EQ(d.stream.mvs.mpgc.window, MpgcOptions().window);
  const MapParamSource fusion =
      ParamsFromYaml(YAML::LoadFile(Dir() + "fusion_node.yaml"));
  EXPECT_TRUE(UnknownFusionNodeParams(fusion).empty());
  const FusionNodeOptions f = ReadFusionNodeOptions(fusion);
  // The fusion node's memory budgets are below the core's (CLI) defaults.
  EXPECT_DOUBLE_EQ(f.session.map_store_mb, 256.0);
  EXPECT_LT(f.session.fusion.map_cache_mb, FusionOptions().map_cache_mb);
  EXPECT_LT(f.session.fusion.pending_mb, FusionOptions().pending_mb);
  EXPECT_FALSE(f.session.fusion.bbox_min[0].has_value());
  // Every parameter is in the file.
  DepthNodeOptions o;
  OptionRegistry r;
  RegisterOptions(&r, "", &o);
  for (const auto& opt : r.options()) {
    ParamSource::Value v;
    EXPECT_TRUE(depth.Lookup(ParamName(opt.key()), &v)) << opt.key();
  }
}

// The depth node registers only the keys it reads, at most 40: its own, the
// stream's and the core thresholds of kStreamCoreKeys.
TEST(Params, DepthNodeKeys) {
  DepthNodeOptions o;
  OptionRegistry r;
  RegisterOptions(&r, "", &o);
  EXPECT_LE(r.options().size(), 40u);
  for (const char* k : kStreamCoreKeys) EXPECT_TRUE(r.Has(k)) << k;
  // Tuning knobs whose library default is right are not parameters.
  for (const char* k :
       {"mvs.mpgc.bilateral_sigma_color", "mvs.mpgc.explain_margin",
        "mvs.mpgc.wide_drop_ncc", "mvs.local.wide_min_ncc",
        "mvs.mpgc.window_step", "consistency.max_relative_depth",
        "tracker.features.max_image_size", "tracker.scene_depth",
        "tracker.max_neighbors"})
    EXPECT_FALSE(r.Has(k)) << k;
}

// The core options of the depth node (registry over `d`'s fields) and of
// the CLI (over `mvs` and `tracker`) under the CLI's keys.
void RegisterCoreOptions(DepthNodeOptions* d, OptionRegistry* r) {
  RegisterOptions(r, "mvs", &d->stream.mvs);
  RegisterOptions(r, "consistency", &d->stream.mvs.consistency);
  RegisterOptions(r, "tracker", &d->stream.tracker);
}

// The mvs:, consistency: and tracker: sections of config/reconstruct.yaml
// (the CLI's keys) are the depth node's mvs/, consistency/ and tracker/
// parameters where the node reads them, and fusion: the fusion node's
// fusion/: a tuned section loads unchanged; the keys the node does not read
// are listed as unknown (warned about) and keep the library default.
TEST(Params, ReconstructYamlSectionsLoadIntoTheNodes) {
  const YAML::Node all = YAML::LoadFile(Dir() + "reconstruct.yaml");
  DepthNodeOptions defaults;
  OptionRegistry node_keys;
  RegisterOptions(&node_keys, "", &defaults);
  for (const char* section : {"mvs", "consistency", "tracker"}) {
    YAML::Node only;
    only[section] = all[section];
    const MapParamSource params = ParamsFromYaml(only);
    std::set<std::string> unknown;
    for (const std::string& n :
         UnknownDepthNodeParams(params, DepthRole::kStandalone))
      unknown.insert(n);
    int known = 0;
    for (const std::string& n : params.Names()) {
      const bool read = node_keys.Find(DottedKey(n)) != nullptr;
      known += read;
      EXPECT_NE(read, unknown.count(n) > 0) << n;
    }
    EXPECT_GE(known, 1) << section;
  }
  // The CLI's fusion and meshing sections are the fusion node's, key for
  // key.
  YAML::Node fusion;
  fusion["fusion"] = all["fusion"];
  fusion["meshing"] = all["meshing"];
  EXPECT_TRUE(UnknownFusionNodeParams(ParamsFromYaml(fusion)).empty());

  const std::string tuned =
      "mvs:\n"
      "  global: {num_neighbors: 6}\n"
      "  local: {num_active: 5, min_ncc: 0.25}\n"
      "  mpgc: {window: 7, drop_ncc: 0.5, min_active_views: 2,\n"
      "         bilateral_sigma_color: 8}\n"
      "  sweep: {below_seeds: 4}\n"
      "consistency: {min_consistent: 2, max_relative_depth: 0.02}\n"
      "tracker:\n"
      "  features: {max_image_size: 1000, max_features: 1234}\n"
      "  min_track_length: 3\n";
  // The CLI's reading of the text ...
  MvsOptions mvs;
  TrackerOptions tracker;
  OptionRegistry cli;
  RegisterOptions(&cli, "mvs", &mvs);
  RegisterOptions(&cli, "consistency", &mvs.consistency);
  RegisterOptions(&cli, "tracker", &tracker);
  LoadOptionsYamlString(&cli, tuned, "tuned");
  // ... and the depth node's (rosparam load into its namespace).
  const MapParamSource params = ParamsFromYaml(YAML::Load(tuned));
  const DepthNodeOptions d =
      ReadDepthNodeOptions(params, DepthRole::kStandalone);
  DepthNodeOptions node = d;
  OptionRegistry r, core, library;
  RegisterOptions(&r, "", &node);
  RegisterCoreOptions(&node, &core);
  RegisterCoreOptions(&defaults, &library);
  const std::vector<std::string> unknown =
      UnknownDepthNodeParams(params, DepthRole::kStandalone);
  for (const auto& o : cli.options()) {
    if (r.Has(o.key())) {
      EXPECT_EQ(r.Find(o.key())->Text(), o.Text()) << o.key();
    } else {
      // Not read: the library default, and named when it was set.
      EXPECT_EQ(core.Find(o.key())->Text(), library.Find(o.key())->Text())
          << o.key();
      ParamSource::Value v;
      EXPECT_EQ(
          params.Lookup(ParamName(o.key()), &v),
          std::count(unknown.begin(), unknown.end(), ParamName(o.key())) == 1)
          << o.key();
    }
  }
  EXPECT_EQ(unknown.size(), 3u);  // feature size, bilateral, relative depth
  EXPECT_EQ(d.stream.mvs.mpgc.window, 7);
  EXPECT_DOUBLE_EQ(d.stream.mvs.mpgc.drop_ncc, 0.5);
  EXPECT_DOUBLE_EQ(d.stream.mvs.local.min_ncc, 0.25);
  EXPECT_EQ(d.stream.mvs.local.num_active, 5);
  EXPECT_EQ(d.stream.mvs.sweep.below_seeds, 4);
  EXPECT_EQ(d.stream.mvs.consistency.min_consistent, 2);
  EXPECT_EQ(d.stream.tracker.features.max_features, 1234);
  EXPECT_EQ(d.stream.tracker.features.max_image_size,
            FeatureOptions().max_image_size);
  EXPECT_DOUBLE_EQ(d.stream.mvs.mpgc.bilateral_sigma_color,
                   MpgcOptions().bilateral_sigma_color);
}

TEST(Params, RangesAgreeWithCheck) {
  test::ExpectRangesAgreeWithCheck<DepthNodeOptions>(
      [](DepthNodeOptions* o, OptionRegistry* r) {
        RegisterOptions(r, "", o);
      });
  test::ExpectRangesAgreeWithCheck<FusionNodeOptions>(
      [](FusionNodeOptions* o, OptionRegistry* r) {
        RegisterOptions(r, "", o);
      });
}

std::string ErrorOf(const MapParamSource& p) {
  try {
    ReadDepthNodeOptions(p, DepthRole::kStandalone);
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
  EXPECT_NE(
      ErrorOf(MapParamSource({{"mvs/local/min_ncc", 3.0}})).find("min_ncc"),
      std::string::npos);
  // Check()'s message: the window must be odd.
  EXPECT_NE(ErrorOf(MapParamSource({{"mvs/mpgc/window", 4}})).find("odd"),
            std::string::npos);
  EXPECT_NE(ErrorOf(MapParamSource({{"tf_timeout", 99.0}})).find("tf_timeout"),
            std::string::npos);
  EXPECT_NE(ErrorOf(MapParamSource({{"mvs/max_image_size", 8}}))
                .find("mvs.max_image_size"),
            std::string::npos);
  MapParamSource f({{"fusion/min_support", 0}});
  EXPECT_THROW(ReadFusionNodeOptions(f), Error);
  // Reset policy of the fusion node: keep or reset, nothing else.
  EXPECT_EQ(ReadFusionNodeOptions(
                MapParamSource({{"on_new_session", std::string("reset")}}))
                .session.on_new_session,
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
  const auto unknown = UnknownDepthNodeParams(p, DepthRole::kStandalone);
  ASSERT_EQ(unknown.size(), 1u);
  EXPECT_EQ(unknown[0], "keyframe_min_angel");
  // The keys before the registry (renamed: docs/ROS.md) are unknown now.
  EXPECT_EQ(
      UnknownDepthNodeParams(MapParamSource({{"mvs/window", 5},
                                             {"mvs/rescaling", true},
                                             {"mvs/local_view_selection", true},
                                             {"mvs/sweep_step", 8},
                                             {"tracker/feature_downscale", 1.0},
                                             {"mvs/mpgc/window", 5}}),
                             DepthRole::kStandalone)
          .size(),
      5u);
  // Fixed in the node now (named constants) or one key for both sizes.
  EXPECT_EQ(UnknownDepthNodeParams(MapParamSource({{"error_throttle", 5.0},
                                                   {"drop_window", 60.0},
                                                   {"repair_delay", 1.0},
                                                   {"max_image_size", 320}}),
                                   DepthRole::kStandalone)
                .size(),
            4u);
  // Core options the node leaves at the library default.
  EXPECT_EQ(UnknownDepthNodeParams(
                MapParamSource({{"mvs/mpgc/explain_margin", 0.1},
                                {"mvs/mpgc/window_step", 1},
                                {"tracker/scene_depth", 3.0},
                                {"consistency/free_space_margin", 0.02}}),
                DepthRole::kStandalone)
                .size(),
            4u);
  EXPECT_TRUE(
      UnknownFusionNodeParams(MapParamSource({{"fusion/min_support", 3}}))
          .empty());
}

}  // namespace
}  // namespace ros1
}  // namespace wild_mvs
