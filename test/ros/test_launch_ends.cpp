// Copyright wild_mvs authors. `roslaunch wild_mvs reconstruct_bag.launch` on
// a bag recorded like a real robot (real_world_bag.h: epoch stamps,
// leading-slash frames, body frame on /tf + /tf_static, 30 Hz camera on
// /camera/rgb/image_color) with use_sim_time:=true ends by itself, with
// status 0, and leaves a non-empty PLY. A plain gtest (ctest runs it without
// rostest): roslaunch starts its own master on a private port.
//
// A second test checks the bag writer itself: exact stamps, latched
// /tf_static, frame ids, and that tf (world -> base_link -> optical frame,
// interpolated at every image stamp) gives the ground-truth camera.
//
// The package is found by sourcing a catkin devel setup.bash: the one named
// by $WILD_MVS_DEVEL_SETUP, else the first `setup.bash` beside a
// `lib/wild_mvs` folder found walking up from this executable (checking
// each folder and its `devel/` subfolder).
#include <gtest/gtest.h>
#include <rosbag/view.h>
#include <sys/wait.h>
#include <tf2/buffer_core.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>
#include <string>

#include "real_world_bag.h"
#include "ros_test_scene.h"
#include "test_paths.h"

namespace wild_mvs {
namespace testing {
namespace {

namespace fs = std::filesystem;

std::string FindDevelSetup() {
  if (const char* e = std::getenv("WILD_MVS_DEVEL_SETUP"))
    if (*e) return e;
  std::error_code ec;
  fs::path p = fs::read_symlink("/proc/self/exe", ec);
  if (ec) return "";
  for (p = p.parent_path(); !p.empty(); p = p.parent_path()) {
    for (const fs::path& d : {p, p / "devel"})
      if (fs::exists(d / "setup.bash") && fs::is_directory(d / "lib/wild_mvs"))
        return (d / "setup.bash").string();
    if (p == p.root_path()) break;
  }
  return "";
}

// Vertex count of a PLY header, or -1.
long PlyVertices(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  std::string line;
  if (!std::getline(f, line) || line.rfind("ply", 0) != 0) return -1;
  long n = -1;
  while (std::getline(f, line)) {
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line == "end_header") return n;
    std::istringstream s(line);
    std::string a, b;
    long c = -1;
    if (s >> a >> b >> c && a == "element" && b == "vertex") n = c;
  }
  return -1;
}

std::string Tail(const std::string& path, size_t max_chars = 6000) {
  std::ifstream f(path);
  std::stringstream ss;
  ss << f.rdbuf();
  std::string s = ss.str();
  return s.size() > max_chars ? "..." + s.substr(s.size() - max_chars) : s;
}

std::string Quote(const std::string& s) {
  std::string q = "'";
  for (char c : s) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return q + "'";
}

std::string Strip(const std::string& f) {
  return !f.empty() && f[0] == '/' ? f.substr(1) : f;
}

TEST(RealWorldBag, StampsFramesAndTfGiveTheGroundTruth) {
  for (const std::string variant : {"rgb8", "mono8", "compressed"}) {
    SCOPED_TRACE(variant);
    const std::string dir = MakeTempDir("wild_mvs_real_world_bag");
    const SyntheticScene scene = Render(RosTestSpec(4));
    RealWorldBagOptions bo;
    if (variant == "compressed")
      bo.compression = "jpeg";
    else
      bo.encoding = variant;
    const RealWorldBag bag = WriteRealWorldBag(scene, dir + "/b.bag", bo);
    ASSERT_EQ(bag.image_stamps.size(), 4u * bo.frames_per_view);
    EXPECT_EQ(bag.first_stamp.sec, 1305031102u);
    EXPECT_EQ(bag.first_stamp.nsec, 175304000u);
    EXPECT_EQ(bag.image_stamps[1].toNSec() - bag.image_stamps[0].toNSec(),
              33333333u);
    ASSERT_EQ(bag.first_stamp_of_view.size(), 4u);
    EXPECT_EQ(bag.first_stamp_of_view[1], bag.image_stamps[bo.frames_per_view]);
    EXPECT_EQ(bag.ViewOfStamp(bag.image_stamps[bo.frames_per_view - 1]), 0);
    EXPECT_EQ(bag.ViewOfStamp(bag.image_stamps[bo.frames_per_view]), 1);
    EXPECT_EQ(bag.ViewOfStamp(bag.image_stamps[0] + ros::Duration(0, 1)), -1);

    rosbag::Bag b(bag.path, rosbag::bagmode::Read);
    rosbag::View view(b);
    tf2::BufferCore tf(ros::Duration(100));
    std::vector<ros::Time> images;
    std::set<std::string> topics;
    int tf_static = 0, tf_msgs = 0, infos = 0;
    bool static_first = false, static_latched = false;
    ros::Time last_tf;
    for (const rosbag::MessageInstance& m : view) {
      topics.insert(m.getTopic());
      if (m.getTopic() == "/tf_static") {
        static_first = tf_msgs == 0 && images.empty();
        auto h = m.getConnectionHeader();
        static_latched = h && h->count("latching") && h->at("latching") == "1";
        ++tf_static;
      }
      if (auto t = m.instantiate<tf2_msgs::TFMessage>()) {
        if (m.getTopic() == "/tf") ++tf_msgs;
        for (const auto& T : t->transforms) {
          EXPECT_EQ(T.header.frame_id[0], '/');
          EXPECT_EQ(T.child_frame_id[0], '/');
          geometry_msgs::TransformStamped s = T;
          s.header.frame_id = Strip(T.header.frame_id);
          s.child_frame_id = Strip(T.child_frame_id);
          tf.setTransform(s, "bag", m.getTopic() == "/tf_static");
          if (m.getTopic() == "/tf") {
            if (!last_tf.isZero()) {
              EXPECT_EQ((T.header.stamp - last_tf).toNSec(), 10000000);
            }
            last_tf = T.header.stamp;
          }
        }
      }
      if (auto i = m.instantiate<sensor_msgs::CameraInfo>()) {
        ++infos;
        EXPECT_EQ(i->header.frame_id, "/camera_rgb_optical_frame");
        EXPECT_EQ(i->distortion_model, "plumb_bob");
        EXPECT_EQ(i->D, std::vector<double>(5, 0.0));
        EXPECT_EQ(i->P[3], 0.0);
        EXPECT_EQ(i->P[0], i->K[0]);
      }
      if (auto i = m.instantiate<sensor_msgs::Image>()) {
        EXPECT_EQ(m.getTopic(), "/camera/rgb/image_color");
        EXPECT_EQ(i->encoding, variant);
        EXPECT_EQ(i->header.frame_id, "/camera_rgb_optical_frame");
        EXPECT_EQ(i->header.stamp, m.getTime());
        images.push_back(i->header.stamp);
      }
      if (auto i = m.instantiate<sensor_msgs::CompressedImage>()) {
        EXPECT_EQ(m.getTopic(), "/camera/rgb/image_color/compressed");
        EXPECT_EQ(i->format, "rgb8; jpeg compressed bgr8");
        images.push_back(i->header.stamp);
      }
    }
    EXPECT_EQ(tf_static, 1);
    EXPECT_TRUE(static_first);
    EXPECT_TRUE(static_latched);
    EXPECT_GT(tf_msgs, 100);
    EXPECT_EQ(infos, static_cast<int>(bag.image_stamps.size()));
    EXPECT_EQ(topics.count("/camera/rgb/image_color"), variant != "compressed");
    EXPECT_EQ(topics.count("/camera/rgb/image_color/compressed"),
              variant == "compressed");
    ASSERT_EQ(images, bag.image_stamps);
    // tf at every image stamp (interpolated) = the view's ground truth.
    for (size_t k = 0; k < images.size(); ++k) {
      const geometry_msgs::TransformStamped T =
          tf.lookupTransform("world", "camera_rgb_optical_frame", images[k]);
      Camera cam;
      ros1::SetCameraPose(T.transform, &cam);
      const Camera& gt = bag.view_cameras[bag.view_of_image[k]];
      EXPECT_LT((cam.Center() - gt.Center()).norm(), 1e-9) << "image " << k;
      EXPECT_LT((cam.R - gt.R).norm(), 1e-9) << "image " << k;
    }
    // The extrinsic is not trivial: base_link is not the camera.
    const auto E = tf.lookupTransform("base_link", "camera_rgb_optical_frame",
                                      ros::Time(0));
    EXPECT_GT(std::abs(E.transform.translation.x), 0.01);
    EXPECT_LT(std::abs(E.transform.rotation.w), 0.9);
    fs::remove_all(dir);
  }
}

TEST(LaunchEnds, ReconstructBagOfARealWorldBag) {
  const std::string setup = FindDevelSetup();
  ASSERT_FALSE(setup.empty())
      << "no catkin devel setup.bash found: set WILD_MVS_DEVEL_SETUP";
  const std::string env = "source " + Quote(setup) + " >/dev/null 2>&1; ";
  if (std::system(("bash -c " + Quote(env + "command -v roslaunch") +
                   " >/dev/null 2>&1")
                      .c_str()) != 0)
    GTEST_SKIP() << "roslaunch is not installed (ros-core / python3-roslaunch)";

  const std::string dir = MakeTempDir("wild_mvs_launch_ends");
  const int views = 5;
  const SyntheticScene scene = Render(RosTestSpec(views));
  RealWorldBagOptions bo;  // raw rgb8, leading slashes, epoch stamps
  const RealWorldBag bag = WriteRealWorldBag(scene, dir + "/real.bag", bo);
  const std::string ply = dir + "/cloud.ply";
  const std::string log = dir + "/roslaunch.log";
  const int port = 11411 + static_cast<int>(getpid() % 1000);
  // ctest stops ros_test_* after 300 s (cmake/ros_nodes.cmake): end the
  // launch before, so that its log is printed. WILD_MVS_LAUNCH_TIMEOUT=600
  // for a slow machine (run the executable directly then).
  int limit = 270;
  if (const char* e = std::getenv("WILD_MVS_LAUNCH_TIMEOUT"))
    if (std::atoi(e) > 0) limit = std::atoi(e);

  const std::string script =
      env + "export ROS_MASTER_URI=http://localhost:" + std::to_string(port) +
      " ROS_HOSTNAME=localhost ROS_HOME=" + Quote(dir) +
      " ROS_LOG_DIR=" + Quote(dir + "/log") + "; exec timeout -k 20 " +
      std::to_string(limit) + " roslaunch -p " + std::to_string(port) +
      " wild_mvs reconstruct_bag.launch bag:=" + Quote(bag.path) +
      " output:=" + Quote(ply) +
      " image:=/camera/rgb/image_color camera_info:=/camera/rgb/camera_info"
      " world_frame:=world use_sim_time:=true rate:=2";
  const std::string cmd =
      "bash -c " + Quote(script) + " >" + Quote(log) + " 2>&1";
  std::printf("[launch_ends] %s\n", cmd.c_str());
  const int status = std::system(cmd.c_str());
  ASSERT_TRUE(WIFEXITED(status)) << "roslaunch did not exit normally\n"
                                 << Tail(log);
  const int code = WEXITSTATUS(status);
  EXPECT_NE(code, 124) << "roslaunch did not end by itself within " << limit
                       << " s\n"
                       << Tail(log);
  EXPECT_EQ(code, 0) << "roslaunch exit status " << code << "\n" << Tail(log);
  ASSERT_TRUE(fs::exists(ply)) << ply << " not written\n" << Tail(log);
  const long n = PlyVertices(ply);
  EXPECT_GT(n, 0) << ply << ": no vertices in the PLY header\n" << Tail(log);
  std::printf("[launch_ends] exit %d, %s: %ld vertices\n", code, ply.c_str(),
              n);
  if (!HasFailure()) fs::remove_all(dir);
}

}  // namespace
}  // namespace testing
}  // namespace wild_mvs
