// Copyright wild_mvs authors. rostest (test/ros/pipeline.test): a bag made
// from a synthetic scene with exact ground truth is played through the depth
// and fusion nodes; the published depth images must match the ground truth,
// the fused cloud must arrive and score, and ~save must write a valid PLY.
#include <gtest/gtest.h>
#include <ros/ros.h>
#include <sensor_msgs/Image.h>
#include <visualization_msgs/Marker.h>
#include <wild_mvs/DepthView.h>
#include <wild_mvs/SaveCloud.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
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
constexpr int kViews = 6;

TEST(Pipeline, BagThroughDepthAndFusionNodes) {
  ros::NodeHandle nh;
  const SyntheticScene scene = Render(RosTestSpec(kViews));
  const std::string dir = MakeTempDir("wild_mvs_rostest_pipeline");
  const std::string bag = dir + "/scene.bag";
  ros1::SceneBagOptions bo;
  bo.rate = kRate;
  bo.with_points = true;
  ros1::WriteSceneBag(
      scene.scene, [&](int i) { return ros1::LinearToSrgb8(scene.images[i]); },
      bag, bo);

  // WILD_MVS_KEEP_BAG=PATH keeps a copy of the bag (demos, screenshots).
  if (const char* keep = std::getenv("WILD_MVS_KEEP_BAG"))
    std::filesystem::copy_file(
        bag, keep, std::filesystem::copy_options::overwrite_existing);
  std::mutex mutex;
  std::map<int, sensor_msgs::ImageConstPtr> depth;  // by view index
  std::map<int, wild_mvs::DepthViewConstPtr> views;
  sensor_msgs::PointCloud2ConstPtr cloud;
  auto index_of = [&](const ros::Time& t) {
    return static_cast<int>(std::lround((t.toSec() - bo.start_time) * kRate));
  };
  ros::Subscriber s1 = nh.subscribe<sensor_msgs::Image>(
      "/depth_node/depth/image_rect", 20,
      [&](const sensor_msgs::ImageConstPtr& m) {
        std::lock_guard<std::mutex> lock(mutex);
        depth[index_of(m->header.stamp)] = m;
      });
  ros::Subscriber s2 = nh.subscribe<wild_mvs::DepthView>(
      "/depth_node/depth_view", 20, [&](const wild_mvs::DepthViewConstPtr& m) {
        std::lock_guard<std::mutex> lock(mutex);
        views[index_of(m->header.stamp)] = m;
      });
  ros::Subscriber s3 = nh.subscribe<sensor_msgs::PointCloud2>(
      "/fusion_node/cloud", 2, [&](const sensor_msgs::PointCloud2ConstPtr& m) {
        std::lock_guard<std::mutex> lock(mutex);
        cloud = m;
      });
  visualization_msgs::MarkerConstPtr mesh;
  ros::Subscriber s4 = nh.subscribe<visualization_msgs::Marker>(
      "/fusion_node/mesh", 2, [&](const visualization_msgs::MarkerConstPtr& m) {
        std::lock_guard<std::mutex> lock(mutex);
        mesh = m;
      });
  DiagnosticsWatch diag(nh);
  ros::AsyncSpinner spinner(2);
  spinner.start();
  // The nodes are up when their outputs are advertised.
  ASSERT_TRUE(WaitFor(
      [&] { return s1.getNumPublishers() > 0 && s3.getNumPublishers() > 0; },
      30));
  ros::WallDuration(1.0).sleep();  // let the subscriptions settle
  const ros::WallTime t0 = ros::WallTime::now();
  std::thread player = PlayBag(bag, 1.0);
  player.join();
  const double play_seconds = (ros::WallTime::now() - t0).toSec();
  // Every keyframe with enough neighbours gets its depth map.
  WaitFor(
      [&] {
        std::lock_guard<std::mutex> lock(mutex);
        return views.size() >= static_cast<size_t>(kViews);
      },
      150);
  const double depth_seconds = (ros::WallTime::now() - t0).toSec();
  {
    std::lock_guard<std::mutex> lock(mutex);
    EXPECT_GE(views.size(), static_cast<size_t>(kViews - 1))
        << diag.Dump("depth_node");
    EXPECT_EQ(depth.size(), views.size());
    for (const auto& [i, msg] : depth) {
      ASSERT_GE(i, 0);
      ASSERT_LT(i, kViews);
      EXPECT_EQ(msg->encoding, "32FC1");
      ASSERT_TRUE(views.count(i));
      // Depth in metres along z with NaN unknown (REP 118), at the depth
      // map's resolution given by the DepthView's camera_info.
      Camera cam;
      ros1::CameraFromCameraInfo(views[i]->camera_info, &cam, nullptr);
      ros1::SetCameraPose(views[i]->camera_pose.pose, &cam);
      EXPECT_LT((cam.Center() - scene.scene.views[i].camera.Center()).norm(),
                1e-4);
      cv::Mat d = ros1::FloatImageFromMsg(*msg, 1, "depth");
      int nan = 0;
      d.forEach<float>([&nan](float& v, const int*) {
        if (std::isnan(v)) v = 0;
      });
      (void)nan;
      const DepthMetrics m =
          EvaluateDepth(d, cam, scene.depth[i], scene.scene.views[i].camera);
      EXPECT_GT(m.completeness, 0.4) << "view " << i << ": " << m.ToString();
      EXPECT_LT(m.median_rel_error, 0.01) << "view " << i;
      EXPECT_GT(m.relative_accuracy[2], 0.85) << "view " << i;  // within 5 %
    }
  }
  // The fused cloud arrives (latched, publish_period) and scores.
  ASSERT_TRUE(WaitFor(
      [&] {
        std::lock_guard<std::mutex> lock(mutex);
        return cloud && cloud->width * cloud->height > 1000 &&
               diag.Get("fusion_node", "views fused") >=
                   static_cast<long>(views.size());
      },
      30))
      << diag.Dump("fusion_node");
  ros::WallDuration(1.5).sleep();  // the cloud after the last view
  PointCloud fused;
  {
    std::lock_guard<std::mutex> lock(mutex);
    EXPECT_EQ(cloud->header.frame_id, "world");
    fused = CloudFromMsg(*cloud);
  }
  CloudMetricsOptions co;
  co.taus = {0.02, 0.04};
  const CloudMetrics cm = EvaluateCloud(fused, scene.GroundTruthCloud(1), co);
  EXPECT_GT(cm.precision[1], 0.9) << cm.ToString();
  EXPECT_GT(cm.recall[1], 0.3) << cm.ToString();

  // The mesh Marker (mesh_period 2 s, Poisson on the fused cloud): a
  // triangle list in the world frame whose triangles are finite,
  // non-degenerate and lie on the scene (centroids vs the GT surface).
  ASSERT_TRUE(WaitFor(
      [&] {
        std::lock_guard<std::mutex> lock(mutex);
        return mesh != nullptr;
      },
      30))
      << "no mesh on /fusion_node/mesh";
  size_t triangles = 0, degenerate = 0;
  PointCloud centroids;
  {
    std::lock_guard<std::mutex> lock(mutex);
    EXPECT_EQ(mesh->type, visualization_msgs::Marker::TRIANGLE_LIST);
    EXPECT_EQ(mesh->action, visualization_msgs::Marker::ADD);
    EXPECT_EQ(mesh->header.frame_id, "world");
    EXPECT_DOUBLE_EQ(mesh->pose.orientation.w, 1.0);
    ASSERT_EQ(mesh->points.size() % 3, 0u);
    EXPECT_TRUE(mesh->colors.empty() ||
                mesh->colors.size() == mesh->points.size());
    triangles = mesh->points.size() / 3;
    for (size_t t = 0; t < triangles; ++t) {
      Eigen::Vector3d p[3];
      for (int k = 0; k < 3; ++k) {
        const auto& q = mesh->points[3 * t + k];
        p[k] = Eigen::Vector3d(q.x, q.y, q.z);
        ASSERT_TRUE(p[k].allFinite()) << "triangle " << t;
      }
      if ((p[1] - p[0]).cross(p[2] - p[0]).norm() < 1e-12) ++degenerate;
      centroids.xyz.push_back(((p[0] + p[1] + p[2]) / 3).cast<float>());
    }
  }
  EXPECT_GT(triangles, 500u);
  EXPECT_LT(degenerate, triangles / 100 + 1);
  const CloudMetrics mm =
      EvaluateCloud(centroids, scene.GroundTruthCloud(1), co);
  EXPECT_GT(mm.precision[1], 0.7) << "mesh: " << mm.ToString();

  // ~save writes a valid binary PLY atomically.
  wild_mvs::SaveCloud srv;
  srv.request.path = dir + "/saved.ply";
  ASSERT_TRUE(ros::service::waitForService("/fusion_node/save", 10000));
  ASSERT_TRUE(ros::service::call("/fusion_node/save", srv));
  EXPECT_TRUE(srv.response.success) << srv.response.message;
  EXPECT_GT(srv.response.num_points, 1000u);
  std::ifstream ply(srv.request.path, std::ios::binary);
  ASSERT_TRUE(ply.good());
  std::string line, header;
  size_t vertices = 0, header_bytes = 0, stride = 0;
  while (std::getline(ply, line)) {
    header_bytes += line.size() + 1;
    header += line + "\n";
    if (line.rfind("element vertex ", 0) == 0)
      vertices = std::stoul(line.substr(15));
    if (line.rfind("property float", 0) == 0) stride += 4;
    if (line.rfind("property uchar", 0) == 0) stride += 1;
    if (line == "end_header") break;
  }
  EXPECT_EQ(header.rfind("ply\nformat binary_little_endian 1.0\n", 0), 0u);
  EXPECT_EQ(vertices, srv.response.num_points);
  EXPECT_EQ(std::filesystem::file_size(srv.request.path),
            header_bytes + vertices * stride);
  // A save to an unwritable place fails cleanly and the node stays up.
  srv.request.path = "/proc/wild_mvs_cannot_write/cloud.ply";
  ASSERT_TRUE(ros::service::call("/fusion_node/save", srv));
  EXPECT_FALSE(srv.response.success);

  // Diagnostics report the work.
  EXPECT_GE(diag.Get("depth_node", "depth maps"),
            static_cast<long>(views.size()));
  EXPECT_EQ(diag.Get("depth_node", "frames dropped"), 0)
      << diag.Dump("depth_node");
  const double depth_rss = PeakRssMb(NodePid("/depth_node"));
  const double fusion_rss = PeakRssMb(NodePid("/fusion_node"));
  std::printf(
      "[pipeline] %d views at %.1f Hz: bag played in %.1f s, depth maps "
      "after %.1f s; %zu fused points; precision@4cm %.3f recall@4cm %.3f; "
      "mesh %zu triangles, centroid precision@4cm %.3f; "
      "peak RSS depth_node %.0f MB, fusion_node %.0f MB; mean %.2f s per "
      "depth map\n",
      kViews, kRate, play_seconds, depth_seconds, fused.size(), cm.precision[1],
      cm.recall[1], triangles, mm.precision[1], depth_rss, fusion_rss,
      std::atof(
          diag.Values("depth_node")["mean seconds per depth map"].c_str()));
  // RSS ceilings about 2x the measured peaks (95 / 118-139 MB; docs/ROS.md).
  EXPECT_GT(depth_rss, 0);
  EXPECT_GT(fusion_rss, 0);
  EXPECT_LT(depth_rss, 200.0);
  EXPECT_LT(fusion_rss, 280.0);
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace testing
}  // namespace wild_mvs

int main(int argc, char** argv) {
  ::testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "rostest_pipeline");
  return RUN_ALL_TESTS();
}
