// Copyright wild_mvs authors. rostest (test/ros/real_bag*.test): a bag
// recorded the way real robots and public datasets record (real_world_bag.h:
// epoch stamps with sub-second parts, leading-slash frame ids, a body frame
// on /tf at 100 Hz plus a /tf_static extrinsic, a 30 Hz camera lingering on
// each view, /camera/rgb/image_color or only its /compressed) is played with
// `rosbag play --clock` into the depth and fusion nodes (use_sim_time) and
// depth_image_proc's point_cloud_xyz. Checks:
//   - every output header stamp is bit-for-bit an input image stamp;
//   - one depth map per view (the keyframe selection takes one frame of
//     each lingering group), matching the exact ground truth;
//   - output frame ids have no leading '/';
//   - the final fused cloud comes after the bag ended (/clock stopped) and
//     carries the newest fused view's stamp;
//   - depth_image_proc's cloud of /depth_node/depth/image_rect agrees with
//     the depth node's own /depth_node/points.
// Private params: ~variant (rgb8 | bgr8 | mono8 | compressed, the last one
// writes only JPEG <image>/compressed; the .test sets
// depth_node/image_transport=compressed), ~rate (play rate), ~views,
// ~leading_slash (default true).
#include <gtest/gtest.h>
#include <ros/ros.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/Image.h>
#include <sensor_msgs/PointCloud2.h>
#include <wild_mvs/DepthView.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <map>
#include <mutex>
#include <set>
#include <sstream>
#include <vector>

#include "real_world_bag.h"
#include "ros_test_scene.h"
#include "rostest_util.h"
#include "test_paths.h"
#include "wild_mvs/core/metrics.h"
#include "wild_mvs/ros/conversions.h"

