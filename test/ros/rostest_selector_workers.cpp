// Copyright wild_mvs authors. rostest (test/ros/selector_workers.test): a
// keyframe selector and two depth workers in separate processes. The
// checker relays the selector's keyframes to worker 1, dropping every other
// keyframe of each owner and holding back the last one; worker 1 fetches
// what it missed from the selector, so every keyframe is reconstructed
// exactly once, by its owner. Then the fusion node's keyframe diagnostics
// must name a keyframe announced but never done and one done twice.
#include <gtest/gtest.h>
#include <ros/ros.h>
#include <sensor_msgs/Image.h>
#include <wild_mvs/DepthView.h>
#include <wild_mvs/KeyframeIndex.h>
#include <wild_mvs/SelectedKeyframe.h>

#include <filesystem>
#include <map>
#include <mutex>
#include <set>

#include "ros_test_scene.h"
#include "rostest_util.h"
#include "test_paths.h"
#include "wild_mvs/ros/scene_bag.h"
#include "wild_mvs/stream/keyframe_store.h"

namespace wild_mvs {
namespace testing {
namespace {

constexpr int kViews = 8;
constexpr int kWorkers = 2;

TEST(SelectorWorkers, EveryKeyframeOnceThoughAWorkerDropsFrames) {
  ros::NodeHandle nh;
  const SyntheticScene scene = Render(RosTestSpec(kViews));
  const std::string dir = MakeTempDir("wild_mvs_rostest_selector");
  const std::string bag = dir + "/scene.bag";
  ros1::SceneBagOptions bo;
  bo.rate = 2.0;
  ros1::WriteSceneBag(
      scene.scene, [&](int i) { return ros1::LinearToSrgb8(scene.images[i]); },
      bag, bo);

  std::mutex mutex;
  std::vector<wild_mvs::SelectedKeyframeConstPtr> selected;  // by the selector
  std::set<uint64_t> dropped;                                // by the relay
  int passed_per_owner[kWorkers] = {0, 0};
  wild_mvs::SelectedKeyframeConstPtr held;  // the relay's newest, held back
  std::map<uint64_t, std::vector<wild_mvs::DepthViewConstPtr>> views;
  wild_mvs::KeyframeIndexConstPtr last_index;
  ros::Publisher lossy =
      nh.advertise<wild_mvs::SelectedKeyframe>("/lossy/keyframes", 50);
  // The relay to worker 1: each owner's keyframes alternately passed and
  // dropped (the first one of each dropped); every message is held until the
  // next one comes, so the last one never arrives.
  ros::Subscriber relay = nh.subscribe<wild_mvs::SelectedKeyframe>(
      "/selector/keyframes", 50,
      [&](const wild_mvs::SelectedKeyframeConstPtr& k) {
        std::lock_guard<std::mutex> lock(mutex);
        selected.push_back(k);
        if (held) lossy.publish(held);
        held.reset();
        const int owner = KeyframeOwner(k->header.stamp.toNSec(), kWorkers);
        if (passed_per_owner[owner]++ % 2 == 0) {
          dropped.insert(k->header.stamp.toNSec());
          return;
        }
        held = k;
      });
  ros::Subscriber index_sub = nh.subscribe<wild_mvs::KeyframeIndex>(
      "/selector/keyframe_index", 10,
      [&](const wild_mvs::KeyframeIndexConstPtr& m) {
        std::lock_guard<std::mutex> lock(mutex);
        last_index = m;
      });
  ros::Subscriber view_sub = nh.subscribe<wild_mvs::DepthView>(
      "/depth_view", 50, [&](const wild_mvs::DepthViewConstPtr& m) {
        std::lock_guard<std::mutex> lock(mutex);
        views[m->header.stamp.toNSec()].push_back(m);
      });
  DiagnosticsWatch diag(nh);
  ros::AsyncSpinner spinner(2);
  spinner.start();
  ASSERT_TRUE(WaitFor(
      [&] {
        return relay.getNumPublishers() > 0 && lossy.getNumSubscribers() > 0 &&
               view_sub.getNumPublishers() >= 2 &&
               diag.Get("selector", "input queue size") > 0 &&
               diag.Get("depth_worker_0", "input queue size") > 0 &&
               diag.Get("depth_worker_1", "input queue size") > 0 &&
               diag.Get("fusion_node", "views fused") >= 0;
      },
      60));
  {
    ros::Publisher probe =
        nh.advertise<sensor_msgs::Image>("/camera/image_raw", 1);
    ASSERT_TRUE(WaitFor([&] { return probe.getNumSubscribers() >= 1; }, 60));
  }
  ros::WallDuration(1.0).sleep();
  std::thread player = PlayBag(bag, 1.0);
  player.join();

  // Every keyframe the selector made has a depth view.
  auto all_done = [&] {
    std::lock_guard<std::mutex> lock(mutex);
    if (selected.size() < 6) return false;
    for (const auto& k : selected) {
      auto it = views.find(k->header.stamp.toNSec());
      if (it == views.end() || it->second.size() < 2) return false;
    }
    return true;
  };
  ASSERT_TRUE(WaitFor(all_done, 200))
      << views.size() << " of " << selected.size() << " keyframes done\n"
      << diag.Dump("depth_worker_1") << diag.Dump("fusion_node");
  ros::WallDuration(2.0).sleep();  // anything done twice would be here now
  std::set<uint64_t> selected_stamps;
  {
    std::lock_guard<std::mutex> lock(mutex);
    int dropped_of_worker_1 = 0;
    for (uint64_t s : dropped)
      dropped_of_worker_1 += KeyframeOwner(s, kWorkers) == 1;
    EXPECT_GE(dropped_of_worker_1, 1);
    EXPECT_GE(dropped.size(), 2u);
    for (size_t i = 0; i < selected.size(); ++i) {
      const wild_mvs::SelectedKeyframeConstPtr& k = selected[i];
      EXPECT_EQ(k->keyframe_id, i);  // consecutive
      const uint64_t s = k->header.stamp.toNSec();
      selected_stamps.insert(s);
      // Matched once (revision 0), then revised once (the consistency
      // step against the worker's own neighbour maps), by its owner.
      ASSERT_EQ(views[s].size(), 2u) << "keyframe " << i;
      for (uint32_t rev = 0; rev < 2; ++rev) {
        const wild_mvs::DepthView& v = *views[s][rev];
        EXPECT_EQ(static_cast<int>(v.worker_index), KeyframeOwner(s, kWorkers));
        EXPECT_EQ(v.keyframe_id, k->keyframe_id);  // the selector's numbering
        EXPECT_EQ(v.session, k->session);
        EXPECT_EQ(v.revision, rev);
        EXPECT_EQ(v.final_revision, rev == 1);
      }
    }
    EXPECT_EQ(views.size(), selected.size());  // nothing else
    std::printf(
        "[selector_workers] %zu keyframes, %zu dropped and 1 held back by "
        "the relay (%d of worker 1)\n",
        selected.size(), dropped.size(), dropped_of_worker_1);
  }
  const long n = static_cast<long>(selected_stamps.size());
  // Worker 1 fetched every keyframe it missed (the dropped ones and the
  // held-back last one, which it learns of from the index only) and lost
  // none; each worker took every keyframe once (a message that came after
  // the keyframe was fetched counts as repeated).
  long missed = 0;
  {
    std::lock_guard<std::mutex> lock(mutex);
    missed = static_cast<long>(dropped.size()) + (held ? 1 : 0);
  }
  auto taken = [&](const std::string& w) {
    return diag.Get(w, "keyframes received") -
           diag.Get(w, "keyframe messages repeated") +
           diag.Get(w, "keyframes fetched");
  };
  EXPECT_TRUE(WaitFor(
      [&] {
        return taken("depth_worker_0") == n && taken("depth_worker_1") == n;
      },
      20))
      << diag.Dump("depth_worker_0") << diag.Dump("depth_worker_1");
  EXPECT_GE(diag.Get("depth_worker_1", "keyframes fetched"), missed);
  EXPECT_EQ(diag.Get("depth_worker_1", "keyframes lost"), 0);
  EXPECT_EQ(diag.Get("depth_worker_0", "keyframes lost"), 0);
  EXPECT_EQ(diag.Get("selector", "keyframes published"), n);
  // The fusion node fused each once and names nothing.
  ASSERT_TRUE(WaitFor(
      [&] {
        return diag.Get("fusion_node", "views fused") == n &&
               diag.Get("fusion_node", "keyframes announced") == n &&
               diag.Get("fusion_node", "keyframes with a depth view") == n;
      },
      30))
      << diag.Dump("fusion_node");
  EXPECT_EQ(diag.Get("fusion_node", "keyframes missing"), 0);
  EXPECT_EQ(diag.Get("fusion_node", "keyframes done twice"), 0);

  // The diagnostics name what goes wrong: a keyframe announced that no
  // worker will do (not among the selector's, so both workers count it
  // lost), and a depth view sent a second time.
  wild_mvs::KeyframeIndex fake;
  wild_mvs::DepthViewConstPtr again;
  {
    std::lock_guard<std::mutex> lock(mutex);
    ASSERT_TRUE(last_index);
    fake = *last_index;
    again = views.begin()->second.front();
  }
  const ros::Time ghost = fake.stamps.back() + ros::Duration(0.25);
  fake.first_id += static_cast<uint32_t>(fake.stamps.size());
  fake.stamps = {ghost};
  ros::Publisher fake_index =
      nh.advertise<wild_mvs::KeyframeIndex>("/selector/keyframe_index", 10);
  ros::Publisher views_pub =
      nh.advertise<wild_mvs::DepthView>("/depth_view", 10);
  ASSERT_TRUE(WaitFor(
      [&] {
        return fake_index.getNumSubscribers() >= 3 &&
               views_pub.getNumSubscribers() >= 1;
      },
      30));
  for (int i = 0; i < 3; ++i) {  // an index repeats (the heartbeat)
    fake_index.publish(fake);
    ros::WallDuration(1.2).sleep();
  }
  views_pub.publish(again);
  char ghost_text[40];
  std::snprintf(ghost_text, sizeof(ghost_text), "%u.%09u", ghost.sec,
                ghost.nsec);
  EXPECT_TRUE(WaitFor(
      [&] {
        const auto v = diag.Values("fusion_node");
        auto has = [&](const char* k) { return v.count(k) > 0; };
        return diag.Get("fusion_node", "keyframes missing") == 1 &&
               diag.Get("fusion_node", "keyframes done twice") == 1 &&
               has("keyframes missing (first stamps)") &&
               v.at("keyframes missing (first stamps)") == ghost_text;
      },
      30))
      << diag.Dump("fusion_node") << "expected missing: " << ghost_text;
  EXPECT_TRUE(WaitFor(
      [&] {
        return diag.Get("depth_worker_0", "keyframes lost") == 1 &&
               diag.Get("depth_worker_1", "keyframes lost") == 1;
      },
      20))
      << diag.Dump("depth_worker_0");
  // The cloud still has each keyframe once: the copy was not fused again.
  EXPECT_EQ(diag.Get("fusion_node", "views fused"), n);
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace testing
}  // namespace wild_mvs

int main(int argc, char** argv) {
  ::testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "rostest_selector_workers");
  return RUN_ALL_TESTS();
}
