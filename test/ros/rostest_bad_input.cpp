// Copyright wild_mvs authors. rostest (test/ros/bad_input.test): malformed
// and hostile input to the depth and fusion nodes. The nodes must stay up,
// drop what is bad with the reason counted in their diagnostics, keep their
// queues and memory bounded, and still accept good input afterwards.
#include <gtest/gtest.h>
#include <ros/ros.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/Image.h>
#include <tf2_msgs/TFMessage.h>
#include <wild_mvs/DepthView.h>

#include <cmath>
#include <limits>

#include "ros_test_scene.h"
#include "rostest_util.h"
#include "wild_mvs/ros/conversions.h"
#include "wild_mvs/ros/scene_bag.h"

namespace wild_mvs {
namespace testing {
namespace {

class BadInput : public ::testing::Test {
 protected:
  void SetUp() override {
    scene_ = Render(RosTestSpec(4));
    image_pub_ = nh_.advertise<sensor_msgs::Image>("/camera/image_raw", 500);
    info_pub_ =
        nh_.advertise<sensor_msgs::CameraInfo>("/camera/camera_info", 10);
    tf_pub_ = nh_.advertise<tf2_msgs::TFMessage>("/tf", 500);
    view_pub_ =
        nh_.advertise<wild_mvs::DepthView>("/depth_node/depth_view", 10);
    diag_ = std::make_unique<DiagnosticsWatch>(nh_);
    spinner_ = std::make_unique<ros::AsyncSpinner>(2);
    spinner_->start();
    ASSERT_TRUE(WaitFor(
        [&] {
          return image_pub_.getNumSubscribers() > 0 &&
                 info_pub_.getNumSubscribers() > 0 &&
                 tf_pub_.getNumSubscribers() > 0 &&
                 view_pub_.getNumSubscribers() > 0 &&
                 diag_->Get("depth_node", "frames received") >= 0;
        },
        30));
    ros::WallDuration(0.5).sleep();
  }

  sensor_msgs::Image Image(int view, double stamp,
                           const std::string& frame = "camera") {
    const cv::Mat rgb8 = ros1::LinearToSrgb8(scene_.images[view]);
    sensor_msgs::Image im;
    im.header.stamp = ros::Time(stamp);
    im.header.frame_id = frame;
    im.width = rgb8.cols;
    im.height = rgb8.rows;
    im.encoding = "rgb8";
    im.step = rgb8.cols * 3;
    im.data.assign(rgb8.data, rgb8.data + rgb8.total() * 3);
    return im;
  }
  sensor_msgs::CameraInfo Info(int view) {
    sensor_msgs::CameraInfo info =
        ros1::CameraInfoFromCamera(scene_.scene.views[view].camera);
    info.header.frame_id = "camera";
    return info;
  }
  void Tf(int view, double stamp, bool nan = false) {
    geometry_msgs::TransformStamped T;
    T.header.stamp = ros::Time(stamp);
    T.header.frame_id = "world";
    T.child_frame_id = "camera";
    const geometry_msgs::Pose p =
        ros1::PoseFromCamera(scene_.scene.views[view].camera);
    T.transform.translation.x = p.position.x;
    T.transform.translation.y = p.position.y;
    T.transform.translation.z = p.position.z;
    T.transform.rotation = p.orientation;
    if (nan) T.transform.rotation.w = std::numeric_limits<double>::quiet_NaN();
    tf2_msgs::TFMessage m;
    m.transforms.push_back(T);
    tf_pub_.publish(m);
  }
  // A good frame: tf, then the image.
  void Good(int view, double stamp) {
    Tf(view, stamp);
    ros::WallDuration(0.02).sleep();
    image_pub_.publish(Image(view, stamp));
  }
  long Dropped(const std::string& reason) {
    return diag_->Dropped("depth_node", reason);
  }
  bool WaitDropped(const std::string& reason, double seconds = 10) {
    return WaitFor([&] { return Dropped(reason) > 0; }, seconds);
  }

