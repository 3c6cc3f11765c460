// Copyright wild_mvs authors. rostest (test/ros/two_workers.test): the depth
// work split over two workers (each selecting the same keyframes, shared
// sparse tracks) gives the same fused cloud as one worker, within tolerance
// (ownership by the stamp hash, KeyframeOwner). The bag is played once; each
// case checks one outcome.
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

// The bag played once through both set-ups ("one": one depth node; "two":
// two depth worker nodelets), and what came out. A step that does not
// complete ends the run; `failure` says which.
class TwoWorkersRun {
  ros::NodeHandle nh_;  // first: the members below use it

 public:
  TwoWorkersRun() : diag(nh_), spinner_(2) {}
  // No callback may run while the members it uses are destroyed.
  ~TwoWorkersRun() {
    spinner_.stop();
    if (!dir.empty()) std::filesystem::remove_all(dir);
  }

  void Run() {
    const SyntheticScene scene = Render(RosTestSpec(kViews));
    dir = MakeTempDir("wild_mvs_rostest_workers");
    const std::string bag = dir + "/scene.bag";
    ros1::SceneBagOptions bo;
    bo.rate = 2.0;
    bo.with_points = true;
    ros1::WriteSceneBag(
        scene.scene,
        [&](int i) { return ros1::LinearToSrgb8(scene.images[i]); }, bag, bo);
    Subscribe();
    spinner_.start();
    if (!WaitFor(
            [&] {
              for (const ros::Subscriber& s : subs_)
                if (s.getNumPublishers() == 0) return false;
              return true;
            },
            60)) {
      failure = "the depth and fusion nodes did not come up";
      return;
    }
    // Every depth node (one + two workers) is up and subscribed before the
    // bag starts: each publishes diagnostics once constructed (after
    // subscribing).
    if (!WaitFor(
            [&] {
              return diag.Get("one/depth_node", "input queue size") > 0 &&
                     diag.Get("two/depth_worker_0", "input queue size") > 0 &&
                     diag.Get("two/depth_worker_1", "input queue size") > 0;
            },
            60)) {
      failure = "the depth nodes published no diagnostics";
      return;
    }
    // Both processes (one/depth_node and the manager of the two workers)
    // connected on every topic before the first message.
    PlayBagConnected(bag, 1.0, 2).join();
    if (!WaitFor(
            [&] {
              std::lock_guard<std::mutex> lock(mutex_);
              return ids_[0].size() >= static_cast<size_t>(kViews) &&
                     ids_[1].size() >= static_cast<size_t>(kViews);
            },
            200)) {
      std::lock_guard<std::mutex> lock(mutex_);
      failure = "depth views: " + std::to_string(ids_[0].size()) +
                " from one worker, " + std::to_string(ids_[1].size()) +
                " from two, of " + std::to_string(kViews);
      return;
    }
    // Both fusion nodes fused every view; their latched clouds after that.
    if (!WaitFor(
            [&] {
              return diag.Get("one/fusion_node", "views fused") >= kViews &&
                     diag.Get("two/fusion_node", "views fused") >= kViews;
            },
            60)) {
      failure = "not every view fused; " + diag.Dump("one/fusion_node") +
                diag.Dump("two/fusion_node");
      return;
    }
    ros::WallDuration(1.5).sleep();
    std::lock_guard<std::mutex> lock(mutex_);
    if (!clouds_[0] || !clouds_[1]) {
      failure = "no cloud from a fusion node";
      return;
    }
    cloud_one = CloudFromMsg(*clouds_[0]);
    cloud_two = CloudFromMsg(*clouds_[1]);
    keyframes_one = ids_[0];
    keyframes_two = ids_[1];
    complete = true;
  }

  std::string dir;
  DiagnosticsWatch diag;
  bool complete = false;
  std::string failure;
  std::set<uint32_t> keyframes_one, keyframes_two;  // keyframe ids
  PointCloud cloud_one, cloud_two;                  // the fused clouds

