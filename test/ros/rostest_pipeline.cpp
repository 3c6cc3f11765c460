// Copyright wild_mvs authors. rostest (test/ros/pipeline.test): a bag made
// from a synthetic scene with exact ground truth is played once through the
// depth and fusion nodes; each case checks one outcome: the published depth
// images against the ground truth, the fused cloud, the mesh marker, ~save,
// the diagnostics and the nodes' memory.
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
#include <memory>
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

// The bag played once through the nodes, and what came out. The
// subscriptions and the spinner stay up for the cases (the diagnostics keep
// arriving, the services are called from the cases). A step that does not
// complete ends the run; `failure` says which.
class PipelineRun {
  ros::NodeHandle nh_;  // first: the members below use it

 public:
  PipelineRun() : diag(nh_), spinner_(2) {}
  // No callback may run while the members it uses are destroyed.
  ~PipelineRun() {
    spinner_.stop();
    if (!dir.empty()) std::filesystem::remove_all(dir);
  }

  void Run() {
    scene = Render(RosTestSpec(kViews));
    dir = MakeTempDir("wild_mvs_rostest_pipeline");
    const std::string bag = dir + "/scene.bag";
    bo_.rate = kRate;
    bo_.with_points = true;
    ros1::WriteSceneBag(
        scene.scene,
        [&](int i) { return ros1::LinearToSrgb8(scene.images[i]); }, bag, bo_);
    // WILD_MVS_KEEP_BAG=PATH keeps a copy of the bag (demos, screenshots).
    if (const char* keep = std::getenv("WILD_MVS_KEEP_BAG"))
      std::filesystem::copy_file(
          bag, keep, std::filesystem::copy_options::overwrite_existing);
    Subscribe();
    spinner_.start();
    // The nodes are up when their outputs are advertised.
    if (!WaitFor(
            [&] {
              return depth_sub_.getNumPublishers() > 0 &&
                     cloud_sub_.getNumPublishers() > 0;
            },
            30)) {
      failure = "the depth and fusion nodes did not come up";
      return;
    }
    ros::WallDuration(1.0).sleep();  // let the subscriptions settle
    const ros::WallTime t0 = ros::WallTime::now();
    PlayBag(bag, 1.0).join();
    play_seconds = (ros::WallTime::now() - t0).toSec();
    // Every keyframe with enough neighbours gets its depth map.
    WaitFor(
        [&] {
          std::lock_guard<std::mutex> lock(mutex_);
          return views_.size() >= static_cast<size_t>(kViews);
        },
        150);
    depth_seconds = (ros::WallTime::now() - t0).toSec();
    // The fused cloud arrives (latched, publish_period) with every view.
    if (!WaitFor(
            [&] {
              std::lock_guard<std::mutex> lock(mutex_);
              return cloud_ && cloud_->width * cloud_->height > 1000 &&
                     diag.Get("fusion_node", "views fused") >=
                         static_cast<long>(views_.size());
            },
            30)) {
      failure = "no cloud with every view fused; " + diag.Dump("fusion_node");
      return;
    }
    ros::WallDuration(1.5).sleep();  // the cloud after the last view
    // The mesh marker (mesh_period 2 s).
    if (!WaitFor(
            [&] {
              std::lock_guard<std::mutex> lock(mutex_);
              return mesh_ != nullptr;
            },
            30))
      failure = "no mesh on /fusion_node/mesh";
    complete = failure.empty();
  }

  // Copies of the outputs (the callbacks may still replace them).
  std::map<int, sensor_msgs::ImageConstPtr> Depth() {
    std::lock_guard<std::mutex> lock(mutex_);
    return depth_;
  }
  std::map<int, wild_mvs::DepthViewConstPtr> Views() {
    std::lock_guard<std::mutex> lock(mutex_);
    return views_;
  }
  sensor_msgs::PointCloud2ConstPtr Cloud() {
    std::lock_guard<std::mutex> lock(mutex_);
    return cloud_;
  }
  visualization_msgs::MarkerConstPtr Mesh() {
    std::lock_guard<std::mutex> lock(mutex_);
    return mesh_;
  }

  SyntheticScene scene;
  std::string dir;
  DiagnosticsWatch diag;
  double play_seconds = 0, depth_seconds = 0;
  bool complete = false;
  std::string failure;

