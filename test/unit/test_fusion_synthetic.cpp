// Copyright wild_mvs authors. Fusion on the rendered synthetic scenes
// (test/support): ground-truth depth maps corrupted with noise and outliers,
// scored with the cloud metrics against the scene's ground-truth cloud.
#include <gtest/gtest.h>

#include "synthetic_scene.h"
#include "test_fusion_scene.h"
#include "wild_mvs/core/fusion.h"
#include "wild_mvs/core/meshing.h"
#include "wild_mvs/core/metrics.h"

namespace wild_mvs {
namespace {

using testing::SyntheticScene;

DepthMapProvider Provider(const SyntheticScene& s, double noise,
                          double outliers) {
  return [&s, noise, outliers](int v) {
    auto m = std::make_shared<DepthMap>();
    m->view = v;
    m->camera = s.scene.views[v].camera;
    m->depth = s.depth[v].clone();
    m->normal = s.normals[v].clone();
    m->confidence = cv::Mat(m->depth.size(), CV_32F, cv::Scalar(1));
    fusion_test::Corrupt(m.get(), noise, 0.05, outliers, 77 + v);
    // No neighbour list: related views come from camera overlap.
    return std::shared_ptr<const DepthMap>(m);
  };
}

std::vector<int> All(const SyntheticScene& s) {
  std::vector<int> v(s.scene.views.size());
  for (size_t i = 0; i < v.size(); ++i) v[i] = static_cast<int>(i);
  return v;
}

class FusionSynthetic : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    clutter_ = new SyntheticScene(
        testing::Render(testing::ClutteredSceneSpec(false, false)));
    occluded_ = new SyntheticScene(
        testing::Render(testing::ClutteredSceneSpec(false, true)));
  }
  static void TearDownTestSuite() {
    delete clutter_;
    delete occluded_;
  }
  static SyntheticScene* clutter_;
  static SyntheticScene* occluded_;
};
SyntheticScene* FusionSynthetic::clutter_ = nullptr;
SyntheticScene* FusionSynthetic::occluded_ = nullptr;

// F-score at tau = 0.5 % and 1 % of the scene size with 0.2 % depth noise
// and 10 % outliers: fails if the consistency check or merging regresses.
TEST_F(FusionSynthetic, ClutteredSceneFScore) {
  const SyntheticScene& s = *clutter_;
  ThreadPool pool(2);
  ImageProvider images = [&s](int v) { return s.images[v]; };
  const PointCloud pc = FuseDepthMaps(
      All(s), FusionOptions(), Provider(s, 0.002, 0.1), images, nullptr, &pool);
  CloudMetricsOptions mo;
  mo.taus = {0.005 * s.scene_size, 0.01 * s.scene_size};
  const CloudMetrics m = EvaluateCloud(pc, s.GroundTruthCloud(2), mo);
  std::printf("cluttered, k=3: %zu points\n%s\n", pc.size(),
              m.ToString().c_str());
  EXPECT_GT(m.precision[0], 0.97);
  EXPECT_GT(m.fscore[0], 0.94);
  EXPECT_GT(m.fscore[1], 0.96);
  EXPECT_LT(m.accuracy, 0.005 * s.scene_size);
  ASSERT_TRUE(pc.has_rgb());
  for (const auto& c : pc.rgb)
    EXPECT_TRUE(c.allFinite() && c.minCoeff() >= 0 && c.maxCoeff() <= 1);

  FusionOptions no_check;
  no_check.min_support = 1;
  const PointCloud raw = FuseDepthMaps(
      All(s), no_check, Provider(s, 0.002, 0.1), images, nullptr, &pool);
  const CloudMetrics r = EvaluateCloud(raw, s.GroundTruthCloud(2), mo);
  std::printf("cluttered, k=1: %zu points, precision %.4f\n", raw.size(),
              r.precision[0]);
  EXPECT_LT(r.precision[0], m.precision[0] - 0.1);

  // The fused cloud meshes into a valid mesh close to the ground truth.
  MeshingOptions meshing;
  meshing.depth = 7;
  const Mesh mesh = MeshPointCloud(pc, meshing);
  ValidateMesh(mesh);
  const CloudMetrics mm =
      EvaluateCloud(mesh.vertices, s.GroundTruthCloud(2), mo);
  std::printf("mesh vertices: %s\n", mm.ToString().c_str());
  EXPECT_GT(mm.precision[1], 0.93);
}

// An occluder present in view 0 only (a passer-by) has no support in other
// views: the fused cloud does not contain it.
TEST_F(FusionSynthetic, TransientOccluderRemoved) {
  const SyntheticScene& s = *occluded_;
  const PointCloud pc =
      FuseDepthMaps(All(s), FusionOptions(), Provider(s, 0.001, 0.0));
  // Ground truth without the occluder: the depth maps of views 1..n-1.
  PointCloud gt;
  for (size_t v = 1; v < s.depth.size(); ++v) {
    const Camera& cam = s.scene.views[v].camera;
    for (int r = 0; r < s.depth[v].rows; r += 2)
      for (int c = 0; c < s.depth[v].cols; c += 2) {
        const float z = s.depth[v].at<float>(r, c);
        if (z > 0)
          gt.xyz.push_back(
              cam.Backproject({c + 0.5, r + 0.5}, z).cast<float>());
      }
  }
  // Points of the occluder: backprojected from view 0 where its depth is
  // far in front of every other view's surface.
  const double tau = 0.01 * s.scene_size;
  const std::vector<double> d = NearestDistances(pc, gt);
  size_t far = 0;
  for (double x : d) far += x > 3 * tau;
  std::printf(
      "occluder scene: %zu points, %zu farther than %.3f from the "
      "occluder-free surface\n",
      pc.size(), far, 3 * tau);
  EXPECT_LT(far, 0.001 * pc.size() + 5);
  // Without the check the occluder is in the cloud.
  FusionOptions none;
  none.min_support = 1;
  const PointCloud raw = FuseDepthMaps(All(s), none, Provider(s, 0.001, 0.0));
  const std::vector<double> dr = NearestDistances(raw, gt);
  size_t far_raw = 0;
  for (double x : dr) far_raw += x > 3 * tau;
  EXPECT_GT(far_raw, 200u);
}

}  // namespace
}  // namespace wild_mvs
