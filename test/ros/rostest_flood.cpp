// Copyright wild_mvs authors. rostest (test/ros/flood.test): depth views
// published as fast as possible into a fusion node with a small queue that
// meshes all the time, while ~save is called in a loop. No drop may go
// uncounted (views published = views fused + views dropped, roscpp's own
// queue overflows included), ~save keeps answering (its latency bounded by
// one fused view and the write, not by the flood or the meshing), and the
// saved cloud holds the fused views' points.
#include <gtest/gtest.h>
#include <ros/ros.h>
#include <wild_mvs/DepthView.h>
#include <wild_mvs/SaveCloud.h>

#include <algorithm>
#include <atomic>
#include <filesystem>
#include <thread>

#include "ros_test_scene.h"
#include "rostest_util.h"
#include "test_paths.h"
#include "wild_mvs/ros/conversions.h"

namespace wild_mvs {
namespace testing {
namespace {

constexpr int kViews = 150;

// getBusStats of a node, as XML (for failure messages).
std::string BusStats(const std::string& node) {
  XmlRpc::XmlRpcValue args, result, payload;
  args[0] = ros::this_node::getName();
  args[1] = node;
  if (!ros::master::execute("lookupNode", args, result, payload, false))
    return "(no node)";
  std::string host;
  uint32_t port = 0;
  if (!ros::network::splitURI(static_cast<std::string>(payload), host, port))
    return "(bad uri)";
  XmlRpc::XmlRpcClient client(host.c_str(), port, "/");
  XmlRpc::XmlRpcValue a, r;
  a[0] = ros::this_node::getName();
  if (!client.execute("getBusStats", a, r)) return "(getBusStats failed)";
  return "getBusStats of " + node + ": " + r.toXml();
}

TEST(Flood, EveryViewIsFusedOrCountedAndSaveStaysResponsive) {
  ros::NodeHandle nh;
  const SyntheticScene scene = Render(RosTestSpec(6));
  // The ground truth as depth views (keyframe ids 0.., one session).
  std::vector<wild_mvs::DepthViewPtr> views;
  const ros::Time session(1795000000.0);
  for (int k = 0; k < kViews; ++k) {
    const int i = k % static_cast<int>(scene.scene.views.size());
    DepthMap map;
    map.camera = scene.scene.views[i].camera;
    map.depth = scene.depth[i].clone();
    map.normal = scene.normals[i].clone();
    map.confidence = cv::Mat(map.depth.size(), CV_32F, cv::Scalar(0.9f));
    map.confidence.setTo(0, map.depth <= 0);
    auto msg = boost::make_shared<wild_mvs::DepthView>();
    ros1::FillDepthView(map, "world", msg.get());
    msg->header.stamp = session + ros::Duration(0.05 * k);
    msg->header.frame_id = "camera_optical_frame";
    msg->session = session;
    msg->keyframe_id = k;
    views.push_back(msg);
  }
  ros::Publisher pub =
      nh.advertise<wild_mvs::DepthView>("/flood/depth_view", kViews);
  DiagnosticsWatch diag(nh);
  ros::AsyncSpinner spinner(2);
  spinner.start();
  ASSERT_TRUE(WaitFor([&] { return pub.getNumSubscribers() > 0; }, 60));
  ASSERT_TRUE(ros::service::waitForService("/fusion_node/save", 60000));

  // ~save in a loop while the flood runs.
  const std::string dir = MakeTempDir("wild_mvs_rostest_flood");
  std::atomic<bool> flooding{true};
  std::vector<double> latencies;
  int saves_ok = 0;
  std::thread saver([&] {
    ros::ServiceClient save =
        nh.serviceClient<wild_mvs::SaveCloud>("/fusion_node/save");
    while (flooding) {
      wild_mvs::SaveCloud srv;
      srv.request.path = dir + "/cloud.ply";
      const ros::WallTime t0 = ros::WallTime::now();
      if (save.call(srv) && srv.response.success) ++saves_ok;
      latencies.push_back((ros::WallTime::now() - t0).toSec());
      ros::WallDuration(0.05).sleep();
    }
  });
  for (const auto& v : views) pub.publish(v);
  // Done when every view is accounted for (fused or dropped) and idle.
  auto accounted = [&] {
    const long fused = diag.Get("fusion_node: ", "views fused");
    const long dropped = diag.Get("fusion_node: ", "views dropped");
    return fused >= 0 && dropped >= 0 && fused + dropped >= kViews &&
           diag.Get("fusion_node: ", "input queue length") == 0;
  };
  const bool all = WaitFor(accounted, 200);
  ros::WallDuration(1.0).sleep();  // a save during the idle node too
  flooding = false;
  saver.join();

  const long fused = diag.Get("fusion_node: ", "views fused");
  const long dropped = diag.Get("fusion_node: ", "views dropped");
  const long roscpp = diag.Dropped("fusion_node: ", "roscpp queue full");
  const long queue_full = diag.Dropped("fusion_node: ", "input queue full");
  std::printf(
      "[flood] %d views published: %ld fused, %ld dropped (%ld by the "
      "node's queue, %ld by roscpp's); %d saves, latency max %.3f s\n",
      kViews, fused, dropped, queue_full, roscpp, saves_ok,
      latencies.empty()
          ? 0.0
          : *std::max_element(latencies.begin(), latencies.end()));
  EXPECT_TRUE(all) << diag.Dump("fusion_node: ") << BusStats("/fusion_node");
  // No uncounted drop: every published view is fused or dropped, and the
  // drops are the two queues'.
  EXPECT_EQ(fused + dropped, kViews) << diag.Dump("fusion_node: ");
  EXPECT_EQ(roscpp + queue_full, dropped) << diag.Dump("fusion_node: ");
  EXPECT_GT(dropped, 0) << "the flood did not overflow a queue (test too weak)";
  EXPECT_GT(fused, 0);
  // ~save answered all along, within a bound far below the flood's length.
  EXPECT_GE(saves_ok, 3);
  ASSERT_FALSE(latencies.empty());
  EXPECT_LT(*std::max_element(latencies.begin(), latencies.end()), 20.0);
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace testing
}  // namespace wild_mvs

int main(int argc, char** argv) {
  ::testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "rostest_flood");
  return RUN_ALL_TESTS();
}
