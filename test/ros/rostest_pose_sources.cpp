// Copyright wild_mvs authors. rostest (test/ros/pose_sources.test): camera
// poses from the localisation sources robots have, published the way they
// publish them: a body frame (base_link) moving continuously, its pose at
// 100 Hz at stamps that are never the image stamps, the camera extrinsic on
// /tf_static or as a parameter, a world frame named 'odom', epoch stamps.
// Three depth nodes (Odometry, TransformStamped, PoseWithCovarianceStamped
// of the camera) must each put every keyframe at the camera's true pose:
// the pose interpolated at the image stamp (a nearest pose would be 5 mm
// off at this speed) composed with the extrinsic.
#include <geometry_msgs/PoseWithCovarianceStamped.h>
#include <geometry_msgs/TransformStamped.h>
#include <gtest/gtest.h>
#include <nav_msgs/Odometry.h>
#include <ros/ros.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/Image.h>
#include <sensor_msgs/image_encodings.h>
#include <tf2_ros/static_transform_broadcaster.h>
#include <wild_mvs/DepthView.h>

#include <Eigen/SVD>
#include <cmath>
#include <cstring>
#include <map>
#include <mutex>

#include "ros_test_scene.h"
#include "rostest_util.h"
#include "wild_mvs/core/metrics.h"
#include "wild_mvs/ros/conversions.h"
#include "wild_mvs/ros/scene_bag.h"

namespace wild_mvs {
namespace testing {
namespace {

constexpr int kViews = 5;
constexpr double kFramePeriod = 0.25;  // s between images (stream time)
constexpr double kPosePeriod = 0.01;   // 100 Hz poses
constexpr double kPoseOffset = 0.003;  // pose stamps are not image stamps
constexpr double kT0 = 1795000000.0;   // epoch stamp of the first image
constexpr double kSlowdown = 2.0;      // wall seconds per stream second

// T^s of a rigid motion T (screw interpolation): the continuous motion
// that passes through identity at s = 0 and T at s = 1.
Eigen::Isometry3d ScrewPower(const Eigen::Isometry3d& T, double s) {
  const Eigen::AngleAxisd aa(T.linear());
  Eigen::Isometry3d out = Eigen::Isometry3d::Identity();
  if (std::abs(aa.angle()) < 1e-12) {
    out.translation() = s * T.translation();
    return out;
  }
  const Eigen::Vector3d a = aa.axis(), t = T.translation();
  const double d = a.dot(t);  // slide along the axis
  // A point p on the axis: (I - R) p = t - d a.
  const Eigen::Matrix3d A = Eigen::Matrix3d::Identity() - T.linear();
  const Eigen::Vector3d p =
      A.jacobiSvd(Eigen::ComputeFullU | Eigen::ComputeFullV).solve(t - d * a);
  const Eigen::Matrix3d Rs =
      Eigen::AngleAxisd(s * aa.angle(), a).toRotationMatrix();
  out.linear() = Rs;
  out.translation() = (Eigen::Matrix3d::Identity() - Rs) * p + s * d * a;
  return out;
}

Eigen::Isometry3d WorldFromCamera(const Camera& cam) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = cam.R.transpose();
  T.translation() = cam.Center();
  return T;
}

// The camera's true pose at stream time t (s after kT0): the screw motion
// between consecutive views, through every view at its image stamp.
Eigen::Isometry3d CameraAt(const SyntheticScene& s, double t) {
  const int n = static_cast<int>(s.scene.views.size());
  int i = static_cast<int>(std::floor(t / kFramePeriod));
  i = std::max(0, std::min(n - 2, i));
  const Eigen::Isometry3d Ti = WorldFromCamera(s.scene.views[i].camera);
  const Eigen::Isometry3d Tj = WorldFromCamera(s.scene.views[i + 1].camera);
  const double u = t / kFramePeriod - i;  // may leave [0, 1] at the ends
  return ScrewPower(Tj * Ti.inverse(), u) * Ti;
}

geometry_msgs::Pose PoseMsg(const Eigen::Isometry3d& T) {
  geometry_msgs::Pose p;
  const Eigen::Quaterniond q(T.linear());
  p.position.x = T.translation().x();
  p.position.y = T.translation().y();
  p.position.z = T.translation().z();
  p.orientation.x = q.x();
  p.orientation.y = q.y();
  p.orientation.z = q.z();
  p.orientation.w = q.w();
  return p;
}

const std::vector<std::string> kNodes = {"odom", "tfmsg", "pwc"};

// The stream published once to the three nodes, and their depth views. The
// subscriptions and the spinner stay up for the cases (the diagnostics keep
// arriving). A step that does not complete ends the run; `failure` says
// which.
class PoseSourcesRun {
  ros::NodeHandle nh_;  // first: the members below use it

 public:
  PoseSourcesRun() : diag(nh_), spinner_(2) {}
  // No callback may run while the members it uses are destroyed.
  ~PoseSourcesRun() { spinner_.stop(); }

