// Copyright wild_mvs authors. rostest (test/ros/selector_workers.test): a
// keyframe selector and two depth workers in separate processes. The
// checker relays the selector's keyframes to worker 1, dropping every other
// keyframe of each owner and holding back the last one; worker 1 fetches
// what it missed from the selector, so every keyframe is reconstructed
// exactly once, by its owner. Then the fusion node's keyframe diagnostics
// must name a keyframe announced but never done and one done twice. The bag
// is played once; each case checks one outcome.
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

// The bag played once through the selector, the relay and the workers, and
// what came out. The subscriptions and the spinner stay up for the cases
// (the diagnostics keep arriving; the last case publishes faults). A step
// that does not complete ends the run; `failure` says which.
class SelectorWorkersRun {
  ros::NodeHandle nh_;  // first: the members below use it

 public:
  SelectorWorkersRun() : diag(nh_), spinner_(2) {}
  // No callback may run while the members it uses are destroyed.
  ~SelectorWorkersRun() {
    spinner_.stop();
    if (!dir.empty()) std::filesystem::remove_all(dir);
  }

  void Run() {
    const SyntheticScene scene = Render(RosTestSpec(kViews));
    dir = MakeTempDir("wild_mvs_rostest_selector");
    const std::string bag = dir + "/scene.bag";
    ros1::SceneBagOptions bo;
    bo.rate = 2.0;
    ros1::WriteSceneBag(
        scene.scene,
        [&](int i) { return ros1::LinearToSrgb8(scene.images[i]); }, bag, bo);
    Subscribe();
    spinner_.start();
    if (!WaitFor(
            [&] {
              return relay_.getNumPublishers() > 0 &&
                     lossy_.getNumSubscribers() > 0 &&
                     view_sub_.getNumPublishers() >= 2 &&
                     diag.Get("selector", "input queue size") > 0 &&
                     diag.Get("depth_worker_0", "input queue size") > 0 &&
                     diag.Get("depth_worker_1", "input queue size") > 0 &&
                     diag.Get("fusion_node", "views fused") >= 0;
            },
            60)) {
      failure = "the selector, workers and fusion node did not come up";
      return;
    }
    {
      ros::Publisher probe =
          nh_.advertise<sensor_msgs::Image>("/camera/image_raw", 1);
      if (!WaitFor([&] { return probe.getNumSubscribers() >= 1; }, 60)) {
        failure = "the selector does not subscribe to the images";
        return;
      }
    }
    ros::WallDuration(1.0).sleep();
    PlayBag(bag, 1.0).join();
    // Every keyframe the selector made has its two depth views.
    auto all_done = [&] {
      std::lock_guard<std::mutex> lock(mutex_);
      if (selected_.size() < 6) return false;
      for (const auto& k : selected_) {
        auto it = views_.find(k->header.stamp.toNSec());
        if (it == views_.end() || it->second.size() < 2) return false;
      }
      return true;
    };
    if (!WaitFor(all_done, 200)) {
      std::lock_guard<std::mutex> lock(mutex_);
      failure = std::to_string(views_.size()) + " of " +
                std::to_string(selected_.size()) + " keyframes done\n" +
                diag.Dump("depth_worker_1") + diag.Dump("fusion_node");
      return;
    }
    ros::WallDuration(2.0).sleep();  // anything done twice would be here now
    std::lock_guard<std::mutex> lock(mutex_);
    selected = selected_;
    dropped = dropped_;
    held_back = held_ != nullptr;
    views = views_;
    last_index = last_index_;
    complete = true;
  }

  // What the run saw once every keyframe was done.
  std::vector<wild_mvs::SelectedKeyframeConstPtr> selected;  // by the selector
  std::set<uint64_t> dropped;  // stamps the relay dropped
  bool held_back = false;      // the relay's last keyframe never passed
  std::map<uint64_t, std::vector<wild_mvs::DepthViewConstPtr>> views;
  wild_mvs::KeyframeIndexConstPtr last_index;

  std::string dir;
  DiagnosticsWatch diag;
  bool complete = false;
  std::string failure;

