// Copyright wild_mvs authors. rostest (test/ros/faults.test): the nodes
// under faults and load, on a synthetic ring with exact ground truth.
//  1. The depth node is killed hard (SIGKILL) after the first half of the
//     stream and respawned by roslaunch: it starts a new session from the
//     new frames, the fusion node keeps fusing, the cloud stays correct.
//  2. A tf jump (two frames whose pose is 3 m off, then back): the depth
//     node resets its stream at each jump (reset policy, docs/ROS.md), no
//     depth map mixes frames from both sides, the cloud stays correct.
//  3. A long bag at 20x, looped (time going back): frames dropped by policy
//     and counted, the keyframe store and queues within their bounds, the
//     depth node's RSS under a ceiling, resets on every loop.
//  4. SIGTERM: the fusion node saves its cloud to ~output_path atomically.
#include <gtest/gtest.h>
#include <ros/ros.h>
#include <signal.h>
#include <wild_mvs/DepthView.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <mutex>
#include <set>

#include "ros_test_scene.h"
#include "rostest_util.h"
#include "test_paths.h"
#include "wild_mvs/core/metrics.h"
#include "wild_mvs/ros/scene_bag.h"

namespace wild_mvs {
namespace testing {
namespace {

namespace fs = std::filesystem;
constexpr double kRate = 4.0;
constexpr int kViews = 10;

// Frames of a bag: view index into the rendered scene and a camera-centre
// offset (a tf glitch).
struct Frame {
  int view;
  Eigen::Vector3d offset = Eigen::Vector3d::Zero();
};

void WriteBag(const SyntheticScene& s, const std::vector<Frame>& frames,
              double start_time, const std::string& path) {
  Scene scene;
  std::vector<cv::Mat> images;
  for (const Frame& f : frames) {
    View v = s.scene.views[f.view];
    v.camera.t -= v.camera.R * f.offset;  // centre moved by offset
    scene.views.push_back(v);
    images.push_back(ros1::LinearToSrgb8(s.images[f.view]));
  }
  ros1::SceneBagOptions bo;
  bo.rate = kRate;
  bo.start_time = start_time;
  ros1::WriteSceneBag(
      scene, [&](int i) { return images[i]; }, path, bo);
}

class Faults : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    // 120x90 (the other ROS tests use 160x120): keeps this long test short.
    SyntheticSpec spec = RosTestSpec(kViews);
    spec.width = 120;
    spec.height = 90;
    spec.focal = 112.5;
    scene_ = new SyntheticScene(Render(spec));
    gt_ = new PointCloud(scene_->GroundTruthCloud(1));
  }
  static void TearDownTestSuite() {
    delete scene_;
    delete gt_;
  }
  static SyntheticScene* scene_;
  static PointCloud* gt_;
};
SyntheticScene* Faults::scene_ = nullptr;
PointCloud* Faults::gt_ = nullptr;

TEST_F(Faults, RestartPoseJumpLoadAndSigtermSave) {
  ros::NodeHandle nh;
  const SyntheticScene& scene = *scene_;
  const std::string dir = MakeTempDir("wild_mvs_rostest_faults");
  std::mutex mutex;
  std::vector<wild_mvs::DepthViewConstPtr> views;
  sensor_msgs::PointCloud2ConstPtr cloud;
  ros::Subscriber s1 = nh.subscribe<wild_mvs::DepthView>(
      "/depth_node/depth_view", 50, [&](const wild_mvs::DepthViewConstPtr& m) {
        std::lock_guard<std::mutex> lock(mutex);
        views.push_back(m);
      });
  ros::Subscriber s2 = nh.subscribe<sensor_msgs::PointCloud2>(
      "/fusion_node/cloud", 2, [&](const sensor_msgs::PointCloud2ConstPtr& m) {
        std::lock_guard<std::mutex> lock(mutex);
        cloud = m;
      });
  DiagnosticsWatch diag(nh);
  ros::AsyncSpinner spinner(2);
  spinner.start();
  ASSERT_TRUE(WaitFor(
      [&] { return s1.getNumPublishers() > 0 && s2.getNumPublishers() > 0; },
      30));
  ros::WallDuration(1.0).sleep();
  auto fused = [&] { return diag.Get("fusion_node: ", "views fused"); };
  auto cloud_precision = [&](double* recall = nullptr) {
    PointCloud c;
    {
      std::lock_guard<std::mutex> lock(mutex);
      if (cloud) c = CloudFromMsg(*cloud);
    }
    CloudMetricsOptions co;
    co.taus = {0.04, 0.5};
    const CloudMetrics m = EvaluateCloud(c, *gt_, co);
    if (recall) *recall = m.recall[0];
    return std::make_pair(m.precision[0], m.precision[1]);
  };
  const double t0 = 1000.0;

  // --- 1. restart: first half, SIGKILL, respawn, second half -------------
  std::vector<Frame> first, second;
  for (int i = 0; i < kViews / 2; ++i) first.push_back({i});
  for (int i = kViews / 2; i < kViews; ++i) second.push_back({i});
  WriteBag(scene, first, t0, dir + "/first.bag");
  WriteBag(scene, second, t0 + (kViews / 2) / kRate, dir + "/second.bag");
  PlayBag(dir + "/first.bag", 1.0).join();
  ASSERT_TRUE(WaitFor([&] { return fused() >= 3; }, 90))
      << diag.Dump("depth_node") << diag.Dump("fusion_node: ");
  const int pid1 = NodePid("/depth_node");
  ASSERT_GT(pid1, 0);
  ASSERT_EQ(kill(pid1, SIGKILL), 0);
  int pid2 = -1;
  ASSERT_TRUE(WaitFor(
      [&] {
        pid2 = NodePid("/depth_node");
        return pid2 > 0 && pid2 != pid1 && s1.getNumPublishers() > 0;
      },
      30))
      << "depth_node was not respawned";
  ros::WallDuration(1.5).sleep();  // subscriptions of the new node
  const long fused_before = fused();
  size_t views_before = 0;
  {
    std::lock_guard<std::mutex> lock(mutex);
    views_before = views.size();
  }
  PlayBag(dir + "/second.bag", 1.0).join();
  ASSERT_TRUE(WaitFor([&] { return fused() >= fused_before + 3; }, 90))
      << diag.Dump("depth_node") << diag.Dump("fusion_node: ");
  {
    std::lock_guard<std::mutex> lock(mutex);
    // The respawned node's views: one new session starting at the first
    // frame it used (the first frames of the second bag can be missed while
    // its subscriptions connect: within 1 s), neighbours only from its own
    // frames.
    const double second_start = t0 + (kViews / 2) / kRate;
    std::set<uint64_t> sessions;
    for (size_t i = views_before; i < views.size(); ++i) {
      const auto& v = *views[i];
      EXPECT_GE(v.header.stamp.toSec(), second_start - 1e-6);
      EXPECT_GE(v.session.toSec(), second_start - 1e-6);
      EXPECT_LE(v.session.toSec(), second_start + 1.0 + 1e-6);
      EXPECT_GE(v.header.stamp.toSec(), v.session.toSec() - 1e-6);
      sessions.insert(v.session.toNSec());
      for (const ros::Time& n : v.neighbor_stamps)
        EXPECT_GE(n.toSec(), v.session.toSec() - 1e-6);
    }
    EXPECT_EQ(sessions.size(), 1u) << "the respawned node changed session";
  }
  EXPECT_GE(diag.Get("fusion_node: ", "depth sessions"), 2);
  // on_new_session: reset (the second fusion node): the first session's
  // cloud was saved to <output stem>_session0.ply, then a new cloud began.
  {
    std::string reset_out;
    ASSERT_TRUE(ros::param::get("/fusion_reset/output_path", reset_out));
    const std::string session0 =
        reset_out.substr(0, reset_out.size() - 4) + "_session0.ply";
    EXPECT_TRUE(WaitFor([&] { return fs::exists(session0); }, 10)) << session0;
    EXPECT_GT(PlyVertexCount(session0), 100)
        << session0;  // >= 3 views fused (min_support 3)
    EXPECT_GE(diag.Get("fusion_reset: ", "resets"), 1)
        << diag.Dump("fusion_reset: ");
    EXPECT_LT(diag.Get("fusion_reset: ", "points"),
              diag.Get("fusion_node: ", "points"));
    fs::remove_all(fs::path(reset_out).parent_path());
  }
  ros::WallDuration(1.0).sleep();  // the cloud after the last view
  double recall = 0;
  auto [p4, p50] = cloud_precision(&recall);
  std::printf(
      "[faults] after restart: %ld views fused, precision@4cm %.3f, "
      "@50cm %.4f, recall@4cm %.3f\n",
      fused(), p4, p50, recall);
  EXPECT_GT(p4, 0.9);
  EXPECT_GT(p50, 0.995);

  // --- 2. tf jump: frames 2 and 3 are 3 m off, then the pose is right ----
  std::vector<Frame> jump;
  for (int i = 0; i < 8; ++i) jump.push_back({i});
  jump[2].offset = jump[3].offset = Eigen::Vector3d(3.0, 0.0, 0.0);
  const double t_jump = t0 + kViews / kRate + 1.0;
  WriteBag(scene, jump, t_jump, dir + "/jump.bag");
  const long resets_before = diag.Get("depth_node", "stream resets");
  const long fused_before_jump = fused();
  {
    std::lock_guard<std::mutex> lock(mutex);
    views_before = views.size();
  }
  PlayBag(dir + "/jump.bag", 1.0).join();
  ASSERT_TRUE(WaitFor(
      [&] {
        return diag.Get("depth_node", "stream resets") >= resets_before + 2 &&
               fused() >= fused_before_jump + 2;
      },
      90))
      << diag.Dump("depth_node") << diag.Dump("fusion_node: ");
  WaitFor(
      [&] { return diag.Get("depth_node", "reconstructions pending") == 0; },
      30);
  {
    std::lock_guard<std::mutex> lock(mutex);
    const double jump_start = t_jump + 2 / kRate, jump_end = t_jump + 4 / kRate;
    for (size_t i = views_before; i < views.size(); ++i) {
      const auto& v = *views[i];
      const double s = v.header.stamp.toSec();
      // The glitched frames never make a depth map (2 keyframes in their
      // session), and nothing after the jump back uses frames before it.
      EXPECT_TRUE(s < jump_start - 1e-6 || s > jump_end - 1e-6)
          << "depth map of a glitched frame at " << s;
      if (s > jump_end - 1e-6) {
        EXPECT_NEAR(v.session.toSec(), jump_end, 1e-6) << "view at " << s;
        for (const ros::Time& n : v.neighbor_stamps)
          EXPECT_GE(n.toSec(), jump_end - 1e-6) << "view at " << s;
      } else {
        for (const ros::Time& n : v.neighbor_stamps)
          EXPECT_LT(n.toSec(), jump_start - 1e-6) << "view at " << s;
      }
    }
  }
  ros::WallDuration(1.0).sleep();
  std::tie(p4, p50) = cloud_precision(&recall);
  std::printf(
      "[faults] after the tf jump: %ld views fused, %ld resets, "
      "precision@4cm %.3f, @50cm %.4f\n",
      fused(), diag.Get("depth_node", "stream resets"), p4, p50);
  EXPECT_GT(p4, 0.9);
  EXPECT_GT(p50, 0.995);  // no points 3 m off

  // --- 3. load: 40 frames back and forth along the ring at 20x, looped ---
  std::vector<Frame> long_bag;
  for (int k = 0; k < 40; ++k) {
    const int period = 2 * (kViews - 1), m = k % period;
    long_bag.push_back({m < kViews ? m : period - m});
  }
  const double t_load = t_jump + 8 / kRate + 1.0;
  WriteBag(scene, long_bag, t_load, dir + "/long.bag");
  const long dropped_before = diag.Get("depth_node", "frames dropped");
  const long resets_before_load = diag.Get("depth_node", "stream resets");
  const int depth_pid = NodePid("/depth_node");
  long max_held = 0, max_queue = 0, max_pending = 0, max_fusion_queue = 0;
  double max_store_mb = 0;
  std::thread player([&] {
    // 10 s of bag at 20x = 0.5 s per pass; `timeout` ends the loop.
    const std::string cmd = "timeout -s INT 6 rosbag play --quiet -l -r 20 '" +
                            dir + "/long.bag' >/dev/null 2>&1";
    (void)std::system(cmd.c_str());
  });
  const ros::WallTime load_end = ros::WallTime::now() + ros::WallDuration(7.0);
  while (ros::WallTime::now() < load_end) {
    max_held = std::max(max_held, diag.Get("depth_node", "keyframes held"));
    max_queue =
        std::max(max_queue, diag.Get("depth_node", "input queue length"));
    max_pending = std::max(max_pending,
                           diag.Get("depth_node", "reconstructions pending"));
    max_fusion_queue = std::max(
        max_fusion_queue, diag.Get("fusion_node: ", "input queue length"));
    max_store_mb = std::max(
        max_store_mb,
        std::atof(diag.Values("depth_node")["keyframe store MB"].c_str()));
    ros::WallDuration(0.1).sleep();
  }
  player.join();
  const long dropped =
      diag.Get("depth_node", "frames dropped") - dropped_before;
  const long resets =
      diag.Get("depth_node", "stream resets") - resets_before_load;
  const double depth_rss = PeakRssMb(depth_pid);
  std::printf(
      "[faults] load (20x, looped): %ld frames dropped, %ld resets, "
      "max keyframes held %ld (%.1f MB), max queue %ld, max pending "
      "%ld, max fusion queue %ld; depth_node peak RSS %.0f MB\n%s",
      dropped, resets, max_held, max_store_mb, max_queue, max_pending,
      max_fusion_queue, depth_rss, diag.Dump("depth_node").c_str());
  EXPECT_GT(dropped, 0) << "no frame dropped at 20x";
  EXPECT_GT(diag.Dropped("depth_node", "input queue full"), 0);
  EXPECT_GE(resets, 1) << "bag loop (time going back) did not reset";
  EXPECT_LE(max_held, 10);    // max_keyframes
  EXPECT_LE(max_queue, 5);    // input_queue_size
  EXPECT_LE(max_pending, 2);  // max_pending
  EXPECT_LE(max_fusion_queue, 10);
  EXPECT_GT(depth_rss, 0);
  // RSS ceiling about 2x the measured peak (94-95 MB; docs/ROS.md).
  EXPECT_LT(depth_rss, 200.0);
  // The nodes are still up and the cloud is still right.
  EXPECT_EQ(NodePid("/depth_node"), depth_pid);
  WaitFor(
      [&] { return diag.Get("depth_node", "reconstructions pending") == 0; },
      60);
  ros::WallDuration(1.5).sleep();
  std::tie(p4, p50) = cloud_precision(&recall);
  EXPECT_GT(p4, 0.9);
  EXPECT_GT(p50, 0.995);

  // --- 4. SIGTERM: the fusion node saves to ~output_path atomically ------
  std::string out;
  ASSERT_TRUE(ros::param::get("/fusion_node/output_path", out));
  // The fusion node may still be fusing the last depth maps: read its point
  // count once it has stopped changing (two diagnostics reports apart).
  long points = diag.Get("fusion_node: ", "points");
  WaitFor(
      [&] {
        ros::WallDuration(2.5).sleep();
        const long now = diag.Get("fusion_node: ", "points");
        const bool stable = now == points;
        points = now;
        return stable;
      },
      60);
  fs::create_directories(fs::path(out).parent_path());
  {
    std::ofstream old(out);
    old << "an earlier result\n";
  }
  const int fusion_pid = NodePid("/fusion_node");
  ASSERT_GT(fusion_pid, 0);
  const double fusion_rss = PeakRssMb(fusion_pid);
  ASSERT_EQ(kill(fusion_pid, SIGTERM), 0);
  ASSERT_TRUE(WaitFor([&] { return kill(fusion_pid, 0) != 0; }, 60))
      << "fusion node did not exit on SIGTERM";
  const long vertices = PlyVertexCount(out);
  EXPECT_GT(vertices, 1000) << "no valid PLY saved at " << out;
  EXPECT_NEAR(vertices, points, points * 0.05 + 10);
  for (const auto& e : fs::directory_iterator(fs::path(out).parent_path()))
    EXPECT_EQ(e.path().filename().string().find(".tmp"), std::string::npos)
        << "temporary file left: " << e.path();
  std::printf(
      "[faults] SIGTERM: fusion node saved %ld points (diagnostics: "
      "%ld); peak RSS fusion_node %.0f MB\n",
      vertices, points, fusion_rss);
  // RSS ceiling about 2x the measured peak (91-101 MB; docs/ROS.md).
  EXPECT_GT(fusion_rss, 0);
  EXPECT_LT(fusion_rss, 200.0);
  fs::remove_all(fs::path(out).parent_path());
  // The second fusion node too (it saves on exit), then clean up.
  const int reset_pid = NodePid("/fusion_reset");
  if (reset_pid > 0 && kill(reset_pid, SIGTERM) == 0)
    WaitFor([&] { return kill(reset_pid, 0) != 0; }, 60);
  std::string reset_out;
  if (ros::param::get("/fusion_reset/output_path", reset_out))
    fs::remove_all(fs::path(reset_out).parent_path());
  fs::remove_all(dir);
}

}  // namespace
}  // namespace testing
}  // namespace wild_mvs

int main(int argc, char** argv) {
  ::testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "rostest_faults");
  return RUN_ALL_TESTS();
}
