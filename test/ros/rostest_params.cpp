// Copyright wild_mvs authors. Checker of test/ros/params.test: config files
// in the CLI's format, loaded with rosparam into this node's private
// namespace, read through the parameter server (RosParamSource) give the
// nodes the same option values as `wild_mvs reconstruct --config` gives the
// CLI.
#include <gtest/gtest.h>
#include <ros/ros.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "wild_mvs/cli/option_set.h"
#include "wild_mvs/cli/reconstruct_config.h"
#include "wild_mvs/ros/params.h"
#include "wild_mvs/ros/params_ros.h"

namespace wild_mvs {
namespace ros1 {
namespace {

// Every CLI key of `section` that the node reads has the node's value
// (Text()); the ones it does not read are named by `unknown` when the files
// set them (`params`), and `library` (the node's fields under the CLI's
// keys, against `defaults`, the same of default options) keeps the library
// default.
void ExpectSameValues(const cli::OptionSet& cli, const OptionRegistry& node,
                      const std::string& section, int min_compared = 5,
                      const OptionRegistry* library = nullptr,
                      const OptionRegistry* defaults = nullptr,
                      const ParamSource* params = nullptr,
                      const std::vector<std::string>& unknown = {}) {
  int n = 0;
  for (const auto& o : cli.options()) {
    if (o.key().rfind(section + ".", 0) != 0) continue;
    const OptionRegistry::Option* x = node.Find(o.key());
    if (x == nullptr && library != nullptr) {
      EXPECT_EQ(library->Find(o.key())->Text(), defaults->Find(o.key())->Text())
          << o.key();
      ParamSource::Value v;
      const std::string name = ParamName(o.key());
      EXPECT_EQ(params->Lookup(name, &v),
                std::count(unknown.begin(), unknown.end(), name) == 1)
          << o.key();
      continue;
    }
    ++n;
    ASSERT_NE(x, nullptr) << o.key() << " is not a node parameter";
    EXPECT_EQ(x->Text(), o.Text()) << o.key();
  }
  EXPECT_GE(n, min_compared) << section;  // the section was compared, not empty
}

// The core options under the CLI's keys over the depth node's fields.
void RegisterCoreOptions(DepthNodeOptions* d, OptionRegistry* r) {
  RegisterOptions(r, "mvs", &d->stream.mvs);
  RegisterOptions(r, "consistency", &d->stream.mvs.consistency);
  RegisterOptions(r, "tracker", &d->stream.tracker);
}

TEST(Params, ReconstructYamlLoadsIntoTheNodes) {
  const std::string pkg = WILD_MVS_SOURCE_DIR;
  // The CLI's reading of the files params.test loads (in the same order).
  cli::ReconstructConfig c;
  cli::OptionSet cli;
  cli::RegisterOptions(&c, &cli);
  cli.LoadYamlFile(pkg + "/config/reconstruct.yaml");
  cli.LoadYamlFile(pkg + "/test/ros/tuned_reconstruct.yaml");
  c.Check();
  ASSERT_EQ(c.mvs.mpgc.window, 7);  // the tuned file was read

  ros::NodeHandle pnh("~");
  double drop = 0;
  ASSERT_TRUE(pnh.getParam("mvs/mpgc/drop_ncc", drop));
  EXPECT_DOUBLE_EQ(drop, 0.5);
  const RosParamSource params(pnh);

  DepthNodeOptions d = ReadDepthNodeOptions(params, DepthRole::kStandalone);
  DepthNodeOptions defaults;
  OptionRegistry depth, library, library_defaults;
  RegisterOptions(&depth, "", &d);
  RegisterCoreOptions(&d, &library);
  RegisterCoreOptions(&defaults, &library_defaults);
  const std::vector<std::string> unknown =
      UnknownDepthNodeParams(params, DepthRole::kStandalone);
  for (const char* section : {"mvs", "consistency", "tracker"})
    ExpectSameValues(cli, depth, section, 1, &library, &library_defaults,
                     &params, unknown);
  EXPECT_EQ(d.stream.mvs.mpgc.min_active_views, 2);
  EXPECT_EQ(d.stream.mvs.sweep.below_seeds, 4);
  EXPECT_DOUBLE_EQ(d.stream.mvs.local.min_ncc, 0.25);
  EXPECT_EQ(d.stream.tracker.min_track_length, 3);
  // tracker.features.max_image_size is not a depth node parameter: named,
  // and the node keeps the library default.
  EXPECT_EQ(std::count(unknown.begin(), unknown.end(),
                       "tracker/features/max_image_size"),
            1);
  EXPECT_EQ(d.stream.tracker.features.max_image_size,
            FeatureOptions().max_image_size);
  // The other sections of reconstruct.yaml are the CLI's (reported as
  // unknown, not errors), and so are the core's keys the node does not
  // read: every unknown name is a key of the CLI.
  OptionRegistry all_cli;
  cli::ReconstructConfig any;
  cli::RegisterOptions(&any, &all_cli);
  for (const std::string& name : unknown) {
    std::string key = name;
    std::replace(key.begin(), key.end(), '/', '.');
    EXPECT_TRUE(all_cli.Has(key)) << name;
    EXPECT_FALSE(depth.Has(key)) << name;
  }

  FusionNodeOptions f = ReadFusionNodeOptions(params);
  OptionRegistry fusion;
  RegisterOptions(&fusion, "", &f);
  ExpectSameValues(cli, fusion, "fusion");  // bbox .inf included
  EXPECT_EQ(f.session.fusion.min_support, 2);
  EXPECT_EQ(f.session.fusion.bbox_max[2], std::optional<double>(10.0));
  EXPECT_FALSE(f.session.fusion.bbox_min[0].has_value());
}

// The depth node started with depth_node.yaml + the tuned file comes up
// (a bad parameter would stop it before it advertises its outputs).
TEST(Params, TunedDepthNodeStarts) {
  ros::NodeHandle nh;
  const ros::WallTime end = ros::WallTime::now() + ros::WallDuration(30);
  bool up = false;
  while (!up && ros::WallTime::now() < end && ros::ok()) {
    ros::master::V_TopicInfo topics;
    ros::master::getTopics(topics);
    for (const auto& t : topics) up |= t.name == "/tuned_depth/depth_view";
    ros::WallDuration(0.2).sleep();
  }
  EXPECT_TRUE(up) << "/tuned_depth/depth_view never appeared";
  int window = 0;
  EXPECT_TRUE(nh.getParam("/tuned_depth/mvs/mpgc/window", window));
  EXPECT_EQ(window, 7);
}

}  // namespace
}  // namespace ros1
}  // namespace wild_mvs

int main(int argc, char** argv) {
  ::testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "rostest_params");
  return RUN_ALL_TESTS();
}