  std::set<uint32_t> WorkersSeen() {
    std::lock_guard<std::mutex> lock(mutex_);
    return workers_seen_;
  }
  int WrongOwners() {
    std::lock_guard<std::mutex> lock(mutex_);
    return wrong_owner_;
  }

 private:
  void Subscribe() {
    subs_.push_back(nh_.subscribe<wild_mvs::DepthView>(
        "/one/depth_view", 20, [this](const wild_mvs::DepthViewConstPtr& m) {
          std::lock_guard<std::mutex> lock(mutex_);
          ids_[0].insert(m->keyframe_id);
        }));
    subs_.push_back(nh_.subscribe<wild_mvs::DepthView>(
        "/two/depth_view", 20, [this](const wild_mvs::DepthViewConstPtr& m) {
          std::lock_guard<std::mutex> lock(mutex_);
          ids_[1].insert(m->keyframe_id);
          workers_seen_.insert(m->worker_index);
          if (KeyframeOwner(m->header.stamp.toNSec(), 2) !=
              static_cast<int>(m->worker_index))
            ++wrong_owner_;
        }));
    for (int k = 0; k < 2; ++k)
      subs_.push_back(nh_.subscribe<sensor_msgs::PointCloud2>(
          k == 0 ? "/one/fusion_node/cloud" : "/two/fusion_node/cloud", 2,
          [this, k](const sensor_msgs::PointCloud2ConstPtr& m) {
            std::lock_guard<std::mutex> lock(mutex_);
            clouds_[k] = m;
          }));
  }

  ros::AsyncSpinner spinner_;
  std::mutex mutex_;
  std::set<uint32_t> ids_[2];
  std::set<uint32_t> workers_seen_;
  int wrong_owner_ = 0;
  sensor_msgs::PointCloud2ConstPtr clouds_[2];
  std::vector<ros::Subscriber> subs_;
};

class TwoWorkers : public RunOnce<TwoWorkersRun> {
 protected:
  // Fraction of p's points with a point of q within tau metres.
  static double Within(const PointCloud& p, const PointCloud& q, double tau) {
    const std::vector<double> d = NearestDistances(p, q, 2);
    return std::count_if(d.begin(), d.end(),
                         [tau](double x) { return x <= tau; }) /
           double(d.size());
  }
};

TEST_F(TwoWorkers, SameKeyframesAsOneWorker) {
  EXPECT_EQ(run_->keyframes_one, run_->keyframes_two);
}

TEST_F(TwoWorkers, EachKeyframeIsDoneByTheOwnerOfItsStamp) {
  EXPECT_EQ(run_->WorkersSeen().size(), 2u);
  EXPECT_EQ(run_->WrongOwners(), 0);
}

TEST_F(TwoWorkers, CloudHasAsManyPointsAsOneWorkers) {
  ASSERT_GT(run_->cloud_one.size(), 1000u);
  const double ratio =
      double(run_->cloud_two.size()) / double(run_->cloud_one.size());
  EXPECT_GT(ratio, 0.9);
  EXPECT_LT(ratio, 1.1);
}

// Every point of one cloud has a point of the other within 3 cm (the pixel
// footprint is about 2 cm), both ways.
TEST_F(TwoWorkers, CloudsAgreeWithin3cm) {
  ASSERT_FALSE(run_->cloud_one.xyz.empty());
  ASSERT_FALSE(run_->cloud_two.xyz.empty());
  const double ab = Within(run_->cloud_one, run_->cloud_two, 0.03);
  const double ba = Within(run_->cloud_two, run_->cloud_one, 0.03);
  std::printf(
      "[two_workers] one worker %zu points, two workers %zu points; "
      "within 3 cm: %.4f / %.4f\n",
      run_->cloud_one.size(), run_->cloud_two.size(), ab, ba);
  EXPECT_GT(ab, 0.97);
  EXPECT_GT(ba, 0.97);
}

}  // namespace
}  // namespace testing
}  // namespace wild_mvs

int main(int argc, char** argv) {
  ::testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "rostest_two_workers");
  return RUN_ALL_TESTS();
}