  ros::NodeHandle nh_;
  SyntheticScene scene_;
  ros::Publisher image_pub_, info_pub_, tf_pub_, view_pub_;
  std::unique_ptr<DiagnosticsWatch> diag_;
  std::unique_ptr<ros::AsyncSpinner> spinner_;
};

TEST_F(BadInput, NodesSurviveAndCountEveryProblem) {
  // Before any camera_info.
  Good(0, 10.0);
  EXPECT_TRUE(WaitDropped("no camera_info")) << diag_->Dump("depth_node");

  // Zero intrinsics.
  sensor_msgs::CameraInfo zero = Info(0);
  zero.K[0] = zero.K[4] = 0;
  info_pub_.publish(zero);
  ros::WallDuration(0.2).sleep();
  Good(0, 11.0);
  EXPECT_TRUE(WaitDropped("invalid camera_info")) << diag_->Dump("depth_node");

  // Image and camera_info of different sizes.
  sensor_msgs::CameraInfo other = Info(0);
  other.width = 320;
  other.height = 240;
  info_pub_.publish(other);
  ros::WallDuration(0.2).sleep();
  Good(0, 12.0);
  EXPECT_TRUE(WaitDropped("size differs")) << diag_->Dump("depth_node");

  // From now on a valid camera_info.
  info_pub_.publish(Info(0));
  ros::WallDuration(0.2).sleep();

  // Wrong encoding (a 16-bit depth image on the colour topic) and a data
  // array shorter than step * height.
  sensor_msgs::Image wrong = Image(0, 13.0);
  wrong.encoding = "16UC1";
  Tf(0, 13.0);
  image_pub_.publish(wrong);
  sensor_msgs::Image truncated = Image(0, 13.5);
  truncated.data.resize(truncated.data.size() / 2);
  Tf(0, 13.5);
  image_pub_.publish(truncated);
  EXPECT_TRUE(WaitFor([&] { return Dropped("invalid image") >= 2; }, 10))
      << diag_->Dump("depth_node");

  // No tf for the image's frame.
  image_pub_.publish(Image(0, 14.0, "nowhere"));
  EXPECT_TRUE(WaitDropped("no transform")) << diag_->Dump("depth_node");

  // NaN pose (tf2 refuses it, so there is no transform at that stamp).
  const long before_nan = diag_->Get("depth_node", "frames dropped");
  Tf(0, 15.0, /*nan=*/true);
  ros::WallDuration(0.05).sleep();
  image_pub_.publish(Image(0, 15.0));
  EXPECT_TRUE(WaitFor(
      [&] { return diag_->Get("depth_node", "frames dropped") > before_nan; },
      10));

  // A good frame is accepted (becomes the first keyframe) ...
  Good(0, 16.0);
  EXPECT_TRUE(WaitFor(
      [&] { return diag_->Get("depth_node", "keyframes created") >= 1; }, 10))
      << diag_->Dump("depth_node");
  // ... and an older stamp afterwards is out of order.
  Good(1, 15.9);
  EXPECT_TRUE(WaitDropped("out of order")) << diag_->Dump("depth_node");

  // A flood (far faster than 10x the recorded rate): frames are dropped by
  // the bounded input queue, not piled up.
  const long before_flood = Dropped("input queue full");
  for (int k = 0; k < 300; ++k) Good(k % 4, 20.0 + 0.01 * k);
  EXPECT_TRUE(
      WaitFor([&] { return Dropped("input queue full") > before_flood; }, 20))
      << diag_->Dump("depth_node");
  EXPECT_LE(diag_->Get("depth_node", "input queue length"),
            diag_->Get("depth_node", "input queue size"));
  EXPECT_LE(diag_->Get("depth_node", "keyframes held"), 40);

  // Fusion node: a malformed depth view is dropped and counted.
  wild_mvs::DepthView bad;
  bad.header.stamp = ros::Time(30.0);
  bad.camera_pose.header.frame_id = "world";
  bad.depth.encoding = "32FC1";
  bad.depth.width = 10;
  bad.depth.height = 10;
  bad.depth.step = 40;  // but no data
  view_pub_.publish(bad);
  EXPECT_TRUE(WaitFor(
      [&] { return diag_->Dropped("fusion_node", "invalid depth_view") > 0; },
      10))
      << diag_->Dump("fusion_node");

  // Both nodes are still alive (diagnostics keep coming) and their memory
  // stayed bounded.
  const long received = diag_->Get("depth_node", "frames received");
  Good(2, 100.0);
  EXPECT_TRUE(WaitFor(
      [&] { return diag_->Get("depth_node", "frames received") > received; },
      10));
  const int depth_pid = NodePid("/depth_node");
  const int fusion_pid = NodePid("/fusion_node");
  ASSERT_GT(depth_pid, 0);
  ASSERT_GT(fusion_pid, 0);
  const double depth_rss = PeakRssMb(depth_pid);
  const double fusion_rss = PeakRssMb(fusion_pid);
  std::printf(
      "[bad_input] peak RSS depth_node %.0f MB, fusion_node %.0f MB; "
      "depth_node diagnostics:\n%s",
      depth_rss, fusion_rss, diag_->Dump("depth_node").c_str());
  // RSS ceilings about twice the peaks of a healthy run: a leak or an
  // unbounded queue crosses them.
  EXPECT_GT(depth_rss, 0);
  EXPECT_GT(fusion_rss, 0);
  EXPECT_LT(depth_rss, 210.0);
  EXPECT_LT(fusion_rss, 170.0);
}

}  // namespace
}  // namespace testing
}  // namespace wild_mvs

int main(int argc, char** argv) {
  ::testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "rostest_bad_input");
  return RUN_ALL_TESTS();
}