  void Run() {
    scene = Render(RosTestSpec(kViews));
    // The camera optical frame in base_link: REP 103 optical axes (z
    // forward = body x) and an offset; the same as ~camera_extrinsic in the
    // launch.
    Eigen::Isometry3d body_T_cam = Eigen::Isometry3d::Identity();
    body_T_cam.linear() =
        Eigen::Quaterniond(0.5, -0.5, 0.5, -0.5).toRotationMatrix();
    body_T_cam.translation() = Eigen::Vector3d(0.12, -0.03, 0.25);
    cam_T_body_ = body_T_cam.inverse();
    geometry_msgs::TransformStamped ext;
    ext.header.stamp = ros::Time(kT0 - 10);
    ext.header.frame_id = "base_link";
    ext.child_frame_id = "camera_optical_frame";
    const geometry_msgs::Pose p = PoseMsg(body_T_cam);
    ext.transform.translation.x = p.position.x;
    ext.transform.translation.y = p.position.y;
    ext.transform.translation.z = p.position.z;
    ext.transform.rotation = p.orientation;
    static_tf_.sendTransform(ext);
    Advertise();
    spinner_.start();
    if (!WaitFor(
            [&] {
              for (const auto& s : subs_)
                if (s.getNumPublishers() == 0) return false;
              return image_pub_.getNumSubscribers() >= 3 &&
                     info_pub_.getNumSubscribers() >= 3 &&
                     odom_pub_.getNumSubscribers() >= 1 &&
                     tf_pub_.getNumSubscribers() >= 1 &&
                     pwc_pub_.getNumSubscribers() >= 1;
            },
            60)) {
      failure = "the three depth nodes did not come up";
      return;
    }
    PublishStream();
    WaitFor(
        [&] {
          std::lock_guard<std::mutex> lock(mutex_);
          for (const std::string& n : kNodes)
            if (views_[n].size() < static_cast<size_t>(kViews - 1))
              return false;
          return true;
        },
        200);
    complete = true;
  }

  std::map<int, wild_mvs::DepthViewConstPtr> Views(const std::string& node) {
    std::lock_guard<std::mutex> lock(mutex_);
    return views_[node];
  }

  SyntheticScene scene;
  DiagnosticsWatch diag;
  bool complete = false;
  std::string failure;

 private:
  void Advertise() {
    odom_pub_ = nh_.advertise<nav_msgs::Odometry>("/odometry", 200);
    tf_pub_ =
        nh_.advertise<geometry_msgs::TransformStamped>("/body_transform", 200);
    pwc_pub_ = nh_.advertise<geometry_msgs::PoseWithCovarianceStamped>(
        "/camera_pose_cov", 200);
    image_pub_ = nh_.advertise<sensor_msgs::Image>("/camera/image_raw", 10);
    info_pub_ =
        nh_.advertise<sensor_msgs::CameraInfo>("/camera/camera_info", 10);
    for (const std::string& node : kNodes) {
      subs_.push_back(nh_.subscribe<wild_mvs::DepthView>(
          "/" + node + "/depth_view", 20,
          [this, node](const wild_mvs::DepthViewConstPtr& m) {
            const int i = static_cast<int>(
                std::lround((m->header.stamp.toSec() - kT0) / kFramePeriod));
            std::lock_guard<std::mutex> lock(mutex_);
            views_[node][i] = m;
          }));
    }
  }

  void PublishImage(int i) {
    const Camera& cam = scene.scene.views[i].camera;
    sensor_msgs::CameraInfo info = ros1::CameraInfoFromCamera(cam);
    info.header.stamp = ros::Time(kT0 + i * kFramePeriod);
    info.header.frame_id = "camera_optical_frame";
    sensor_msgs::Image im = ros1::MatToMsg(ros1::LinearToSrgb8(scene.images[i]),
                                           sensor_msgs::image_encodings::RGB8);
    im.header = info.header;
    info_pub_.publish(info);
    image_pub_.publish(im);
  }

  // The body's pose at stream time t on each pose topic.
  void PublishPoses(double t) {
    const Eigen::Isometry3d world_T_cam = CameraAt(scene, t);
    const Eigen::Isometry3d world_T_body = world_T_cam * cam_T_body_;
    std_msgs::Header h;
    h.stamp = ros::Time(kT0 + t);
    h.frame_id = "odom";
    nav_msgs::Odometry odom;
    odom.header = h;
    odom.child_frame_id = "base_link";
    odom.pose.pose = PoseMsg(world_T_body);
    odom_pub_.publish(odom);
    geometry_msgs::TransformStamped tfm;
    tfm.header = h;
    tfm.child_frame_id = "base_link";
    const geometry_msgs::Pose pb = PoseMsg(world_T_body);
    tfm.transform.translation.x = pb.position.x;
    tfm.transform.translation.y = pb.position.y;
    tfm.transform.translation.z = pb.position.z;
    tfm.transform.rotation = pb.orientation;
    tf_pub_.publish(tfm);
    geometry_msgs::PoseWithCovarianceStamped pwc;
    pwc.header = h;
    pwc.header.frame_id = "/odom";  // a leading slash, as old drivers send
    pwc.pose.pose = PoseMsg(world_T_cam);
    pwc_pub_.publish(pwc);
  }

