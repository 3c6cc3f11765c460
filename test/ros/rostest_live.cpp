// Copyright wild_mvs authors. rostest (test/ros/live.test): the depth
// node's live parameters through dynamic_reconfigure's protocol, driven by
// its own command-line tool (dynparam, as rqt_reconfigure drives it): a
// valid change reaches ~parameter_updates and the parameter server, a value
// that Check() refuses is not taken, and ~reset clears the keyframes.
#include <dynamic_reconfigure/Config.h>
#include <dynamic_reconfigure/ConfigDescription.h>
#include <gtest/gtest.h>
#include <ros/ros.h>
#include <std_srvs/Trigger.h>

#include <cstdlib>
#include <filesystem>
#include <mutex>

#include "ros_test_scene.h"
#include "rostest_util.h"
#include "test_paths.h"
#include "wild_mvs/ros/scene_bag.h"

namespace wild_mvs {
namespace testing {
namespace {

double DoubleOf(const dynamic_reconfigure::Config& c, const std::string& n) {
  for (const auto& p : c.doubles)
    if (p.name == n) return p.value;
  return -1;
}

int Dynparam(const std::string& args) {
  // The system's python3 first (dynparam is `#!/usr/bin/env python3` and
  // needs Debian's ROS modules), as the other script tests do.
  const std::string cmd =
      "PATH=/usr/local/sbin:/usr/local/bin:/usr/sbin:/usr/bin:/sbin:/bin:$PATH "
      "rosrun dynamic_reconfigure dynparam " +
      args + " >/dev/null 2>&1";
  return std::system(cmd.c_str());
}

TEST(Live, DynparamTunesRefusesAndResets) {
  ros::NodeHandle nh;
  std::mutex mutex;
  dynamic_reconfigure::ConfigDescription description;
  dynamic_reconfigure::Config update;
  int updates = 0;
  ros::Subscriber dsub = nh.subscribe<dynamic_reconfigure::ConfigDescription>(
      "/depth_node/parameter_descriptions", 1,
      [&](const dynamic_reconfigure::ConfigDescriptionConstPtr& m) {
        std::lock_guard<std::mutex> lock(mutex);
        description = *m;
      });
  ros::Subscriber usub = nh.subscribe<dynamic_reconfigure::Config>(
      "/depth_node/parameter_updates", 1,
      [&](const dynamic_reconfigure::ConfigConstPtr& m) {
        std::lock_guard<std::mutex> lock(mutex);
        update = *m;
        ++updates;
      });
  DiagnosticsWatch diag(nh);
  ros::AsyncSpinner spinner(2);
  spinner.start();
  ASSERT_TRUE(
      ros::service::waitForService("/depth_node/set_parameters", 60000));
  ASSERT_TRUE(WaitFor(
      [&] {
        std::lock_guard<std::mutex> lock(mutex);
        return !description.groups.empty() && updates > 0;
      },
      30));
  {
    std::lock_guard<std::mutex> lock(mutex);
    bool found = false;
    for (const auto& p : description.groups[0].parameters)
      found |= p.name == "keyframe_min_baseline" && p.type == "double";
    EXPECT_TRUE(found);
    EXPECT_DOUBLE_EQ(DoubleOf(description.min, "mvs/mpgc/drop_ncc"), -1.0);
    EXPECT_DOUBLE_EQ(DoubleOf(description.max, "mvs/mpgc/drop_ncc"), 1.0);
  }

  // A valid change.
  ASSERT_EQ(Dynparam("set /depth_node keyframe_min_baseline 0.125"), 0);
  double v = 0;
  ASSERT_TRUE(WaitFor(
      [&] {
        std::lock_guard<std::mutex> lock(mutex);
        return DoubleOf(update, "keyframe_min_baseline") == 0.125;
      },
      30));
  ASSERT_TRUE(nh.getParam("/depth_node/keyframe_min_baseline", v));
  EXPECT_DOUBLE_EQ(v, 0.125);

  // Out of Check()'s range: refused, the old value stays everywhere.
  double drop_before = 0;
  ASSERT_TRUE(nh.getParam("/depth_node/mvs/mpgc/drop_ncc", drop_before));
  const int updates_before = updates;
  Dynparam("set /depth_node mvs/mpgc/drop_ncc 5.0");
  ASSERT_TRUE(WaitFor([&] { return updates > updates_before; }, 30));
  {
    std::lock_guard<std::mutex> lock(mutex);
    EXPECT_DOUBLE_EQ(DoubleOf(update, "mvs/mpgc/drop_ncc"), drop_before);
    EXPECT_DOUBLE_EQ(DoubleOf(update, "keyframe_min_baseline"), 0.125);
  }
  ASSERT_TRUE(nh.getParam("/depth_node/mvs/mpgc/drop_ncc", v));
  EXPECT_DOUBLE_EQ(v, drop_before);

  // ~reset: keyframes of a played bag are cleared, a new session counted.
  const SyntheticScene scene = Render(RosTestSpec(4));
  const std::string dir = MakeTempDir("wild_mvs_rostest_live");
  ros1::SceneBagOptions bo;
  bo.rate = 4.0;
  ros1::WriteSceneBag(
      scene.scene, [&](int i) { return ros1::LinearToSrgb8(scene.images[i]); },
      dir + "/scene.bag", bo);
  PlayBag(dir + "/scene.bag", 1.0).join();
  ASSERT_TRUE(WaitFor(
      [&] { return diag.Get("depth_node", "keyframes held") >= 2; }, 60))
      << diag.Dump("depth_node");
  const long resets = diag.Get("depth_node", "stream resets");
  ros::ServiceClient reset =
      nh.serviceClient<std_srvs::Trigger>("/depth_node/reset");
  std_srvs::Trigger srv;
  ASSERT_TRUE(reset.call(srv));
  EXPECT_TRUE(srv.response.success);
  EXPECT_TRUE(WaitFor(
      [&] {
        return diag.Get("depth_node", "keyframes held") == 0 &&
               diag.Get("depth_node", "stream resets") == resets + 1;
      },
      30))
      << diag.Dump("depth_node");
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace testing
}  // namespace wild_mvs

int main(int argc, char** argv) {
  ::testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "rostest_live");
  return RUN_ALL_TESTS();
}
