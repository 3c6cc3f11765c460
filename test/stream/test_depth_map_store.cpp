// Copyright wild_mvs authors. The fusion node's spill store: bounded memory,
// spilled maps read back exactly, images released, spill folder handling.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "../unit/test_fusion_scene.h"
#include "test_paths.h"
#include "wild_mvs/core/error.h"
#include "wild_mvs/stream/depth_map_store.h"

namespace wild_mvs {
namespace {

namespace fs = std::filesystem;

fusion_test::AnalyticScene SmallScene() {
  fusion_test::AnalyticScene s;
  s.width = 64;
  s.height = 48;
  s.focal = 60;
  return s;
}

bool SameMat(const cv::Mat& a, const cv::Mat& b) {
  if (a.size() != b.size() || a.type() != b.type()) return false;
  return a.empty() || cv::norm(a, b, cv::NORM_INF) == 0;
}

TEST(DepthMapStore, SpillsBeyondTheBoundAndReadsBackExactly) {
  const fusion_test::AnalyticScene scene = SmallScene();
  std::string dir;
  {
    // One map is 64 x 48 x 20 bytes (+ image) = 60 KB + 36 KB: a 0.15 MB
    // bound holds one map, so each Hold spills the previous one.
    DepthMapStore store(0.15, "");
    dir = store.dir();
    ASSERT_TRUE(fs::is_directory(dir));
    std::vector<DepthMap> maps;
    for (int v = 0; v < 3; ++v) {
      maps.push_back(scene.Render(v, 8));
      cv::Mat image(scene.height, scene.width, CV_32FC3,
                    cv::Scalar(0.1 * v, 0.2, 0.3));
      store.Hold(v, maps.back(), image,
                 [](const std::string& p, const std::string& d) {
                   ADD_FAILURE() << p << ": " << d;
                 });
    }
    EXPECT_EQ(store.spilled(), 2u);
    EXPECT_FALSE(store.InMemory(0));
    EXPECT_FALSE(store.InMemory(1));
    EXPECT_TRUE(store.InMemory(2));
    EXPECT_LE(store.bytes(), static_cast<size_t>(0.15 * 1048576));
    EXPECT_TRUE(store.Image(0).empty());  // released with the map
    ASSERT_FALSE(store.Image(2).empty());
    EXPECT_FLOAT_EQ(store.Image(2).at<cv::Vec3f>(0, 0)[0], 0.2f);
    for (int v = 0; v < 3; ++v) {
      const std::shared_ptr<const DepthMap> m = store.Map(v);
      ASSERT_TRUE(m);
      EXPECT_EQ(m->view, v);
      EXPECT_TRUE(SameMat(m->depth, maps[v].depth)) << v;
      EXPECT_TRUE(SameMat(m->normal, maps[v].normal)) << v;
      EXPECT_TRUE(SameMat(m->confidence, maps[v].confidence)) << v;
      EXPECT_EQ(m->camera.width, maps[v].camera.width);
      EXPECT_NEAR(m->camera.fx, maps[v].camera.fx, 1e-9);
      EXPECT_NEAR((m->camera.Center() - maps[v].camera.Center()).norm(), 0,
                  1e-9);
      // Spilled maps come back without neighbours, held ones keep them.
      EXPECT_EQ(m->neighbors.empty(), v < 2) << v;
    }
    EXPECT_THROW(store.Map(7), Error);
    EXPECT_TRUE(store.Image(7).empty());
    store.Clear();
    EXPECT_EQ(store.bytes(), 0u);
    EXPECT_THROW(store.Map(0), Error);
  }
  EXPECT_FALSE(fs::exists(dir));  // its own temporary folder is removed
}

TEST(DepthMapStore, GivenFolderIsKeptAndLargeBoundSpillsNothing) {
  const fusion_test::AnalyticScene scene = SmallScene();
  const std::string dir = testing::MakeTempDir("wild_mvs_spill") + "/maps";
  {
    DepthMapStore big(100, dir);
    EXPECT_TRUE(fs::is_directory(dir));  // created
    for (int v = 0; v < 3; ++v) big.Hold(v, scene.Render(v, 8), cv::Mat());
    EXPECT_EQ(big.spilled(), 0u);
    EXPECT_TRUE(big.InMemory(0));
  }
  {
    DepthMapStore small(0.01, dir);
    for (int v = 0; v < 2; ++v) small.Hold(v, scene.Render(v, 8), cv::Mat());
    EXPECT_EQ(small.spilled(), 1u);
  }
  EXPECT_TRUE(fs::is_directory(dir));  // a given folder stays
  EXPECT_FALSE(fs::is_empty(dir));
  fs::remove_all(fs::path(dir).parent_path());
}

TEST(DepthMapStore, FailedSpillIsReportedAndTheMapStaysInMemory) {
  const fusion_test::AnalyticScene scene = SmallScene();
  const std::string dir = testing::MakeTempDir("wild_mvs_spill_fail");
  DepthMapStore store(0.01, dir + "/maps");
  // The spill folder is replaced by a file: writing into it fails.
  fs::remove_all(dir + "/maps");
  std::ofstream(dir + "/maps") << "not a folder";
  std::vector<std::string> errors;
  auto on_error = [&](const std::string& p, const std::string& d) {
    errors.push_back(p + ": " + d);
  };
  store.Hold(0, scene.Render(0, 8), cv::Mat(), on_error);
  EXPECT_TRUE(errors.empty());  // the last map held is never spilled
  store.Hold(1, scene.Render(1, 8), cv::Mat(), on_error);
  ASSERT_EQ(errors.size(), 1u);
  EXPECT_NE(errors[0].find("cannot spill a depth map to " + dir + "/maps"),
            std::string::npos)
      << errors[0];
  EXPECT_EQ(store.spilled(), 0u);
  EXPECT_TRUE(store.InMemory(0));
  ASSERT_TRUE(store.Map(0));
  EXPECT_EQ(store.Map(0)->view, 0);
  fs::remove_all(dir);
}

}  // namespace
}  // namespace wild_mvs