  // The stream in stamp order: poses from 0.1 s before the first image to
  // 0.1 s after the last, images at their stamps; paced like a live stream
  // (slowed down), by wall time.
  void PublishStream() {
    const double t_end = (kViews - 1) * kFramePeriod + 0.1;
    int next_image = 0;
    const ros::WallTime wall0 = ros::WallTime::now();
    for (double t = -0.1 + kPoseOffset; t <= t_end + 1e-9; t += kPosePeriod) {
      while (next_image < kViews && next_image * kFramePeriod <= t)
        PublishImage(next_image++);
      PublishPoses(t);
      const ros::WallTime due =
          wall0 + ros::WallDuration((t + 0.1) * kSlowdown);
      const ros::WallDuration wait = due - ros::WallTime::now();
      if (wait > ros::WallDuration(0)) wait.sleep();
    }
  }

  ros::AsyncSpinner spinner_;
  tf2_ros::StaticTransformBroadcaster static_tf_;
  Eigen::Isometry3d cam_T_body_;
  ros::Publisher odom_pub_, tf_pub_, pwc_pub_, image_pub_, info_pub_;
  std::vector<ros::Subscriber> subs_;
  std::mutex mutex_;
  std::map<std::string, std::map<int, wild_mvs::DepthViewConstPtr>> views_;
};

// The camera a depth view names: its camera_info at its pose.
Camera CameraOf(const wild_mvs::DepthView& m) {
  Camera cam;
  ros1::CameraFromCameraInfo(m.camera_info, &cam, nullptr);
  ros1::SetCameraPose(m.camera_pose.pose, &cam);
  return cam;
}

// One case per outcome and pose source (the parameter: the node's name).
using PoseSources =
    RunOnce<PoseSourcesRun, ::testing::TestWithParam<std::string>>;

TEST_P(PoseSources, EveryKeyframeGetsADepthView) {
  const std::string& node = GetParam();
  const auto views = run_->Views(node);
  EXPECT_GE(views.size(), static_cast<size_t>(kViews - 1))
      << run_->diag.Dump(node);
  for (const auto& [i, msg] : views) {
    EXPECT_GE(i, 0);
    EXPECT_LT(i, kViews);
  }
  std::printf("[pose_sources] %s: %zu depth maps\n", node.c_str(),
              views.size());
}

// The pose interpolated at the image stamp composed with the extrinsic (a
// nearest pose would be 5 mm off at this speed).
TEST_P(PoseSources, KeyframesAreAtTheCamerasTruePose) {
  for (const auto& [i, msg] : run_->Views(GetParam())) {
    ASSERT_GE(i, 0);
    ASSERT_LT(i, kViews);
    const Camera cam = CameraOf(*msg);
    const Camera& truth = run_->scene.scene.views[i].camera;
    EXPECT_LT((cam.Center() - truth.Center()).norm(), 5e-4) << "view " << i;
    EXPECT_LT(Eigen::AngleAxisd(cam.R * truth.R.transpose()).angle(), 2e-4)
        << "view " << i;
  }
}

TEST_P(PoseSources, DepthMapsMatchTheGroundTruth) {
  for (const auto& [i, msg] : run_->Views(GetParam())) {
    ASSERT_GE(i, 0);
    ASSERT_LT(i, kViews);
    const Camera cam = CameraOf(*msg);
    cv::Mat d = ros1::FloatImageFromMsg(msg->depth, 1, "depth");
    d.forEach<float>([](float& v, const int*) {
      if (std::isnan(v)) v = 0;
    });
    // Scored in the true camera at the map's size (a preview is half the
    // image's): the pose itself is checked above.
    const Camera& truth = run_->scene.scene.views[i].camera;
    const Camera at_map = truth.Resized(cam.width, cam.height);
    const DepthMetrics m =
        EvaluateDepth(d, at_map, run_->scene.depth[i], truth);
    EXPECT_GT(m.completeness, 0.3) << "view " << i << ": " << m.ToString();
    EXPECT_LT(m.median_rel_error, 0.01) << "view " << i;
  }
}

TEST_P(PoseSources, NoFrameIsDropped) {
  EXPECT_EQ(run_->diag.Get(GetParam(), "frames dropped"), 0)
      << run_->diag.Dump(GetParam());
}

INSTANTIATE_TEST_SUITE_P(Sources, PoseSources, ::testing::ValuesIn(kNodes),
                         [](const ::testing::TestParamInfo<std::string>& info) {
                           return info.param;
                         });

}  // namespace
}  // namespace testing
}  // namespace wild_mvs

int main(int argc, char** argv) {
  ::testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "rostest_pose_sources");
  return RUN_ALL_TESTS();
}
