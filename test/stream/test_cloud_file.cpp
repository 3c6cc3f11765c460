// Copyright wild_mvs authors. The fusion node's PLY save (SaveCloudPly, used
// by ~save, the shutdown save on SIGINT/SIGTERM and the session saves): a
// process killed hard (SIGKILL) in the middle of saving a large cloud leaves
// the previous file byte-identical, and no partial file takes its place.
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <thread>

#include "test_paths.h"
#include "wild_mvs/stream/cloud_file.h"

namespace wild_mvs {
namespace testing {
namespace {

namespace fs = std::filesystem;

std::string ReadAll(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  std::stringstream ss;
  ss << f.rdbuf();
  return ss.str();
}

PointCloud MakeCloud(size_t n) {
  PointCloud c;
  c.xyz.resize(n);
  c.normal.resize(n);
  c.rgb.resize(n);
  c.confidence.resize(n);
  for (size_t i = 0; i < n; ++i) {
    c.xyz[i] = Eigen::Vector3f(i * 1e-3f, 1.f, 2.f);
    c.normal[i] = Eigen::Vector3f(0, 0, 1);
    c.rgb[i] = Eigen::Vector3f(0.5f, 0.25f, 1.f);
    c.confidence[i] = 0.5f;
  }
  return c;
}

// Temporary files the atomic writer left beside `path` (".<stem>.tmp*").
std::vector<fs::path> TempFiles(const fs::path& path) {
  std::vector<fs::path> out;
  const std::string prefix = "." + path.stem().string() + ".tmp";
  for (const auto& e : fs::directory_iterator(path.parent_path()))
    if (e.path().filename().string().rfind(prefix, 0) == 0)
      out.push_back(e.path());
  return out;
}

TEST(CloudFile, SavesAValidBinaryPly) {
  const std::string dir = MakeTempDir("wild_mvs_cloud_file");
  const std::string path = dir + "/cloud.ply";
  SaveCloudPly(path, MakeCloud(10));
  const std::string s = ReadAll(path);
  const size_t end = s.find("end_header\n");
  ASSERT_NE(end, std::string::npos);
  EXPECT_NE(s.find("element vertex 10\n"), std::string::npos);
  // x y z nx ny nz (floats) r g b (uchar) confidence (float)
  EXPECT_EQ(s.size() - (end + 11), 10u * (6 * 4 + 3 + 4));
  EXPECT_TRUE(TempFiles(path).empty());
  fs::remove_all(dir);
}

TEST(CloudFile, SigkillDuringSaveLeavesThePreviousFileIntact) {
  const std::string dir = MakeTempDir("wild_mvs_cloud_file_kill");
  const std::string path = dir + "/cloud.ply";
  SaveCloudPly(path, MakeCloud(1000));
  const std::string before = ReadAll(path);
  ASSERT_GT(before.size(), 1000u);
  // A cloud of 4 M points (~124 MB of PLY) takes long enough to write that
  // the kill lands in the middle of the save. Build it before forking.
  const PointCloud big = MakeCloud(4000000);
  const pid_t child = fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    try {
      SaveCloudPly(path, big);
    } catch (...) {
      _exit(2);
    }
    _exit(0);
  }
  // Kill it once the temporary file has grown past 8 MB (the save is under
  // way) and before it was renamed.
  bool killed_mid_save = false;
  const auto deadline =
      std::chrono::steady_clock::now() + std::chrono::seconds(60);
  while (std::chrono::steady_clock::now() < deadline) {
    for (const fs::path& t : TempFiles(path)) {
      std::error_code ec;
      if (fs::file_size(t, ec) > 8u * 1048576u && !ec) {
        kill(child, SIGKILL);
        killed_mid_save = true;
        break;
      }
    }
    if (killed_mid_save) break;
    int status = 0;
    if (waitpid(child, &status, WNOHANG) == child) {
      FAIL() << "the save finished before it could be killed";
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
  int status = 0;
  ASSERT_EQ(waitpid(child, &status, 0), child);
  ASSERT_TRUE(killed_mid_save);
  ASSERT_TRUE(WIFSIGNALED(status) && WTERMSIG(status) == SIGKILL);
  // The previous file is byte-identical; the partial data is only in a
  // hidden temporary file, never under the destination's name.
  EXPECT_EQ(ReadAll(path), before);
  const std::vector<fs::path> temps = TempFiles(path);
  ASSERT_EQ(temps.size(), 1u);
  EXPECT_LT(fs::file_size(temps[0]), 4000000u * 31u);
  // The next save succeeds and replaces it.
  SaveCloudPly(path, MakeCloud(20));
  EXPECT_NE(ReadAll(path).find("element vertex 20\n"), std::string::npos);
  fs::remove_all(dir);
}

}  // namespace
}  // namespace testing
}  // namespace wild_mvs
