// Copyright wild_mvs authors. rostest (test/ros/shutdown.test): roslaunch
// ends a node with SIGINT and escalates to SIGTERM and SIGKILL after 15 s.
// A depth node interrupted while it computes a large depth map must end
// before that (the map is cancelled), and the fusion node must save the
// views it fused to ~output_path before it ends.
#include <gtest/gtest.h>
#include <ros/ros.h>
#include <signal.h>
#include <wild_mvs/DepthView.h>

#include <atomic>
#include <filesystem>

#include "ros_test_scene.h"
#include "rostest_util.h"
#include "test_paths.h"
#include "wild_mvs/ros/scene_bag.h"

namespace wild_mvs {
namespace testing {
namespace {

namespace fs = std::filesystem;

// roslaunch's _TIMEOUT_SIGINT: after it, SIGTERM, then SIGKILL.
constexpr double kEscalationSeconds = 15.0;

// Seconds until process `pid` has ended (at most `limit`; then `limit`).
double SecondsToExit(int pid, double limit) {
  const ros::WallTime t0 = ros::WallTime::now();
  WaitFor([&] { return kill(pid, 0) != 0; }, limit);
  return (ros::WallTime::now() - t0).toSec();
}

TEST(Shutdown, WithinRoslaunchEscalation) {
  ros::NodeHandle nh;
  // 960x720 frames: one depth map on one thread takes several seconds.
  SyntheticSpec spec = RosTestSpec(6);
  spec.width = 960;
  spec.height = 720;
  spec.focal = 900;
  const SyntheticScene scene = Render(spec);
  const std::string dir = MakeTempDir("wild_mvs_rostest_shutdown");
  const std::string bag = dir + "/scene.bag";
  ros1::SceneBagOptions bo;
  bo.rate = 2.0;
  bo.with_points = true;
  ros1::WriteSceneBag(
      scene.scene, [&](int i) { return ros1::LinearToSrgb8(scene.images[i]); },
      bag, bo);
  DiagnosticsWatch diag(nh);
  std::atomic<int> received{0};
  ros::Subscriber views = nh.subscribe<wild_mvs::DepthView>(
      "/depth_node/depth_view", 5,
      [&](const wild_mvs::DepthViewConstPtr&) { ++received; });
  ros::AsyncSpinner spinner(2);
  spinner.start();
  ASSERT_TRUE(WaitFor(
      [&] {
        return views.getNumPublishers() > 0 &&
               diag.Get("depth_node: depth_node", "input queue size") > 0 &&
               diag.Get("fusion_node: fusion_node", "views fused") >= 0;
      },
      60));
  PlayBag(bag, 1.0).join();
  // Views fused into a cloud (points need the support of two views), the
  // next depth map being computed.
  ASSERT_TRUE(WaitFor(
      [&] {
        return diag.Get("fusion_node: fusion_node", "points") > 1000 &&
               diag.Get("depth_node: depth_node", "depth maps running") >= 1;
      },
      240))
      << diag.Dump("depth_node: depth_node");
  const long fused = diag.Get("fusion_node: fusion_node", "views fused");
  const long done = diag.Get("depth_node: depth_node", "depth maps");

  const int depth_pid = NodePid("/depth_node");
  ASSERT_GT(depth_pid, 0);
  ASSERT_EQ(kill(depth_pid, SIGINT), 0);
  const double depth_seconds = SecondsToExit(depth_pid, 60);
  EXPECT_LT(depth_seconds, kEscalationSeconds)
      << "the depth node did not end within roslaunch's SIGINT timeout";

  std::string out;
  ASSERT_TRUE(ros::param::get("/fusion_node/output_path", out));
  // Everything the depth node published is fused (nothing more comes).
  ASSERT_TRUE(WaitFor(
      [&] {
        return diag.Get("fusion_node: fusion_node", "input queue length") ==
                   0 &&
               diag.Get("fusion_node: fusion_node",
                        "views waiting for "
                        "order") == 0;
      },
      30));
  const long points = diag.Get("fusion_node: fusion_node", "points");
  const int fusion_pid = NodePid("/fusion_node");
  ASSERT_GT(fusion_pid, 0);
  ASSERT_EQ(kill(fusion_pid, SIGINT), 0);
  const double fusion_seconds = SecondsToExit(fusion_pid, 60);
  EXPECT_LT(fusion_seconds, kEscalationSeconds)
      << "the fusion node did not end within roslaunch's SIGINT timeout";
  const long vertices = PlyVertexCount(out);
  EXPECT_GT(vertices, 1000) << "no valid PLY saved at " << out;
  EXPECT_GE(vertices, points);
  std::printf(
      "[shutdown] depth node: %ld depth maps done, SIGINT during the next "
      "one, ended after %.2f s; fusion node: %ld views fused, SIGINT, saved "
      "%ld points, ended after %.2f s\n",
      done, depth_seconds, fused, vertices, fusion_seconds);
  fs::remove_all(fs::path(out).parent_path());
  fs::remove_all(dir);
}

}  // namespace
}  // namespace testing
}  // namespace wild_mvs

int main(int argc, char** argv) {
  ::testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "rostest_shutdown");
  return RUN_ALL_TESTS();
}
