// Copyright wild_mvs authors.
#include "wild_mvs/core/meshing.h"

#include <pcl/kdtree/kdtree_flann.h>
#include <pcl/point_types.h>
#include <pcl/surface/poisson.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <numeric>
#include <unordered_map>

#include "wild_mvs/core/error.h"

namespace wild_mvs {

namespace {
// Screened Poisson (Kazhdan and Hoppe 2013): PoissonRecon's screening
// weight, samples per octree node for MVS noise, and the reconstruction
// cube over the samples' bounding cube.
constexpr double kPointWeight = 4.0;
constexpr double kSamplesPerNode = 1.5;
constexpr double kScale = 1.1;
// Neighbours whose mean distance defines the local sample spacing (trim).
constexpr int kSpacingNeighbors = 8;
}  // namespace

void MeshingOptions::Check() const {
  Require(depth >= 4 && depth <= 14, "meshing.depth = ", depth,
          " must be in [4, 14]");
  Require(std::isfinite(trim_distance) && trim_distance >= 0,
          "meshing.trim_distance = ", trim_distance, " must be >= 0");
  Require(min_component_faces >= 0,
          "meshing.min_component_faces = ", min_component_faces,
          " must be >= 0");
  Require(std::isfinite(decimation_cell) && decimation_cell >= 0,
          "meshing.decimation_cell = ", decimation_cell, " must be >= 0");
}

void RegisterOptions(OptionRegistry* registry, const std::string& prefix,
                     MeshingOptions* o) {
  auto key = [&prefix](const char* name) {
    return OptionRegistry::Join(prefix, name);
  };
  registry
      ->Add(key("depth"), &o->depth,
            "maximum octree depth of the Poisson solve (resolution 2^depth)")
      .Min(4)
      .Max(14);
  registry
      ->Add(key("trim_distance"), &o->trim_distance,
            "remove surface farther than this x local sample spacing from "
            "the samples, 0 = no trimming")
      .Min(0);
  registry
      ->Add(key("min_component_faces"), &o->min_component_faces,
            "drop connected pieces with fewer faces after trimming")
      .Min(0);
  registry
      ->Add(key("decimation_cell"), &o->decimation_cell,
            "vertex-clustering cell in world units, 0 = no decimation")
      .Min(0);
}

namespace {

// Keeps the vertices with keep[i], remaps faces, drops faces that lose a
// vertex, and drops unreferenced vertices.
Mesh Compact(const Mesh& in, const std::vector<char>& keep_vertex,
             const std::vector<char>& keep_face) {
  const size_t nv = in.vertices.size();
  std::vector<char> used(nv, 0);
  std::vector<Eigen::Vector3i> faces;
  for (size_t f = 0; f < in.faces.size(); ++f) {
    if (!keep_face.empty() && !keep_face[f]) continue;
    const Eigen::Vector3i& t = in.faces[f];
    if (!keep_vertex[t[0]] || !keep_vertex[t[1]] || !keep_vertex[t[2]])
      continue;
    faces.push_back(t);
    used[t[0]] = used[t[1]] = used[t[2]] = 1;
  }
  std::vector<int> remap(nv, -1);
  Mesh out;
  const PointCloud& v = in.vertices;
  PointCloud& o = out.vertices;
  for (size_t i = 0; i < nv; ++i) {
    if (!used[i]) continue;
    remap[i] = static_cast<int>(o.xyz.size());
    o.xyz.push_back(v.xyz[i]);
    if (v.has_normal()) o.normal.push_back(v.normal[i]);
    if (v.has_rgb()) o.rgb.push_back(v.rgb[i]);
    if (v.has_confidence()) o.confidence.push_back(v.confidence[i]);
    if (v.has_support()) o.support.push_back(v.support[i]);
  }
  for (Eigen::Vector3i& t : faces)
    t = Eigen::Vector3i(remap[t[0]], remap[t[1]], remap[t[2]]);
  out.faces = std::move(faces);
  return out;
}

// Area-weighted vertex normals from the faces.
void ComputeVertexNormals(Mesh* mesh) {
  std::vector<Eigen::Vector3f> n(mesh->vertices.size(),
                                 Eigen::Vector3f::Zero());
  for (const Eigen::Vector3i& t : mesh->faces) {
    const Eigen::Vector3f& a = mesh->vertices.xyz[t[0]];
    const Eigen::Vector3f fn =
        (mesh->vertices.xyz[t[1]] - a).cross(mesh->vertices.xyz[t[2]] - a);
    for (int k = 0; k < 3; ++k) n[t[k]] += fn;
  }
  for (Eigen::Vector3f& v : n) {
    const float len = v.norm();
    v = len > 0 && std::isfinite(len) ? Eigen::Vector3f(v / len)
                                      : Eigen::Vector3f(0, 0, 1);
  }
  mesh->vertices.normal = std::move(n);
}

// Union-find component labels over faces sharing a vertex.
std::vector<int> FaceComponents(const Mesh& mesh) {
  std::vector<int> parent(mesh.vertices.size());
  std::iota(parent.begin(), parent.end(), 0);
  auto find = [&](int x) {
    while (parent[x] != x) x = parent[x] = parent[parent[x]];
    return x;
  };
  for (const Eigen::Vector3i& t : mesh.faces) {
    const int a = find(t[0]), b = find(t[1]), c = find(t[2]);
    parent[b] = a;
    parent[find(c)] = a;
  }
  std::vector<int> comp(mesh.faces.size());
  for (size_t f = 0; f < mesh.faces.size(); ++f)
    comp[f] = find(mesh.faces[f][0]);
  return comp;
}

}  // namespace

Mesh MeshPointCloud(const PointCloud& cloud, const MeshingOptions& options,
                    MeshingStats* stats_out) {
  options.Check();
  MeshingStats stats;
  stats.input_points = cloud.size();
  Require(cloud.size() >= 10, "meshing: the point cloud has only ",
          cloud.size(), " points (need >= 10)");
  Require(cloud.has_normal() && cloud.normal.size() == cloud.size(),
          "meshing: the point cloud has no normals (", cloud.normal.size(),
          " normals for ", cloud.size(), " points)");
  Require(!cloud.has_rgb() || cloud.rgb.size() == cloud.size(),
          "meshing: colour array size ", cloud.rgb.size(),
          " != ", cloud.size());

  pcl::PointCloud<pcl::PointNormal>::Ptr pts(
      new pcl::PointCloud<pcl::PointNormal>);
  pts->reserve(cloud.size());
  Eigen::Vector3f lo = Eigen::Vector3f::Constant(1e30f), hi = -lo;
  for (size_t i = 0; i < cloud.size(); ++i) {
    const Eigen::Vector3f& p = cloud.xyz[i];
    Eigen::Vector3f n = cloud.normal[i];
    Require(p.allFinite() && n.allFinite(), "meshing: point ", i,
            " has a non-finite position or normal");
    const float len = n.norm();
    Require(len > 0, "meshing: point ", i, " has a zero normal");
    n /= len;
    pcl::PointNormal q;
    q.x = p.x(), q.y = p.y(), q.z = p.z();
    q.normal_x = n.x(), q.normal_y = n.y(), q.normal_z = n.z();
    pts->push_back(q);
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  stats.voxel_size =
      (hi - lo).maxCoeff() * kScale / std::ldexp(1.0, options.depth);

  pcl::Poisson<pcl::PointNormal> poisson;
  poisson.setDepth(options.depth);
  poisson.setPointWeight(static_cast<float>(kPointWeight));
  poisson.setSamplesPerNode(static_cast<float>(kSamplesPerNode));
  poisson.setScale(static_cast<float>(kScale));
  // One thread: the same mesh on every machine, in seconds at depth 9.
  poisson.setThreads(1);
  poisson.setManifold(true);
  poisson.setOutputPolygons(false);
  poisson.setInputCloud(pts);
  pcl::PointCloud<pcl::PointNormal> verts;
  std::vector<pcl::Vertices> polys;
  poisson.reconstruct(verts, polys);
  stats.poisson_vertices = verts.size();

  Mesh mesh;
  mesh.vertices.xyz.reserve(verts.size());
  for (const auto& v : verts) mesh.vertices.xyz.emplace_back(v.x, v.y, v.z);
  for (const pcl::Vertices& poly : polys) {
    if (poly.vertices.size() != 3) continue;
    const Eigen::Vector3i t(poly.vertices[0], poly.vertices[1],
                            poly.vertices[2]);
    if ((t.array() < 0).any() ||
        (t.array() >= static_cast<int>(verts.size())).any())
      continue;
    if (t[0] == t[1] || t[1] == t[2] || t[0] == t[2]) continue;
    mesh.faces.push_back(t);
  }
  stats.poisson_faces = mesh.faces.size();

  // Nearest sample of every vertex, local spacing of every sample.
  pcl::KdTreeFLANN<pcl::PointNormal> tree;
  tree.setInputCloud(pts);
  const int k =
      std::min<int>(kSpacingNeighbors + 1, static_cast<int>(cloud.size()));
  std::vector<float> spacing(cloud.size(), 0.f);
  {
    std::vector<int> idx(k);
    std::vector<float> d2(k);
    for (size_t i = 0; i < cloud.size(); ++i) {
      const int found = tree.nearestKSearch((*pts)[i], k, idx, d2);
      double sum = 0;
      int cnt = 0;
      for (int j = 0; j < found; ++j)
        if (idx[j] != static_cast<int>(i)) sum += std::sqrt(d2[j]), ++cnt;
      spacing[i] = cnt ? static_cast<float>(sum / cnt) : 0.f;
    }
  }
  const size_t nv = mesh.vertices.size();
  std::vector<int> nearest(nv, 0);
  std::vector<char> keep(nv, 1);
  {
    std::vector<int> idx(1);
    std::vector<float> d2(1);
    for (size_t i = 0; i < nv; ++i) {
      const Eigen::Vector3f& p = mesh.vertices.xyz[i];
      if (!p.allFinite()) {
        keep[i] = 0;
        continue;
      }
      pcl::PointNormal q;
      q.x = p.x(), q.y = p.y(), q.z = p.z();
      if (tree.nearestKSearch(q, 1, idx, d2) < 1) {
        keep[i] = 0;
        continue;
      }
      nearest[i] = idx[0];
      if (options.trim_distance > 0) {
        const double limit =
            options.trim_distance *
            std::max<double>(spacing[idx[0]], 0.5 * stats.voxel_size);
        if (std::sqrt(d2[0]) > limit) {
          keep[i] = 0;
          ++stats.trimmed_vertices;
        }
      }
    }
  }

  // Attributes from the nearest sample.
  if (cloud.has_rgb()) {
    mesh.vertices.rgb.resize(nv);
    for (size_t i = 0; i < nv; ++i)
      mesh.vertices.rgb[i] = cloud.rgb[nearest[i]];
  }
  if (cloud.has_confidence() && cloud.confidence.size() == cloud.size()) {
    mesh.vertices.confidence.resize(nv);
    for (size_t i = 0; i < nv; ++i)
      mesh.vertices.confidence[i] = cloud.confidence[nearest[i]];
  }
  if (cloud.has_support() && cloud.support.size() == cloud.size()) {
    mesh.vertices.support.resize(nv);
    for (size_t i = 0; i < nv; ++i)
      mesh.vertices.support[i] = cloud.support[nearest[i]];
  }

  // Orientation: faces counter-clockwise seen from the side the samples'
  // normals point to. Poisson's output is consistently oriented; flip it
  // all when most faces disagree with their nearest samples.
  {
    double agree = 0;
    for (const Eigen::Vector3i& t : mesh.faces) {
      const Eigen::Vector3f& a = mesh.vertices.xyz[t[0]];
      const Eigen::Vector3f fn =
          (mesh.vertices.xyz[t[1]] - a).cross(mesh.vertices.xyz[t[2]] - a);
      if (!keep[t[0]]) continue;
      agree += fn.dot(cloud.normal[nearest[t[0]]]) > 0 ? 1 : -1;
    }
    if (agree < 0)
      for (Eigen::Vector3i& t : mesh.faces) std::swap(t[1], t[2]);
  }

  mesh = Compact(mesh, keep, {});

  // Small components left by trimming.
  if (options.min_component_faces > 0 && !mesh.faces.empty()) {
    const std::vector<int> comp = FaceComponents(mesh);
    std::unordered_map<int, int> count;
    for (int c : comp) ++count[c];
    std::vector<char> keep_face(mesh.faces.size(), 1);
    for (size_t f = 0; f < comp.size(); ++f)
      if (count[comp[f]] < options.min_component_faces) {
        keep_face[f] = 0;
        ++stats.small_component_faces;
      }
    mesh = Compact(mesh, std::vector<char>(mesh.vertices.size(), 1), keep_face);
  }

  if (options.decimation_cell > 0)
    mesh = DecimateMesh(mesh, options.decimation_cell);
  ComputeVertexNormals(&mesh);
  ValidateMesh(mesh);
  stats.vertices = mesh.vertices.size();
  stats.faces = mesh.faces.size();
  if (stats_out) *stats_out = stats;
  return mesh;
}

Mesh DecimateMesh(const Mesh& mesh, double cell) {
  Require(std::isfinite(cell) && cell > 0, "DecimateMesh: cell = ", cell,
          " must be > 0");
  const PointCloud& v = mesh.vertices;
  const size_t nv = v.size();
  // Cluster id per vertex, in first-seen order (deterministic).
  std::map<std::array<int64_t, 3>, int> clusters;
  std::vector<int> cluster(nv);
  for (size_t i = 0; i < nv; ++i) {
    const std::array<int64_t, 3> key = {
        static_cast<int64_t>(std::floor(v.xyz[i].x() / cell)),
        static_cast<int64_t>(std::floor(v.xyz[i].y() / cell)),
        static_cast<int64_t>(std::floor(v.xyz[i].z() / cell))};
    auto it = clusters.emplace(key, static_cast<int>(clusters.size())).first;
    cluster[i] = it->second;
  }
  const size_t nc = clusters.size();
  Mesh out;
  PointCloud& o = out.vertices;
  std::vector<int> count(nc, 0);
  o.xyz.assign(nc, Eigen::Vector3f::Zero());
  if (v.has_normal()) o.normal.assign(nc, Eigen::Vector3f::Zero());
  if (v.has_rgb()) o.rgb.assign(nc, Eigen::Vector3f::Zero());
  if (v.has_confidence()) o.confidence.assign(nc, 0.f);
  if (v.has_support()) o.support.assign(nc, 0);
  for (size_t i = 0; i < nv; ++i) {
    const int c = cluster[i];
    ++count[c];
    o.xyz[c] += v.xyz[i];
    if (v.has_normal()) o.normal[c] += v.normal[i];
    if (v.has_rgb()) o.rgb[c] += v.rgb[i];
    if (v.has_confidence()) o.confidence[c] += v.confidence[i];
    if (v.has_support()) o.support[c] = std::max(o.support[c], v.support[i]);
  }
  for (size_t c = 0; c < nc; ++c) {
    const float n = static_cast<float>(count[c]);
    o.xyz[c] /= n;
    if (v.has_normal()) {
      const float len = o.normal[c].norm();
      o.normal[c] = len > 0 ? Eigen::Vector3f(o.normal[c] / len)
                            : Eigen::Vector3f(0, 0, 1);
    }
    if (v.has_rgb()) o.rgb[c] /= n;
    if (v.has_confidence()) o.confidence[c] /= n;
  }
  std::map<std::array<int, 3>, char> seen;
  for (const Eigen::Vector3i& t : mesh.faces) {
    const Eigen::Vector3i m(cluster[t[0]], cluster[t[1]], cluster[t[2]]);
    if (m[0] == m[1] || m[1] == m[2] || m[0] == m[2]) continue;
    // Same triangle regardless of rotation: smallest index first.
    std::array<int, 3> key = {m[0], m[1], m[2]};
    std::rotate(key.begin(), std::min_element(key.begin(), key.end()),
                key.end());
    if (!seen.emplace(key, 1).second) continue;
    out.faces.push_back(m);
  }
  std::vector<char> keep(nc, 1);
  out = Compact(out, keep, {});
  return out;
}

void ValidateMesh(const Mesh& mesh) {
  const PointCloud& v = mesh.vertices;
  const size_t n = v.size();
  Require(!v.has_normal() || v.normal.size() == n, "mesh: ", v.normal.size(),
          " normals for ", n, " vertices");
  Require(!v.has_rgb() || v.rgb.size() == n, "mesh: ", v.rgb.size(),
          " colours for ", n, " vertices");
  Require(!v.has_confidence() || v.confidence.size() == n,
          "mesh: ", v.confidence.size(), " confidences for ", n, " vertices");
  Require(!v.has_support() || v.support.size() == n, "mesh: ", v.support.size(),
          " support values for ", n, " vertices");
  for (size_t i = 0; i < n; ++i) {
    Require(v.xyz[i].allFinite(), "mesh: vertex ", i, " is not finite");
    if (v.has_normal())
      Require(v.normal[i].allFinite(), "mesh: normal ", i, " is not finite");
  }
  for (size_t f = 0; f < mesh.faces.size(); ++f) {
    const Eigen::Vector3i& t = mesh.faces[f];
    Require((t.array() >= 0).all() && (t.array() < static_cast<int>(n)).all(),
            "mesh: face ", f, " has an index out of [0, ", n, ")");
    Require(t[0] != t[1] && t[1] != t[2] && t[0] != t[2], "mesh: face ", f,
            " is degenerate (repeated vertex)");
  }
}

}  // namespace wild_mvs
