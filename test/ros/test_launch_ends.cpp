// Copyright wild_mvs authors. `roslaunch wild_mvs reconstruct_bag.launch` on
// a bag recorded like a real robot (real_world_bag.h: epoch stamps,
// leading-slash frames, body frame on /tf + /tf_static, 30 Hz camera on
// /camera/rgb/image_color) with use_sim_time:=true ends by itself, with
// status 0, and leaves a non-empty PLY. A plain gtest (ctest runs it without
// rostest): roslaunch starts its own master on a private port.
//
// The package is found by sourcing a catkin devel setup.bash: the one named
// by $WILD_MVS_DEVEL_SETUP, else the first `setup.bash` beside a
// `lib/wild_mvs` folder found walking up from this executable (checking
// each folder and its `devel/` subfolder).
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
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

  const std::string script =
      env + "export ROS_MASTER_URI=http://localhost:" + std::to_string(port) +
      " ROS_HOSTNAME=localhost ROS_HOME=" + Quote(dir) +
      " ROS_LOG_DIR=" + Quote(dir + "/log") +
      "; exec timeout -k 20 600 roslaunch -p " + std::to_string(port) +
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
  EXPECT_NE(code, 124) << "roslaunch did not end by itself within 600 s\n"
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