namespace wild_mvs {
namespace testing {
namespace {

using Clock = std::chrono::steady_clock;

struct Received {
  std::string topic;
  ros::Time stamp;
  std::string frame_id;
};

std::string StampStr(const ros::Time& t) {
  char buf[64];
  std::snprintf(buf, sizeof(buf), "%u.%09u", t.sec, t.nsec);
  return buf;
}

bool NoLeadingSlash(const std::string& f) { return f.empty() || f[0] != '/'; }

int CountFinite(const cv::Mat& d) {
  int n = 0;
  for (int r = 0; r < d.rows; ++r)
    for (int c = 0; c < d.cols; ++c)
      if (std::isfinite(d.at<float>(r, c))) ++n;
  return n;
}

TEST(RealBag, RecordedLikeARobot) {
  ros::NodeHandle nh, pnh("~");
  std::string variant = "rgb8";
  double rate = 1.0;
  int num_views = 6;
  pnh.getParam("variant", variant);
  pnh.getParam("rate", rate);
  pnh.getParam("views", num_views);
  // ~leading_slash false: frame ids without '/' (to check this checker
  // against nodes that cannot strip it yet).
  bool leading_slash = true;
  pnh.getParam("leading_slash", leading_slash);

  const SyntheticScene scene = Render(RosTestSpec(num_views));
  const std::string dir = MakeTempDir("wild_mvs_rostest_real_bag");
  RealWorldBagOptions bo;
  bo.leading_slash = leading_slash;
  if (variant == "compressed")
    bo.compression = "jpeg";
  else
    bo.encoding = variant;
  const RealWorldBag bag = WriteRealWorldBag(scene, dir + "/real.bag", bo);
  std::printf(
      "[real_bag] variant %s: %zu images (%d views x %d frames at %d Hz), "
      "first %s, last %s\n",
      variant.c_str(), bag.image_stamps.size(), bag.NumViews(),
      bo.frames_per_view, bo.camera_rate_hz, StampStr(bag.first_stamp).c_str(),
      StampStr(bag.last_stamp).c_str());

  std::mutex mutex;
  std::vector<Received> received;  // every output header seen
  std::map<uint64_t, wild_mvs::DepthViewConstPtr> views;  // by stamp ns
  std::map<uint64_t, sensor_msgs::ImageConstPtr> depth_images;
  std::map<uint64_t, sensor_msgs::PointCloud2ConstPtr> node_points, xyz_points;
  int confidence_count = 0, info_count = 0;
  struct CloudRx {
    sensor_msgs::PointCloud2ConstPtr msg;
    Clock::time_point at;
  };
  std::vector<CloudRx> clouds;
  Clock::time_point last_view_at{};  // arrival of the newest DepthView
  auto note = [&](const std::string& topic, const std_msgs::Header& h) {
    received.push_back({topic, h.stamp, h.frame_id});
  };

  ros::Subscriber s_view = nh.subscribe<wild_mvs::DepthView>(
      "/depth_node/depth_view", 50, [&](const wild_mvs::DepthViewConstPtr& m) {
        std::lock_guard<std::mutex> lock(mutex);
        note("/depth_node/depth_view", m->header);
        note("/depth_node/depth_view camera_pose", m->camera_pose.header);
        note("/depth_node/depth_view depth", m->depth.header);
        note("/depth_node/depth_view camera_info", m->camera_info.header);
        views[m->header.stamp.toNSec()] = m;
        last_view_at = Clock::now();
      });
  ros::Subscriber s_depth = nh.subscribe<sensor_msgs::Image>(
      "/depth_node/depth/image_rect", 50,
      [&](const sensor_msgs::ImageConstPtr& m) {
        std::lock_guard<std::mutex> lock(mutex);
        note("/depth_node/depth/image_rect", m->header);
        depth_images[m->header.stamp.toNSec()] = m;
      });
  ros::Subscriber s_info = nh.subscribe<sensor_msgs::CameraInfo>(
      "/depth_node/depth/camera_info", 50,
      [&](const sensor_msgs::CameraInfoConstPtr& m) {
        std::lock_guard<std::mutex> lock(mutex);
        note("/depth_node/depth/camera_info", m->header);
        ++info_count;
      });
  ros::Subscriber s_conf = nh.subscribe<sensor_msgs::Image>(
      "/depth_node/confidence/image", 50,
      [&](const sensor_msgs::ImageConstPtr& m) {
        std::lock_guard<std::mutex> lock(mutex);
        note("/depth_node/confidence/image", m->header);
        ++confidence_count;
      });
  ros::Subscriber s_points = nh.subscribe<sensor_msgs::PointCloud2>(
      "/depth_node/points", 50, [&](const sensor_msgs::PointCloud2ConstPtr& m) {
        std::lock_guard<std::mutex> lock(mutex);
        note("/depth_node/points", m->header);
        node_points[m->header.stamp.toNSec()] = m;
      });
  ros::Subscriber s_xyz = nh.subscribe<sensor_msgs::PointCloud2>(
      "/xyz/points", 50, [&](const sensor_msgs::PointCloud2ConstPtr& m) {
        std::lock_guard<std::mutex> lock(mutex);
        note("/xyz/points", m->header);
        xyz_points[m->header.stamp.toNSec()] = m;
      });
  ros::Subscriber s_cloud = nh.subscribe<sensor_msgs::PointCloud2>(
      "/fusion_node/cloud", 5, [&](const sensor_msgs::PointCloud2ConstPtr& m) {
        std::lock_guard<std::mutex> lock(mutex);
        clouds.push_back({m, Clock::now()});
      });
  DiagnosticsWatch diag(nh);
  ros::AsyncSpinner spinner(3);
  spinner.start();

  // The nodes are up when their outputs are advertised (the new topic names
  // of the depth node: depth/image_rect, depth/camera_info,
  // confidence/image).
  const bool up = WaitFor(
      [&] {
        return s_view.getNumPublishers() > 0 &&
               s_depth.getNumPublishers() > 0 &&
               s_info.getNumPublishers() > 0 && s_conf.getNumPublishers() > 0 &&
               s_cloud.getNumPublishers() > 0 && s_xyz.getNumPublishers() > 0;
      },
      45);
  EXPECT_TRUE(up) << "publishers: depth_view " << s_view.getNumPublishers()
                  << ", depth/image_rect " << s_depth.getNumPublishers()
                  << ", depth/camera_info " << s_info.getNumPublishers()
                  << ", confidence/image " << s_conf.getNumPublishers()
                  << ", fusion cloud " << s_cloud.getNumPublishers()
                  << ", /xyz/points " << s_xyz.getNumPublishers();
  ASSERT_GT(s_view.getNumPublishers(), 0u) << "no depth node";
  ros::WallDuration(2.0).sleep();  // let the subscriptions settle

  const Clock::time_point t0 = Clock::now();
  // --delay: the subscribers connect to the newly advertised topics first
  // (the bag is under 2 s long; its first frames would be lost otherwise).
  PlayBag(bag.path, rate, "--clock --delay 3").join();
  const Clock::time_point bag_ended = Clock::now();
  std::printf("[real_bag] bag played in %.1f s (wall)\n",
              std::chrono::duration<double>(bag_ended - t0).count());

  // Every view gets its depth map (after the bag, the node must flush on
  // wall / steady time: /clock has stopped).
  // The view of an output stamp: exact, or (so that a rounded stamp, which
  // fails the stamp check below, still gets its depth scored) the nearest
  // image stamp within 1 ms.
  auto view_of = [&](const ros::Time& t) {
    const int v = bag.ViewOfStamp(t);
    if (v >= 0) return v;
    const ros::Time n = bag.NearestImageStamp(t);
    return n.isZero() ? -1 : bag.ViewOfStamp(n);
  };
  auto views_covered = [&] {
    std::set<int> s;
    for (const auto& [ns, m] : views) {
      const int v = view_of(m->header.stamp);
      if (v >= 0) s.insert(v);
    }
    return s;
  };
  // Wait budget (the .test's time-limit is 330 s): 45 s for the nodes +
  // the bag + at most 180 s here + at most 45 s for the final cloud. Give
  // up after 90 s when not a single depth map came.
  WaitFor(
      [&] {
        std::lock_guard<std::mutex> lock(mutex);
        if (views.empty() &&
            Clock::now() > bag_ended + std::chrono::seconds(90))
          return true;
        return views_covered().size() >= static_cast<size_t>(num_views) &&
               depth_images.size() >= views.size() &&
               xyz_points.size() >= views.size() &&
               node_points.size() >= views.size();
      },
      180);
  // Outputs of a last depth map still on the way.
  ros::WallDuration(1.0).sleep();

  std::unique_lock<std::mutex> lock(mutex);
  // --- stamps: bit for bit the input image stamps -------------------------
  int bad_stamps = 0, bad_frames = 0;
  std::ostringstream stamp_log, frame_log;
  for (const Received& r : received) {
    if (r.topic == "/depth_node/depth_view camera_pose" ||
        r.topic == "/depth_node/depth_view depth" ||
        r.topic == "/depth_node/depth_view camera_info") {
      // Inner headers: the stamp may be unset (0) but never another time.
      if (!r.stamp.isZero() && !bag.IsImageStamp(r.stamp) && bad_stamps++ < 10)
        stamp_log << "  " << r.topic << " " << StampStr(r.stamp) << "\n";
    } else if (!bag.IsImageStamp(r.stamp) && bad_stamps++ < 10) {
      stamp_log << "  " << r.topic << " " << StampStr(r.stamp) << "\n";
    }
    if (!NoLeadingSlash(r.frame_id) && bad_frames++ < 10)
      frame_log << "  " << r.topic << " '" << r.frame_id << "'\n";
  }
  EXPECT_EQ(bad_stamps, 0)
      << "output stamps that are not an input image stamp (first 10):\n"
      << stamp_log.str();
  EXPECT_EQ(bad_frames, 0) << "frame ids with a leading '/':\n"
                           << frame_log.str();

  // --- one depth map per view, at the ground truth ------------------------
  const std::set<int> covered = views_covered();
  std::ostringstream missing;
  for (int v = 0; v < num_views; ++v)
    if (!covered.count(v)) missing << " " << v;
  EXPECT_EQ(covered.size(), static_cast<size_t>(num_views))
      << "views without a depth map:" << missing.str() << "\n"
      << diag.Dump("depth_node");
  std::map<int, std::set<uint64_t>> keyframes_of_view;
  uint64_t max_view_ns = 0;
  for (const auto& [ns, msg] : views) {
    const int v = view_of(msg->header.stamp);
    max_view_ns = std::max(max_view_ns, ns);
    EXPECT_GE(v, 0) << "DepthView stamp " << StampStr(msg->header.stamp)
                    << " is not within 1 ms of any image stamp";
    if (v < 0) continue;
    keyframes_of_view[v].insert(ns);
    const ros::Time exact = bag.NearestImageStamp(msg->header.stamp);
    std::printf("[real_bag] view %d: DepthView %s = frame %d of the view%s\n",
                v, StampStr(msg->header.stamp).c_str(), bag.FrameInView(exact),
                bag.IsImageStamp(msg->header.stamp) ? "" : " (INEXACT stamp)");
    EXPECT_EQ(msg->header.frame_id, "camera_rgb_optical_frame") << "view " << v;
    EXPECT_EQ(msg->camera_pose.header.frame_id, "world") << "view " << v;
    Camera cam;
    ros1::CameraFromCameraInfo(msg->camera_info, &cam, nullptr);
    ros1::SetCameraPose(msg->camera_pose.pose, &cam);
    const Camera& gt = bag.view_cameras[v];
    // The pose went through /tf (world -> base_link) and /tf_static
    // (base_link -> optical frame).
    EXPECT_LT((cam.Center() - gt.Center()).norm(), 1e-4) << "view " << v;
    EXPECT_LT((cam.R - gt.R).norm(), 1e-4) << "view " << v;
    cv::Mat d = ros1::FloatImageFromMsg(msg->depth, 1, "depth");
    d.forEach<float>([](float& x, const int*) {
      if (std::isnan(x)) x = 0;
    });
    const DepthMetrics m = EvaluateDepth(d, cam, scene.depth[v], gt);
    const bool mono = variant == "mono8";
    EXPECT_GT(m.completeness, mono ? 0.3 : 0.4)
        << "view " << v << ": " << m.ToString();
    EXPECT_LT(m.median_rel_error, mono ? 0.02 : 0.01)
        << "view " << v << ": " << m.ToString();
  }
  for (const auto& [v, stamps] : keyframes_of_view)
    EXPECT_EQ(stamps.size(), 1u)
        << "view " << v << " (" << bo.frames_per_view
        << " frames of the same pose) gave " << stamps.size()
        << " keyframes: the lingering frames must not become keyframes";

  // --- the depth image outputs ---------------------------------------------
  EXPECT_EQ(depth_images.size(), views.size());
  EXPECT_GE(info_count, static_cast<int>(views.size()));
  EXPECT_GE(confidence_count, static_cast<int>(views.size()));
  for (const auto& [ns, img] : depth_images) {
    EXPECT_EQ(img->encoding, "32FC1");
    EXPECT_EQ(img->header.frame_id, "camera_rgb_optical_frame");
    EXPECT_TRUE(views.count(ns))
        << "depth image " << StampStr(img->header.stamp)
        << " without a DepthView";
  }

  // --- depth_image_proc's cloud vs the node's own ---------------------------
  int compared = 0;
  for (const auto& [ns, img] : depth_images) {
    auto xyz = xyz_points.find(ns);
    EXPECT_NE(xyz, xyz_points.end())
        << "no /xyz/points for depth image " << StampStr(img->header.stamp);
    if (xyz == xyz_points.end()) continue;
    EXPECT_EQ(xyz->second->header.frame_id, img->header.frame_id);
    const cv::Mat d = ros1::FloatImageFromMsg(*img, 1, "depth");
    const int valid = CountFinite(d);
    // point_cloud_xyz: organised, NaN where the depth is NaN.
    PointCloud pc = CloudFromMsg(*xyz->second);
    std::vector<Eigen::Vector3d> finite;
    for (const auto& p : pc.xyz)
      if (p.allFinite()) finite.push_back(p.cast<double>());
    EXPECT_EQ(static_cast<int>(finite.size()), valid)
        << "depth image " << StampStr(img->header.stamp);
    EXPECT_GT(valid, 0);
    // The node's per-view cloud (world frame, every valid pixel in pixel
    // order) = depth_image_proc's points moved by the DepthView's pose.
    auto np = node_points.find(ns);
    auto view = views.find(ns);
    EXPECT_NE(np, node_points.end())
        << "no /depth_node/points for " << StampStr(img->header.stamp);
    if (np == node_points.end() || view == views.end()) continue;
    EXPECT_EQ(np->second->header.frame_id, "world");
    const PointCloud world = CloudFromMsg(*np->second);
    EXPECT_EQ(world.xyz.size(), finite.size());
    if (world.xyz.size() != finite.size() || finite.empty()) continue;
    Camera cam;
    ros1::SetCameraPose(view->second->camera_pose.pose, &cam);
    double max_err = 0;
    for (size_t i = 0; i < finite.size(); ++i)
      max_err = std::max(
          max_err,
          (cam.CameraToWorld(finite[i]) - world.xyz[i].cast<double>()).norm());
    // Same pixel convention (ROS cx = core cx - 0.5) and intrinsics: half
    // a pixel off would be ~1 cm at these depths.
    EXPECT_LT(max_err, 2e-3) << "depth_image_proc vs /depth_node/points, view "
                             << StampStr(img->header.stamp);
    ++compared;
  }
  std::printf(
      "[real_bag] %zu depth views, %zu depth images, %zu xyz clouds, "
      "%d compared point by point\n",
      views.size(), depth_images.size(), xyz_points.size(), compared);
  EXPECT_GT(compared, 0);

  // --- the fused cloud: after the newest view, stamped with it -----------
  // The depth maps usually lag the bag: then that cloud comes after /clock
  // stopped, published by a timer that does not run on ROS time. (When the
  // last view was fused before `rosbag play` exited, its cloud may come
  // before, and nothing changes after it.)
  // (wait without the lock: the callbacks need it)
  ASSERT_FALSE(views.empty()) << "no DepthView at all: nothing to fuse\n"
                              << diag.Dump("depth_node");
  lock.unlock();
  const bool final_cloud = WaitFor(
      [&] {
        std::lock_guard<std::mutex> l(mutex);
        for (const CloudRx& c : clouds)
          // (No arrival-order check: the stamp says the newest view was
          // fused, and the test's own DepthView callback may run after
          // the fusion node has already published from that view.)
          if (c.msg->header.stamp.toNSec() == max_view_ns &&
              c.msg->width * c.msg->height > 0)
            return true;
        return false;
      },
      45);
  lock.lock();
  std::ostringstream cloud_log;
  for (const CloudRx& c : clouds)
    cloud_log << "  stamp " << StampStr(c.msg->header.stamp) << " at "
              << std::chrono::duration<double>(c.at - bag_ended).count()
              << " s after the bag, " << c.msg->width * c.msg->height
              << " points, frame '" << c.msg->header.frame_id << "'\n";
  EXPECT_TRUE(final_cloud)
      << "no fused cloud after the newest DepthView (which came "
      << std::chrono::duration<double>(last_view_at - bag_ended).count()
      << " s after the bag ended and /clock stopped) with its stamp "
      << StampStr(TimeFromNSec(max_view_ns)) << "; clouds received:\n"
      << cloud_log.str() << diag.Dump("fusion_node");
  for (const CloudRx& c : clouds) {
    EXPECT_TRUE(bag.IsImageStamp(c.msg->header.stamp) ||
                c.msg->header.stamp.isZero())
        << "fused cloud stamp " << StampStr(c.msg->header.stamp)
        << " is not an input stamp (wall clock?)";
    EXPECT_EQ(c.msg->header.frame_id, "world");
  }
  std::printf("[real_bag] %zu fused clouds received\n", clouds.size());
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace testing
}  // namespace wild_mvs

int main(int argc, char** argv) {
  ::testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "rostest_real_bag");
  return RUN_ALL_TESTS();
}
