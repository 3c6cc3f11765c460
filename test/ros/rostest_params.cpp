// Copyright wild_mvs authors. Checker of test/ros/params.test: config files
// in the CLI's format, loaded with rosparam into this node's private
// namespace, read through the parameter server (RosParamSource) give the
// nodes the same option values as `wild_mvs reconstruct --config` gives the
// CLI.
#include <gtest/gtest.h>
#include <ros/ros.h>

#include <cmath>
#include <string>

#include "wild_mvs/cli/option_set.h"
#include "wild_mvs/cli/reconstruct_config.h"
#include "wild_mvs/ros/params.h"
#include "wild_mvs/ros/params_ros.h"

namespace wild_mvs {
namespace ros1 {
namespace {

// Every CLI key of `section` has the node's value (Text()).
void ExpectSameValues(const cli::OptionSet& cli, const OptionRegistry& node,
                      const std::string& section) {
  int n = 0;
  for (const auto& o : cli.options()) {
    if (o.key().rfind(section + ".", 0) != 0) continue;
    ++n;
    const OptionRegistry::Option* x = node.Find(o.key());
    ASSERT_NE(x, nullptr) << o.key() << " is not a node parameter";
    EXPECT_EQ(x->Text(), o.Text()) << o.key();
  }
  EXPECT_GE(n, 5) << section;  // the section was compared, not empty
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

  DepthNodeOptions d = ReadDepthNodeOptions(params);
  OptionRegistry depth;
  RegisterOptions(&depth, "", &d);
  ExpectSameValues(cli, depth, "mvs");
  ExpectSameValues(cli, depth, "tracker");
  EXPECT_EQ(d.stream.mvs.mpgc.min_active_views, 2);
  EXPECT_EQ(d.stream.mvs.sweep.below_seeds, 4);
  EXPECT_DOUBLE_EQ(d.stream.mvs.local.min_ncc, 0.25);
  // The depth node knows every mvs/ and tracker/ key; the other sections of
  // reconstruct.yaml are the CLI's (reported as unknown, not errors).
  for (const std::string& name : UnknownDepthNodeParams(params)) {
    EXPECT_TRUE(name.rfind("run/", 0) == 0 || name.rfind("image/", 0) == 0 ||
                name.rfind("consistency/", 0) == 0 ||
                name.rfind("ablation/", 0) == 0 ||
                name.rfind("fusion/", 0) == 0 || name.rfind("meshing/", 0) == 0)
        << name;
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
