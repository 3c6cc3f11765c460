// Copyright wild_mvs authors. Triangle mesh from the fused oriented points:
// screened Poisson surface reconstruction (PCL's pcl::Poisson), trimming of
// the surface Poisson invents beyond the data, optional decimation.
//
// Trimming (the paper removes Poisson's hole-filling surface by mesh
// filtering): every mesh vertex farther from its nearest sample than
// trim_distance x (local sample spacing at that sample, floored at half the
// Poisson voxel) is removed with its faces; then connected components with
// fewer than min_component_faces faces are dropped. Vertex colour,
// confidence and support come from the nearest sample; vertex normals are
// area-weighted face normals. Faces are oriented counter-clockwise seen from
// outside (the side the samples' normals point to).
#pragma once

#include <cstddef>

#include "wild_mvs/core/option_registry.h"
#include "wild_mvs/core/point_cloud.h"

namespace wild_mvs {

struct MeshingOptions {
  // Maximum octree depth of the Poisson solve (resolution 2^depth over the
  // bounding cube); the solver adapts below it.
  int depth = 9;
  // Trim: remove vertices farther than trim_distance x local sample spacing
  // from the nearest sample. 0 = no trimming.
  double trim_distance = 2.0;
  // Drop connected components with fewer faces after trimming.
  int min_component_faces = 50;
  // Vertex-clustering decimation cell in world units; 0 = off.
  double decimation_cell = 0.0;

  void Check() const;
};
// Registers the fields under `prefix` (option_registry.h), e.g. "meshing".
void RegisterOptions(OptionRegistry* registry, const std::string& prefix,
                     MeshingOptions* options);

struct MeshingStats {
  size_t input_points = 0;
  size_t poisson_vertices = 0, poisson_faces = 0;
  size_t trimmed_vertices = 0;  // removed by the distance test
  size_t small_component_faces = 0;
  size_t vertices = 0, faces = 0;  // of the result
  double voxel_size = 0;           // Poisson voxel at `depth`
};

// Meshes an oriented point cloud (normals required, facing outward / to the
// cameras). Throws Error when the cloud has no normals, fewer than 10
// points, or non-finite values.
Mesh MeshPointCloud(const PointCloud& cloud, const MeshingOptions& options,
                    MeshingStats* stats = nullptr);

// Vertex clustering on a grid of `cell` world units: vertices of one cell
// merge into their mean (attributes averaged), degenerate and duplicate faces
// are removed.
Mesh DecimateMesh(const Mesh& mesh, double cell);

// Throws Error naming the problem when the mesh is invalid: non-finite
// vertices, face indices out of range, degenerate faces, attribute arrays of
// the wrong size.
void ValidateMesh(const Mesh& mesh);

}  // namespace wild_mvs