 private:
  int IndexOf(const ros::Time& t) const {
    return static_cast<int>(std::lround((t.toSec() - bo_.start_time) * kRate));
  }

  void Subscribe() {
    depth_sub_ = nh_.subscribe<sensor_msgs::Image>(
        "/depth_node/depth/image_rect", 20,
        [this](const sensor_msgs::ImageConstPtr& m) {
          std::lock_guard<std::mutex> lock(mutex_);
          depth_[IndexOf(m->header.stamp)] = m;
        });
    view_sub_ = nh_.subscribe<wild_mvs::DepthView>(
        "/depth_node/depth_view", 20,
        [this](const wild_mvs::DepthViewConstPtr& m) {
          std::lock_guard<std::mutex> lock(mutex_);
          views_[IndexOf(m->header.stamp)] = m;
        });
    cloud_sub_ = nh_.subscribe<sensor_msgs::PointCloud2>(
        "/fusion_node/cloud", 2,
        [this](const sensor_msgs::PointCloud2ConstPtr& m) {
          std::lock_guard<std::mutex> lock(mutex_);
          cloud_ = m;
        });
    mesh_sub_ = nh_.subscribe<visualization_msgs::Marker>(
        "/fusion_node/mesh", 2,
        [this](const visualization_msgs::MarkerConstPtr& m) {
          std::lock_guard<std::mutex> lock(mutex_);
          mesh_ = m;
        });
  }

  ros::AsyncSpinner spinner_;
  ros1::SceneBagOptions bo_;
  std::mutex mutex_;
  std::map<int, sensor_msgs::ImageConstPtr> depth_;  // by view index
  std::map<int, wild_mvs::DepthViewConstPtr> views_;
  sensor_msgs::PointCloud2ConstPtr cloud_;
  visualization_msgs::MarkerConstPtr mesh_;
  ros::Subscriber depth_sub_, view_sub_, cloud_sub_, mesh_sub_;
};

class Pipeline : public RunOnce<PipelineRun> {
 protected:
  static CloudMetrics AgainstTruth(const PointCloud& cloud) {
    CloudMetricsOptions co;
    co.taus = {0.02, 0.04};
    return EvaluateCloud(cloud, run_->scene.GroundTruthCloud(1), co);
  }
};

TEST_F(Pipeline, EveryKeyframeGetsADepthImageAndADepthView) {
  const auto views = run_->Views();
  EXPECT_GE(views.size(), static_cast<size_t>(kViews - 1))
      << run_->diag.Dump("depth_node");
  EXPECT_EQ(run_->Depth().size(), views.size());
}

TEST_F(Pipeline, DepthImagesAreMetresAlongZAtTheViewsPose) {
  const auto views = run_->Views();
  for (const auto& [i, msg] : run_->Depth()) {
    ASSERT_GE(i, 0);
    ASSERT_LT(i, kViews);
    EXPECT_EQ(msg->encoding, "32FC1");
    ASSERT_TRUE(views.count(i)) << "view " << i;
    // Depth in metres along z with NaN unknown (REP 118), at the depth
    // map's resolution given by the DepthView's camera_info.
    Camera cam;
    ros1::CameraFromCameraInfo(views.at(i)->camera_info, &cam, nullptr);
    ros1::SetCameraPose(views.at(i)->camera_pose.pose, &cam);
    const Camera& truth = run_->scene.scene.views[i].camera;
    EXPECT_LT((cam.Center() - truth.Center()).norm(), 1e-4);
    cv::Mat d = ros1::FloatImageFromMsg(*msg, 1, "depth");
    d.forEach<float>([](float& v, const int*) {
      if (std::isnan(v)) v = 0;
    });
    const DepthMetrics m = EvaluateDepth(d, cam, run_->scene.depth[i], truth);
    EXPECT_GT(m.completeness, 0.4) << "view " << i << ": " << m.ToString();
    EXPECT_LT(m.median_rel_error, 0.01) << "view " << i;
    EXPECT_GT(m.relative_accuracy[2], 0.85) << "view " << i;  // within 5 %
  }
}