 private:
  void Subscribe() {
    lossy_ = nh_.advertise<wild_mvs::SelectedKeyframe>("/lossy/keyframes", 50);
    // The relay to worker 1: each owner's keyframes alternately passed and
    // dropped (the first one of each dropped); every message is held until
    // the next one comes, so the last one never arrives.
    relay_ = nh_.subscribe<wild_mvs::SelectedKeyframe>(
        "/selector/keyframes", 50,
        [this](const wild_mvs::SelectedKeyframeConstPtr& k) {
          std::lock_guard<std::mutex> lock(mutex_);
          selected_.push_back(k);
          if (held_) lossy_.publish(held_);
          held_.reset();
          const int owner = KeyframeOwner(k->header.stamp.toNSec(), kWorkers);
          if (passed_per_owner_[owner]++ % 2 == 0) {
            dropped_.insert(k->header.stamp.toNSec());
            return;
          }
          held_ = k;
        });
    index_sub_ = nh_.subscribe<wild_mvs::KeyframeIndex>(
        "/selector/keyframe_index", 10,
        [this](const wild_mvs::KeyframeIndexConstPtr& m) {
          std::lock_guard<std::mutex> lock(mutex_);
          last_index_ = m;
        });
    view_sub_ = nh_.subscribe<wild_mvs::DepthView>(
        "/depth_view", 50, [this](const wild_mvs::DepthViewConstPtr& m) {
          std::lock_guard<std::mutex> lock(mutex_);
          views_[m->header.stamp.toNSec()].push_back(m);
        });
  }

  ros::AsyncSpinner spinner_;
  std::mutex mutex_;
  std::vector<wild_mvs::SelectedKeyframeConstPtr> selected_;
  std::set<uint64_t> dropped_;
  int passed_per_owner_[kWorkers] = {0, 0};
  wild_mvs::SelectedKeyframeConstPtr held_;  // the relay's newest, held back
  std::map<uint64_t, std::vector<wild_mvs::DepthViewConstPtr>> views_;
  wild_mvs::KeyframeIndexConstPtr last_index_;
  ros::Publisher lossy_;
  ros::Subscriber relay_, index_sub_, view_sub_;
};

// The cases run in the order written: the last one publishes faults that
// change the fusion node's counts the one before checks.
class SelectorWorkers : public RunOnce<SelectorWorkersRun> {
 protected:
  static long Keyframes() { return static_cast<long>(run_->selected.size()); }
};

// The precondition of what follows: worker 1 missed keyframes.
TEST_F(SelectorWorkers, RelayDroppedKeyframesOfWorker1) {
  int dropped_of_worker_1 = 0;
  for (uint64_t s : run_->dropped)
    dropped_of_worker_1 += KeyframeOwner(s, kWorkers) == 1;
  EXPECT_GE(dropped_of_worker_1, 1);
  EXPECT_GE(run_->dropped.size(), 2u);
  std::printf(
      "[selector_workers] %zu keyframes, %zu dropped and 1 held back by "
      "the relay (%d of worker 1)\n",
      run_->selected.size(), run_->dropped.size(), dropped_of_worker_1);
}

TEST_F(SelectorWorkers, KeyframeIdsAreConsecutive) {
  for (size_t i = 0; i < run_->selected.size(); ++i)
    EXPECT_EQ(run_->selected[i]->keyframe_id, i);
}

// Matched once (revision 0), then revised twice (revision 1, then the
// final one: the consistency step against the worker's own neighbour
// maps), by its owner, under the selector's numbering and session.
TEST_F(SelectorWorkers, EveryKeyframeIsMatchedOnceAndRevisedByItsOwner) {
  for (size_t i = 0; i < run_->selected.size(); ++i) {
    const wild_mvs::SelectedKeyframe& k = *run_->selected[i];
    const uint64_t s = k.header.stamp.toNSec();
    ASSERT_TRUE(run_->views.count(s)) << "keyframe " << i;
    const auto& revisions = run_->views.at(s);
    ASSERT_EQ(revisions.size(), 3u) << "keyframe " << i;
    for (uint32_t rev = 0; rev < 3; ++rev) {
      const wild_mvs::DepthView& v = *revisions[rev];
      EXPECT_EQ(static_cast<int>(v.worker_index), KeyframeOwner(s, kWorkers));
      EXPECT_EQ(v.keyframe_id, k.keyframe_id);
      EXPECT_EQ(v.session, k.session);
      EXPECT_EQ(v.revision, rev);
      EXPECT_EQ(v.final_revision, rev == 2);
    }
  }
}

