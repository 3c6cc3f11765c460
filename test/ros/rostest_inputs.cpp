// Copyright wild_mvs authors. rostest (test/ros/inputs.test): the depth node
// takes compressed images (<image>/compressed, PNG) and poses from the
// `pose` topic (geometry_msgs/PoseStamped, matched by stamp) instead of raw
// images and tf: a synthetic bag played without /tf and without raw images
// still gives every keyframe its depth map, at the right pose and matching
// the exact ground truth.
#include <gtest/gtest.h>
#include <ros/ros.h>
#include <sensor_msgs/Image.h>
#include <wild_mvs/DepthView.h>

#include <cmath>
#include <filesystem>
#include <map>
#include <mutex>

#include "ros_test_scene.h"
#include "rostest_util.h"
#include "test_paths.h"
#include "wild_mvs/core/metrics.h"
#include "wild_mvs/ros/conversions.h"
#include "wild_mvs/ros/scene_bag.h"

namespace wild_mvs {
namespace testing {
namespace {

constexpr double kRate = 4.0;
constexpr int kViews = 5;

TEST(Inputs, CompressedImagesAndPoseTopic) {
  ros::NodeHandle nh;
  const SyntheticScene scene = Render(RosTestSpec(kViews));
  const std::string dir = MakeTempDir("wild_mvs_rostest_inputs");
  const std::string bag = dir + "/scene.bag";
  ros1::SceneBagOptions bo;
  bo.rate = kRate;
  bo.compression = "png";
  bo.with_pose = true;
  ros1::WriteSceneBag(
      scene.scene, [&](int i) { return ros1::LinearToSrgb8(scene.images[i]); },
      bag, bo);

  std::mutex mutex;
  std::map<int, wild_mvs::DepthViewConstPtr> views;
  auto index_of = [&](const ros::Time& t) {
    return static_cast<int>(std::lround((t.toSec() - bo.start_time) * kRate));
  };
  ros::Subscriber sub = nh.subscribe<wild_mvs::DepthView>(
      "/depth_node/depth_view", 20, [&](const wild_mvs::DepthViewConstPtr& m) {
        std::lock_guard<std::mutex> lock(mutex);
        views[index_of(m->header.stamp)] = m;
      });
  DiagnosticsWatch diag(nh);
  ros::AsyncSpinner spinner(2);
  spinner.start();
  ASSERT_TRUE(WaitFor([&] { return sub.getNumPublishers() > 0; }, 30));
  ros::WallDuration(1.0).sleep();
  // Only the compressed images, camera_info and the pose topic: no tf.
  PlayBag(bag, 1.0,
          "--topics /camera/image_raw/compressed /camera/camera_info "
          "/camera/pose")
      .join();
  WaitFor(
      [&] {
        std::lock_guard<std::mutex> lock(mutex);
        return views.size() >= static_cast<size_t>(kViews);
      },
      120);
  std::lock_guard<std::mutex> lock(mutex);
  EXPECT_GE(views.size(), static_cast<size_t>(kViews - 1))
      << diag.Dump("depth_node");
  for (const auto& [i, msg] : views) {
    ASSERT_GE(i, 0);
    ASSERT_LT(i, kViews);
    Camera cam;
    ros1::CameraFromCameraInfo(msg->camera_info, &cam, nullptr);
    ros1::SetCameraPose(msg->camera_pose.pose, &cam);
    // The pose came from the pose topic (there is no tf).
    EXPECT_LT((cam.Center() - scene.scene.views[i].camera.Center()).norm(),
              1e-4);
    cv::Mat d = ros1::FloatImageFromMsg(msg->depth, 1, "depth");
    d.forEach<float>([](float& v, const int*) {
      if (std::isnan(v)) v = 0;
    });
    const DepthMetrics m =
        EvaluateDepth(d, cam, scene.depth[i], scene.scene.views[i].camera);
    EXPECT_GT(m.completeness, 0.4) << "view " << i << ": " << m.ToString();
    EXPECT_LT(m.median_rel_error, 0.01) << "view " << i;
    // Colours decoded from the PNG reach the DepthView.
    EXPECT_EQ(msg->image.encoding, "rgb8");
  }
  EXPECT_EQ(diag.Get("depth_node", "frames dropped"), 0)
      << diag.Dump("depth_node");
  std::printf("[inputs] %zu depth maps from compressed images + pose topic\n",
              views.size());
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace testing
}  // namespace wild_mvs

int main(int argc, char** argv) {
  ::testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "rostest_inputs");
  return RUN_ALL_TESTS();
}