TEST_F(Pipeline, FusedCloudLiesOnTheSceneInTheWorldFrame) {
  const sensor_msgs::PointCloud2ConstPtr cloud = run_->Cloud();
  EXPECT_EQ(cloud->header.frame_id, "world");
  const PointCloud fused = CloudFromMsg(*cloud);
  const CloudMetrics cm = AgainstTruth(fused);
  EXPECT_GT(cm.precision[1], 0.9) << cm.ToString();
  EXPECT_GT(cm.recall[1], 0.3) << cm.ToString();
  std::printf(
      "[pipeline] %d views at %.1f Hz: bag played in %.1f s, depth maps "
      "after %.1f s; %zu fused points; precision@4cm %.3f recall@4cm %.3f\n",
      kViews, kRate, run_->play_seconds, run_->depth_seconds, fused.size(),
      cm.precision[1], cm.recall[1]);
}

// The mesh Marker (mesh_period 2 s, Poisson on the fused cloud): a triangle
// list in the world frame whose triangles are finite, non-degenerate and lie
// on the scene (centroids against the ground-truth surface).
TEST_F(Pipeline, MeshMarkerIsATriangleListOnTheScene) {
  const visualization_msgs::MarkerConstPtr mesh = run_->Mesh();
  EXPECT_EQ(mesh->type, visualization_msgs::Marker::TRIANGLE_LIST);
  EXPECT_EQ(mesh->action, visualization_msgs::Marker::ADD);
  EXPECT_EQ(mesh->header.frame_id, "world");
  EXPECT_DOUBLE_EQ(mesh->pose.orientation.w, 1.0);
  ASSERT_EQ(mesh->points.size() % 3, 0u);
  EXPECT_TRUE(mesh->colors.empty() ||
              mesh->colors.size() == mesh->points.size());
  const size_t triangles = mesh->points.size() / 3;
  size_t degenerate = 0;
  PointCloud centroids;
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
  EXPECT_GT(triangles, 500u);
  EXPECT_LT(degenerate, triangles / 100 + 1);
  const CloudMetrics mm = AgainstTruth(centroids);
  EXPECT_GT(mm.precision[1], 0.7) << "mesh: " << mm.ToString();
}

// ~save writes a valid binary PLY of the whole cloud.
TEST_F(Pipeline, SaveWritesTheCloudAsABinaryPly) {
  wild_mvs::SaveCloud srv;
  srv.request.path = run_->dir + "/saved.ply";
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
}

TEST_F(Pipeline, SaveToAnUnwritablePlaceFailsAndTheNodeStaysUp) {
  wild_mvs::SaveCloud srv;
  srv.request.path = "/proc/wild_mvs_cannot_write/cloud.ply";
  ASSERT_TRUE(ros::service::waitForService("/fusion_node/save", 10000));
  ASSERT_TRUE(ros::service::call("/fusion_node/save", srv));
  EXPECT_FALSE(srv.response.success);
  EXPECT_FALSE(srv.response.message.empty());
  srv.request.path = run_->dir + "/after_failure.ply";
  ASSERT_TRUE(ros::service::call("/fusion_node/save", srv));
  EXPECT_TRUE(srv.response.success) << srv.response.message;
}

TEST_F(Pipeline, DiagnosticsCountEveryDepthMapAndNoDrop) {
  EXPECT_GE(run_->diag.Get("depth_node", "depth maps"),
            static_cast<long>(run_->Views().size()));
  EXPECT_EQ(run_->diag.Get("depth_node", "frames dropped"), 0)
      << run_->diag.Dump("depth_node");
  EXPECT_GT(
      std::atof(run_->diag.Values("depth_node")["mean seconds per depth map"]
                    .c_str()),
      0.0)
      << run_->diag.Dump("depth_node");
}

// Ceilings about twice the peaks of a healthy run (the case prints them): a
// leak or an unbounded queue crosses them.
TEST_F(Pipeline, NodesStayUnderTheirMemoryCeilings) {
  const double depth_rss = PeakRssMb(NodePid("/depth_node"));
  const double fusion_rss = PeakRssMb(NodePid("/fusion_node"));
  std::printf("[pipeline] peak RSS depth_node %.0f MB, fusion_node %.0f MB\n",
              depth_rss, fusion_rss);
  EXPECT_GT(depth_rss, 0);
  EXPECT_GT(fusion_rss, 0);
  EXPECT_LT(depth_rss, 200.0);
  EXPECT_LT(fusion_rss, 280.0);
}

}  // namespace
}  // namespace testing
}  // namespace wild_mvs

int main(int argc, char** argv) {
  ::testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "rostest_pipeline");
  return RUN_ALL_TESTS();
}