TEST_F(SelectorWorkers, NoDepthViewOfAnythingButTheKeyframes) {
  EXPECT_EQ(run_->views.size(), run_->selected.size());
}

// Worker 1 fetched every keyframe it missed (the dropped ones and the
// held-back last one, which it learns of from the index only) and lost
// none; each worker took every keyframe once (a message that came after
// the keyframe was fetched counts as repeated).
TEST_F(SelectorWorkers, Worker1FetchesWhatItMissedAndNoWorkerLosesAny) {
  const long n = Keyframes();
  auto taken = [&](const std::string& w) {
    return run_->diag.Get(w, "keyframes received") -
           run_->diag.Get(w, "keyframe messages repeated") +
           run_->diag.Get(w, "keyframes fetched");
  };
  EXPECT_TRUE(WaitFor(
      [&] {
        return taken("depth_worker_0") == n && taken("depth_worker_1") == n;
      },
      20))
      << run_->diag.Dump("depth_worker_0") << run_->diag.Dump("depth_worker_1");
  const long missed =
      static_cast<long>(run_->dropped.size()) + (run_->held_back ? 1 : 0);
  EXPECT_GE(run_->diag.Get("depth_worker_1", "keyframes fetched"), missed);
  EXPECT_EQ(run_->diag.Get("depth_worker_1", "keyframes lost"), 0);
  EXPECT_EQ(run_->diag.Get("depth_worker_0", "keyframes lost"), 0);
  EXPECT_EQ(run_->diag.Get("selector", "keyframes published"), n);
}

TEST_F(SelectorWorkers, FusionFusesEachKeyframeOnceAndNamesNone) {
  const long n = Keyframes();
  ASSERT_TRUE(WaitFor(
      [&] {
        return run_->diag.Get("fusion_node", "views fused") == n &&
               run_->diag.Get("fusion_node", "keyframes announced") == n &&
               run_->diag.Get("fusion_node", "keyframes with a depth view") ==
                   n;
      },
      30))
      << run_->diag.Dump("fusion_node");
  EXPECT_EQ(run_->diag.Get("fusion_node", "keyframes missing"), 0);
  EXPECT_EQ(run_->diag.Get("fusion_node", "keyframes done twice"), 0);
}

// The diagnostics name what goes wrong: a keyframe announced that no worker
// will do (not among the selector's, so both workers count it lost), and a
// depth view sent a second time, which is not fused again.
TEST_F(SelectorWorkers, FusionNamesAKeyframeNeverDoneAndOneDoneTwice) {
  ros::NodeHandle nh;
  ASSERT_TRUE(run_->last_index);
  ASSERT_FALSE(run_->views.empty());
  wild_mvs::KeyframeIndex fake = *run_->last_index;
  const wild_mvs::DepthViewConstPtr again = run_->views.begin()->second.front();
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
        const auto v = run_->diag.Values("fusion_node");
        auto has = [&](const char* k) { return v.count(k) > 0; };
        return run_->diag.Get("fusion_node", "keyframes missing") == 1 &&
               run_->diag.Get("fusion_node", "keyframes done twice") == 1 &&
               has("keyframes missing (first stamps)") &&
               v.at("keyframes missing (first stamps)") == ghost_text;
      },
      30))
      << run_->diag.Dump("fusion_node") << "expected missing: " << ghost_text;
  EXPECT_TRUE(WaitFor(
      [&] {
        return run_->diag.Get("depth_worker_0", "keyframes lost") == 1 &&
               run_->diag.Get("depth_worker_1", "keyframes lost") == 1;
      },
      20))
      << run_->diag.Dump("depth_worker_0");
  // The cloud still has each keyframe once: the copy was not fused again.
  EXPECT_EQ(run_->diag.Get("fusion_node", "views fused"), Keyframes());
}

}  // namespace
}  // namespace testing
}  // namespace wild_mvs

int main(int argc, char** argv) {
  ::testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "rostest_selector_workers");
  return RUN_ALL_TESTS();
}
