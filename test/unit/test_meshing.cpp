// Copyright wild_mvs authors. Tests of Poisson meshing with trimming on
// fused analytic scenes.
#include <gtest/gtest.h>

#include "test_fusion_scene.h"
#include "wild_mvs/core/error.h"
#include "wild_mvs/core/fusion.h"
#include "wild_mvs/core/meshing.h"

namespace wild_mvs {
namespace {

using fusion_test::AnalyticScene;
using fusion_test::Corrupt;

PointCloud FuseScene(const AnalyticScene& scene, int n) {
  DepthMapProvider prov = [scene, n](int v) {
    auto m = std::make_shared<DepthMap>(scene.Render(v, n));
    Corrupt(m.get(), 0.002, 0.05, 0.05, 500 + v);
    return std::shared_ptr<const DepthMap>(m);
  };
  ImageProvider colour = [scene](int) {
    return cv::Mat(scene.height, scene.width, CV_32FC3,
                   cv::Scalar(0.3, 0.1, 0.6));
  };
  std::vector<int> views(n);
  for (int i = 0; i < n; ++i) views[i] = i;
  ThreadPool pool(2);
  return FuseDepthMaps(views, FusionOptions(), prov, colour, nullptr, &pool);
}

double Area(const Mesh& m) {
  double a = 0;
  for (const auto& t : m.faces) {
    const Eigen::Vector3f& p = m.vertices.xyz[t[0]];
    a +=
        0.5 * (m.vertices.xyz[t[1]] - p).cross(m.vertices.xyz[t[2]] - p).norm();
  }
  return a;
}

// Area of the faces whose centroid is farther than d from the true surface.
double FarArea(const AnalyticScene& s, const Mesh& m, double d) {
  double a = 0;
  for (const auto& t : m.faces) {
    const Eigen::Vector3f& p = m.vertices.xyz[t[0]];
    const Eigen::Vector3f& q = m.vertices.xyz[t[1]];
    const Eigen::Vector3f& r = m.vertices.xyz[t[2]];
    if (s.Distance(((p + q + r) / 3).cast<double>()) > d)
      a += 0.5 * (q - p).cross(r - p).norm();
  }
  return a;
}

// Fraction of vertices within d of the true surface.
double FractionNear(const AnalyticScene& s, const Mesh& m, double d) {
  size_t k = 0;
  for (const auto& p : m.vertices.xyz) k += s.Distance(p.cast<double>()) <= d;
  return m.vertices.size() ? static_cast<double>(k) / m.vertices.size() : 0;
}

TEST(MeshingOptions, CheckRejectsBadValues) {
  EXPECT_NO_THROW(MeshingOptions().Check());
  MeshingOptions o;
  o.depth = 2;
  EXPECT_THROW(o.Check(), Error);
  o = MeshingOptions();
  o.trim_distance = -1;
  EXPECT_THROW(o.Check(), Error);
  o = MeshingOptions();
  o.trim_distance = NAN;
  EXPECT_THROW(o.Check(), Error);
  o = MeshingOptions();
  o.decimation_cell = -0.1;
  try {
    o.Check();
    ADD_FAILURE();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("decimation_cell"), std::string::npos);
  }
}

// A sphere seen from a ring above it: the mesh follows the true surface,
// faces point outward, colours come from the samples, and trimming removes
// the bottom cap that Poisson closes without data.
TEST(Meshing, FusedSphereTrimmedToData) {
  AnalyticScene scene;
  scene.with_ground = false;
  scene.ring_height = 3.0;  // 45 degrees up: the lower third is never seen
  scene.width = 320;
  scene.height = 240;
  scene.focal = 400;
  const PointCloud cloud = FuseScene(scene, 12);
  ASSERT_GT(cloud.size(), 3000u);
  float min_z = 1e9f;
  for (const auto& p : cloud.xyz) min_z = std::min(min_z, p.z());

  MeshingOptions o;
  o.depth = 7;
  MeshingStats st;
  const Mesh mesh = MeshPointCloud(cloud, o, &st);
  EXPECT_NO_THROW(ValidateMesh(mesh));
  ASSERT_GT(mesh.faces.size(), 1000u);
  std::printf(
      "sphere: %zu points -> poisson %zu v / %zu f -> %zu v / %zu f "
      "(trimmed %zu), voxel %.4f\n",
      cloud.size(), st.poisson_vertices, st.poisson_faces, st.vertices,
      st.faces, st.trimmed_vertices, st.voxel_size);
  const double r = scene.sphere_radius;
  EXPECT_GT(FractionNear(scene, mesh, 0.01 * r), 0.95);
  EXPECT_GT(FractionNear(scene, mesh, 0.03 * r), 0.995);
  // Nothing far below the lowest sample (the invented cap is gone).
  for (const auto& p : mesh.vertices.xyz) EXPECT_GT(p.z(), min_z - 0.1f);
  // Outward orientation of faces and vertex normals.
  size_t out = 0;
  for (const auto& t : mesh.faces) {
    const Eigen::Vector3f& a = mesh.vertices.xyz[t[0]];
    const Eigen::Vector3f fn =
        (mesh.vertices.xyz[t[1]] - a).cross(mesh.vertices.xyz[t[2]] - a);
    out += fn.dot(a) > 0;
  }
  EXPECT_GT(out, 0.99 * mesh.faces.size());
  ASSERT_TRUE(mesh.vertices.has_normal() && mesh.vertices.has_rgb());
  for (size_t i = 0; i < mesh.vertices.size(); ++i) {
    EXPECT_NEAR(mesh.vertices.rgb[i].x(), cloud.rgb[0].x(), 1e-5);
    EXPECT_NEAR(mesh.vertices.normal[i].norm(), 1.0, 1e-4);
  }
  // Area: the seen part of the sphere, not the closed sphere.
  const double full = 4 * M_PI * r * r;
  const double cap_z = min_z;  // area of the sphere above z = min_z
  const double seen = 2 * M_PI * r * (r - cap_z);
  const double area = Area(mesh);
  std::printf("area %.4f, seen %.4f, full sphere %.4f\n", area, seen, full);
  EXPECT_LT(area, 1.15 * seen);
  EXPECT_LT(area, 0.85 * full);
  EXPECT_GT(area, 0.9 * seen);

  // Without trimming Poisson closes the sphere: the test above can fail.
  MeshingOptions untrimmed = o;
  untrimmed.trim_distance = 0;
  const Mesh closed = MeshPointCloud(cloud, untrimmed);
  EXPECT_GT(Area(closed), 1.2 * seen);
  float closed_min_z = 1e9f;
  for (const auto& p : closed.vertices.xyz)
    closed_min_z = std::min(closed_min_z, p.z());
  EXPECT_LT(closed_min_z, min_z - 0.15f);
}

// Sphere on an open ground square: Poisson invents a hull around the open
// square; trimmed, every vertex is near the true surface.
TEST(Meshing, OpenSceneNoInventedHull) {
  AnalyticScene scene;
  const PointCloud cloud = FuseScene(scene, 12);
  MeshingOptions o;
  o.depth = 7;
  const Mesh mesh = MeshPointCloud(cloud, o);
  ValidateMesh(mesh);
  const double size = scene.SceneSize();
  const double near = FractionNear(scene, mesh, 0.005 * size);
  MeshingOptions untrimmed = o;
  untrimmed.trim_distance = 0;
  const Mesh hull = MeshPointCloud(cloud, untrimmed);
  const double hull_near = FractionNear(scene, hull, 0.005 * size);
  const double far = FarArea(scene, mesh, 0.02 * size);
  const double hull_far = FarArea(scene, hull, 0.02 * size);
  std::printf(
      "open scene: %zu faces, %.4f near, far area %.3f of %.3f; untrimmed "
      "%zu faces, %.4f near, far area %.3f of %.3f\n",
      mesh.faces.size(), near, far, Area(mesh), hull.faces.size(), hull_near,
      hull_far, Area(hull));
  EXPECT_GT(near, 0.95);
  EXPECT_LT(far, 0.01 * Area(mesh));
  EXPECT_GT(hull_far, 0.05 * Area(hull));  // what trimming removed
  // Ground square 2.4 x 2.4 plus the seen part of the sphere at most.
  EXPECT_LT(Area(mesh), 1.1 * (2.4 * 2.4 + 2 * M_PI * 0.5 * 0.9));
}

TEST(Meshing, DecimationKeepsAValidCloseMesh) {
  AnalyticScene scene;
  scene.with_ground = false;
  const PointCloud cloud = FuseScene(scene, 8);
  MeshingOptions o;
  o.depth = 6;
  const Mesh mesh = MeshPointCloud(cloud, o);
  MeshingOptions d = o;
  d.decimation_cell = 0.04;
  const Mesh small = MeshPointCloud(cloud, d);
  ValidateMesh(small);
  EXPECT_LT(small.faces.size(), mesh.faces.size() / 2);
  EXPECT_GT(small.faces.size(), 100u);
  EXPECT_GT(FractionNear(scene, small, 0.02), 0.9);
  EXPECT_GT(FractionNear(scene, small, 0.02),
            FractionNear(scene, mesh, 0.02) - 0.05);
  // A huge cell collapses the mesh into at most the 8 cells around the
  // origin.
  const Mesh none = DecimateMesh(mesh, 100.0);
  EXPECT_LE(none.vertices.size(), 8u);
  EXPECT_NO_THROW(ValidateMesh(none));
  EXPECT_THROW(DecimateMesh(mesh, 0.0), Error);
}

TEST(Meshing, RejectsBadInputAndInvalidMeshes) {
  PointCloud pc;
  for (int i = 0; i < 20; ++i) pc.xyz.emplace_back(i, 0, 0);
  EXPECT_THROW(MeshPointCloud(pc, MeshingOptions()), Error);  // no normals
  pc.normal.assign(20, Eigen::Vector3f(0, 0, 1));
  pc.xyz[3].x() = NAN;
  EXPECT_THROW(MeshPointCloud(pc, MeshingOptions()), Error);
  Mesh m;
  m.vertices.xyz = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  m.faces = {{0, 1, 2}};
  EXPECT_NO_THROW(ValidateMesh(m));
  m.faces = {{0, 1, 3}};
  EXPECT_THROW(ValidateMesh(m), Error);
  m.faces = {{0, 1, 1}};
  EXPECT_THROW(ValidateMesh(m), Error);
  m.faces = {{0, 1, 2}};
  m.vertices.xyz[1].y() = INFINITY;
  EXPECT_THROW(ValidateMesh(m), Error);
}

}  // namespace
}  // namespace wild_mvs
