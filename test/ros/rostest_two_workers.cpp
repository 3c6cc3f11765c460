// Copyright wild_mvs authors. rostest (test/ros/two_workers.test): the depth
// work split over two workers (each selecting the same keyframes, shared
// sparse tracks)
// gives the same fused cloud as one worker, within tolerance (ownership by
// the stamp hash, KeyframeOwner).
#include <gtest/gtest.h>
#include <ros/ros.h>
#include <sensor_msgs/Image.h>
#include <wild_mvs/DepthView.h>

#include <algorithm>
#include <filesystem>
#include <mutex>
#include <set>

#include "ros_test_scene.h"
#include "rostest_util.h"
#include "test_paths.h"
#include "wild_mvs/core/metrics.h"
#include "wild_mvs/ros/scene_bag.h"
#include "wild_mvs/stream/keyframe_store.h"

namespace wild_mvs {
namespace testing {
namespace {

constexpr int kViews = 6;

TEST(TwoWorkers, SameCloudAsOneWorker) {
  ros::NodeHandle nh;
  const SyntheticScene scene = Render(RosTestSpec(kViews));
  const std::string dir = MakeTempDir("wild_mvs_rostest_workers");
  const std::string bag = dir + "/scene.bag";
  ros1::SceneBagOptions bo;
  bo.rate = 2.0;
  bo.with_points = true;
  ros1::WriteSceneBag(
      scene.scene, [&](int i) { return ros1::LinearToSrgb8(scene.images[i]); },
      bag, bo);
  std::mutex mutex;
  std::set<uint32_t> ids[2];
  std::set<uint32_t> workers_seen;
  sensor_msgs::PointCloud2ConstPtr clouds[2];
  ros::Subscriber v1 = nh.subscribe<wild_mvs::DepthView>(
      "/one/depth_view", 20, [&](const wild_mvs::DepthViewConstPtr& m) {
        std::lock_guard<std::mutex> lock(mutex);
        ids[0].insert(m->keyframe_id);
      });
  ros::Subscriber v2 = nh.subscribe<wild_mvs::DepthView>(
      "/two/depth_view", 20, [&](const wild_mvs::DepthViewConstPtr& m) {
        std::lock_guard<std::mutex> lock(mutex);
        ids[1].insert(m->keyframe_id);
        workers_seen.insert(m->worker_index);
        EXPECT_EQ(KeyframeOwner(m->header.stamp.toNSec(), 2),
                  static_cast<int>(m->worker_index));
      });
  ros::Subscriber c1 = nh.subscribe<sensor_msgs::PointCloud2>(
      "/one/fusion_node/cloud", 2,
      [&](const sensor_msgs::PointCloud2ConstPtr& m) {
        std::lock_guard<std::mutex> lock(mutex);
        clouds[0] = m;
      });
  ros::Subscriber c2 = nh.subscribe<sensor_msgs::PointCloud2>(
      "/two/fusion_node/cloud", 2,
      [&](const sensor_msgs::PointCloud2ConstPtr& m) {
        std::lock_guard<std::mutex> lock(mutex);
        clouds[1] = m;
      });
  DiagnosticsWatch diag(nh);
  ros::AsyncSpinner spinner(2);
  spinner.start();
  ASSERT_TRUE(WaitFor(
      [&] {
        return v1.getNumPublishers() > 0 && v2.getNumPublishers() > 0 &&
               c1.getNumPublishers() > 0 && c2.getNumPublishers() > 0;
      },
      60));
  // Every depth node (one + two workers) is up and subscribed before the bag
  // starts: each publishes diagnostics once constructed (after subscribing).
  ASSERT_TRUE(WaitFor(
      [&] {
        return diag.Get("one/depth_node", "input queue size") > 0 &&
               diag.Get("two/depth_worker_0", "input queue size") > 0 &&
               diag.Get("two/depth_worker_1", "input queue size") > 0;
      },
      60));
  // Both processes (one/depth_node and the manager of the two workers)
  // connected on every topic before the first message.
  std::thread player = PlayBagConnected(bag, 1.0, 2);
  player.join();
  ASSERT_TRUE(WaitFor(
      [&] {
        std::lock_guard<std::mutex> lock(mutex);
        return ids[0].size() >= static_cast<size_t>(kViews) &&
               ids[1].size() >= static_cast<size_t>(kViews);
      },
      200))
      << ids[0].size() << " vs " << ids[1].size();
  {
    std::lock_guard<std::mutex> lock(mutex);
    EXPECT_EQ(ids[0], ids[1]);  // the same keyframes, split by stamp
    EXPECT_EQ(workers_seen.size(), 2u);
  }
  // Both fusion nodes fused every view; compare their latched clouds.
  ASSERT_TRUE(WaitFor(
      [&] {
        return diag.Get("one/fusion_node", "views fused") >= kViews &&
               diag.Get("two/fusion_node", "views fused") >= kViews;
      },
      60));
  ros::WallDuration(1.5).sleep();
  PointCloud a, b;
  {
    std::lock_guard<std::mutex> lock(mutex);
    ASSERT_TRUE(clouds[0] && clouds[1]);
    a = CloudFromMsg(*clouds[0]);
    b = CloudFromMsg(*clouds[1]);
  }
  ASSERT_GT(a.size(), 1000u);
  const double ratio = double(b.size()) / double(a.size());
  EXPECT_GT(ratio, 0.9);
  EXPECT_LT(ratio, 1.1);
  // Every point of one cloud has a point of the other within 3 cm (the
  // pixel footprint is ~2 cm).
  auto within = [](const PointCloud& p, const PointCloud& q, double tau) {
    const std::vector<double> d = NearestDistances(p, q, 2);
    return std::count_if(d.begin(), d.end(),
                         [tau](double x) { return x <= tau; }) /
           double(d.size());
  };
  const double ab = within(a, b, 0.03), ba = within(b, a, 0.03);
  std::printf(
      "[two_workers] one worker %zu points, two workers %zu points; "
      "within 3 cm: %.4f / %.4f\n",
      a.size(), b.size(), ab, ba);
  EXPECT_GT(ab, 0.97);
  EXPECT_GT(ba, 0.97);
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace testing
}  // namespace wild_mvs

int main(int argc, char** argv) {
  ::testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "rostest_two_workers");
  return RUN_ALL_TESTS();
}
