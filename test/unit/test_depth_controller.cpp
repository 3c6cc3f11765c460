// Copyright wild_mvs authors. The depth pipeline (pipeline/depth_controller.h)
// on a rendered scene with exact depth, with the default options: the
// offline run over a folder writes matched and filtered maps that match
// the ground truth, resumes without redoing anything, and a sharded run
// filtered later gives the same maps; the live path's steps over an
// in-memory workspace give the offline maps; the fused cloud lies on the
// true surfaces and is the same from files or from memory.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>

#include "synthetic_scene.h"
#include "wild_mvs/core/error.h"
#include "wild_mvs/pipeline/depth_controller.h"
#include "wild_mvs/pipeline/file_workspace.h"

namespace wild_mvs {
namespace {

namespace fs = std::filesystem;
using Stage = DepthWorkspace::Stage;
using testing::Render;
using testing::SyntheticScene;

const SyntheticScene& Scene8() {
  static const SyntheticScene* s = [] {
    testing::SyntheticSpec spec = testing::ClutteredSceneSpec(true, false, 105);
    spec.width = 200;
    spec.height = 150;
    spec.focal = 190;
    spec.supersample = 1;
    return new SyntheticScene(Render(spec));
  }();
  return *s;
}

std::string TempDir(const std::string& name) {
  const fs::path p =
      fs::temp_directory_path() /
      ("wild_mvs_depth_controller_" + name + "_" + std::to_string(::getpid()));
  fs::remove_all(p);
  fs::create_directories(p);
  return p.string();
}

std::vector<int> AllViews(const Scene& scene) {
  std::vector<int> v;
  for (size_t i = 0; i < scene.views.size(); ++i)
    v.push_back(static_cast<int>(i));
  return v;
}

struct Accuracy {
  long long samples = 0, within1 = 0, off5 = 0;
};
// A map against view v's exact depth (the map may be smaller).
Accuracy Score(const DepthMap& map, const SyntheticScene& s, int v) {
  Accuracy a;
  const cv::Mat& gt = s.depth[v];
  for (int y = 0; y < map.height(); ++y) {
    for (int x = 0; x < map.width(); ++x) {
      const float d = map.depth.at<float>(y, x);
      if (!(d > 0)) continue;
      const int gx = x * gt.cols / map.width();
      const int gy = y * gt.rows / map.height();
      const float g = gt.at<float>(gy, gx);
      ++a.samples;
      const double rel = g > 0 ? std::abs(d - g) / g : 1.0;
      if (rel <= 0.01) ++a.within1;
      if (rel > 0.05) ++a.off5;
    }
  }
  return a;
}

DepthRun MakeRun(const SyntheticScene& s, ImageCache* images) {
  DepthRun run;
  run.scene = &s.scene;
  run.views = AllViews(s.scene);
  run.images = images;
  return run;
}

bool SameDepth(const DepthMap& a, const DepthMap& b) {
  return a.depth.size() == b.depth.size() &&
         cv::countNonZero(a.depth != b.depth) == 0;
}

TEST(DepthController, OfflineRunWritesAccurateFilteredMapsAndResumes) {
  const SyntheticScene& s = Scene8();
  ImageCache images(s.Loader(), 256);
  const std::string out = TempDir("offline");
  const DepthController controller(MvsOptions(), nullptr);
  ASSERT_TRUE(controller.filters());  // the consistency step is a default
  FileDepthWorkspace workspace(s.scene, out, controller.filters());
  const int n = static_cast<int>(s.scene.views.size());
  const DepthRunSummary first =
      controller.Run(MakeRun(s, &images), &workspace, nullptr);
  EXPECT_TRUE(first.failures.empty());
  EXPECT_EQ(first.matched, n);
  EXPECT_EQ(first.filtered, n);
  EXPECT_EQ(first.skipped, 0);
  EXPECT_EQ(first.samples, first.filter_kept);
  EXPECT_LT(first.filter_kept, first.filter_samples);  // the filter removes
  Accuracy raw, final_maps;
  long long gt_pixels = 0;
  for (int v = 0; v < n; ++v) {
    ASSERT_TRUE(workspace.Has(Stage::kRaw, v));
    ASSERT_TRUE(workspace.Has(Stage::kFinal, v));
    const Accuracy r = Score(*workspace.Read(Stage::kRaw, v), s, v);
    const Accuracy f = Score(*workspace.Read(Stage::kFinal, v), s, v);
    EXPECT_EQ(workspace.Samples(Stage::kFinal, v), f.samples);
    raw.samples += r.samples, raw.within1 += r.within1, raw.off5 += r.off5;
    final_maps.samples += f.samples, final_maps.within1 += f.within1;
    final_maps.off5 += f.off5;
    gt_pixels += cv::countNonZero(s.depth[v] > 0);
  }
  EXPECT_EQ(final_maps.samples, first.filter_kept);
  // Final maps: accurate, and more so than the matched ones.
  EXPECT_GT(final_maps.within1, 0.97 * final_maps.samples);
  EXPECT_LT(final_maps.off5, 0.01 * final_maps.samples);
  EXPECT_LT(static_cast<double>(final_maps.off5) / final_maps.samples,
            static_cast<double>(raw.off5) / raw.samples);
  EXPECT_GT(final_maps.samples, 0.5 * gt_pixels);

  // Resumed: nothing is matched or filtered again, the counts come from
  // the logs.
  const DepthRunSummary again =
      controller.Run(MakeRun(s, &images), &workspace, nullptr);
  EXPECT_EQ(again.matched, 0);
  EXPECT_EQ(again.filtered, 0);
  EXPECT_EQ(again.skipped, n);
  EXPECT_EQ(again.samples, first.samples);
  fs::remove_all(out);
}

TEST(DepthController, ShardsFilteredLaterEqualOneRun) {
  const SyntheticScene& s = Scene8();
  ImageCache images(s.Loader(), 256);
  const DepthController controller(MvsOptions(), nullptr);
  const std::string one = TempDir("one"), shards = TempDir("shards");
  FileDepthWorkspace ws_one(s.scene, one, true);
  controller.Run(MakeRun(s, &images), &ws_one, nullptr);

  // Two shards (even and odd views) that only match, as --shard does.
  FileDepthWorkspace ws(s.scene, shards, true);
  const int n = static_cast<int>(s.scene.views.size());
  for (int k = 0; k < 2; ++k) {
    DepthRun run = MakeRun(s, &images);
    run.views.clear();
    for (int v = k; v < n; v += 2) run.views.push_back(v);
    run.filter_now = false;
    const DepthRunSummary r = controller.Run(run, &ws, nullptr);
    EXPECT_EQ(r.matched, static_cast<int>(run.views.size()));
    EXPECT_EQ(r.unfiltered, static_cast<int>(run.views.size()));
    EXPECT_EQ(r.filtered, 0);
  }
  for (int v = 0; v < n; ++v) EXPECT_FALSE(ws.Has(Stage::kFinal, v));
  const DepthRunSummary f =
      controller.FilterViews(MakeRun(s, &images), &ws, nullptr);
  EXPECT_EQ(f.filtered, n);
  for (int v = 0; v < n; ++v) {
    EXPECT_TRUE(
        SameDepth(*ws.Read(Stage::kFinal, v), *ws_one.Read(Stage::kFinal, v)))
        << "view " << v;
  }
  fs::remove_all(one);
  fs::remove_all(shards);
}

TEST(DepthController, LiveStepsInMemoryGiveTheOfflineMaps) {
  const SyntheticScene& s = Scene8();
  ImageCache images(s.Loader(), 256);
  const DepthController controller(MvsOptions(), nullptr);
  const std::string out = TempDir("files");
  FileDepthWorkspace files(s.scene, out, true);
  controller.Run(MakeRun(s, &images), &files, nullptr);

  // The live path's order: every view matched as it comes, then filtered
  // against its neighbours' maps held in memory.
  MemoryDepthWorkspace memory;
  const int n = static_cast<int>(s.scene.views.size());
  for (int v = 0; v < n; ++v) {
    ViewProblem problem;
    problem.scene = &s.scene;
    problem.ref = v;
    problem.images = &images;
    memory.Write(Stage::kRaw, v, controller.Match(problem));
  }
  for (int v = 0; v < n; ++v) {
    const auto raw = memory.Read(Stage::kRaw, v);
    EXPECT_TRUE(SameDepth(*raw, *files.Read(Stage::kRaw, v))) << "view " << v;
    const ViewResult f = controller.Filter(*raw, memory);
    EXPECT_TRUE(f.filtered);
    EXPECT_EQ(f.neighbor_maps, static_cast<int>(raw->neighbors.size()));
    EXPECT_EQ(f.consistency.kept, f.map.CountValid());
    EXPECT_TRUE(SameDepth(f.map, *files.Read(Stage::kFinal, v)))
        << "view " << v;
    // The held raw map is left as it was.
    EXPECT_EQ(raw->CountValid(), f.consistency.samples);
  }
  fs::remove_all(out);
}

TEST(DepthController, FilterChecksOnlyAgainstMapsTheWorkspaceHolds) {
  const SyntheticScene& s = Scene8();
  ImageCache images(s.Loader(), 256);
  const DepthController controller(MvsOptions(), nullptr);
  ViewProblem problem;
  problem.scene = &s.scene;
  problem.ref = 3;
  problem.images = &images;
  const ViewResult matched = controller.Match(problem);
  ASSERT_FALSE(matched.map.neighbors.empty());
  MemoryDepthWorkspace empty;
  const ViewResult alone = controller.Filter(matched.map, empty);
  EXPECT_EQ(alone.neighbor_maps, 0);
  EXPECT_EQ(alone.consistency.kept, matched.map.CountValid());
}

// Fraction of the points that lie on a surface some view sees: projected
// into a view, within 1 % of its exact depth there.
double OnTheSurface(const PointCloud& cloud, const SyntheticScene& s) {
  long long on = 0;
  for (const Eigen::Vector3f& p : cloud.xyz) {
    const Eigen::Vector3d X = p.cast<double>();
    for (size_t v = 0; v < s.scene.views.size(); ++v) {
      const Camera& c = s.scene.views[v].camera;
      Eigen::Vector2d px;
      if (!c.Project(X, &px) || !c.InImage(px)) continue;
      const int x = std::min(c.width - 1, static_cast<int>(px.x()));
      const int y = std::min(c.height - 1, static_cast<int>(px.y()));
      const float g = s.depth[v].at<float>(y, x);
      if (g > 0 && std::abs(c.Depth(X) - g) <= 0.01 * g) {
        ++on;
        break;
      }
    }
  }
  return cloud.empty() ? 0.0 : static_cast<double>(on) / cloud.size();
}

TEST(DepthController, FusesTheFinalMapsFromFilesOrMemoryAlike) {
  const SyntheticScene& s = Scene8();
  ImageCache images(s.Loader(), 256);
  const DepthController controller(MvsOptions(), nullptr);
  const std::string out = TempDir("fuse");
  FileDepthWorkspace files(s.scene, out, true);
  DepthRun run = MakeRun(s, &images);
  controller.Run(run, &files, nullptr);
  PointCloud from_files;
  const int n = static_cast<int>(s.scene.views.size());
  EXPECT_EQ(controller.Fuse(
                run, FusionOptions(), files, nullptr,
                [&](const StreamingFusion& f) { from_files = f.Cloud(); }),
            n);
  EXPECT_GT(from_files.size(), 1000u);
  EXPECT_GT(OnTheSurface(from_files, s), 0.97);
  // The same final maps held in memory (as the live path holds them).
  MemoryDepthWorkspace memory;
  for (int v = 0; v < n; ++v)
    memory.Put(Stage::kFinal, v, files.Read(Stage::kFinal, v));
  PointCloud from_memory;
  controller.Fuse(run, FusionOptions(), memory, nullptr,
                  [&](const StreamingFusion& f) { from_memory = f.Cloud(); });
  ASSERT_EQ(from_memory.size(), from_files.size());
  for (size_t i = 0; i < from_files.size(); ++i)
    ASSERT_EQ(from_memory.xyz[i], from_files.xyz[i]) << "point " << i;
  // Nothing to fuse is an error, not an empty cloud.
  MemoryDepthWorkspace empty;
  EXPECT_THROW(controller.Fuse(run, FusionOptions(), empty, nullptr, nullptr),
               Error);
  fs::remove_all(out);
}

TEST(DepthWorkspace, MissingMapsAreNamedErrors) {
  const SyntheticScene& s = Scene8();
  const std::string out = TempDir("missing");
  FileDepthWorkspace files(s.scene, out, true);
  EXPECT_FALSE(files.Has(Stage::kRaw, 2));
  try {
    files.Read(Stage::kRaw, 2);
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find(s.scene.views[2].Stem()),
              std::string::npos)
        << e.what();
  }
  EXPECT_THROW(files.Has(Stage::kRaw, 99), Error);
  MemoryDepthWorkspace memory;
  try {
    memory.Read(Stage::kFinal, 7);
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("view 7"), std::string::npos)
        << e.what();
  }
  fs::remove_all(out);
}

}  // namespace
}  // namespace wild_mvs
