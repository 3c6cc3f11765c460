// Copyright wild_mvs authors. PLY point clouds and triangle meshes.
//
// Writer: binary little-endian; vertex properties, only those present in
// the cloud: float x y z; float nx ny nz; uchar red green blue (colour in
// [0,1] x 255, rounded); float confidence; ushort support. Faces:
// `element face N` / `property list uchar int vertex_indices`. Atomic.
// Reader: ascii, binary_little_endian and binary_big_endian; any scalar
// property type; vertex x y z (required), nx ny nz, red/green/blue (or
// r/g/b, diffuse_red/...; integer types are scaled to [0,1] by their
// maximum, float kept), confidence, support; other properties and elements
// are skipped; faces from `vertex_indices` / `vertex_index` lists (polygons
// are fan-triangulated). Counts are bounds-checked against the file size
// before anything is allocated; errors name the file and the element /
// line / byte offset.
#pragma once

#include <cstddef>
#include <functional>
#include <string>

#include "wild_mvs/core/point_cloud.h"

namespace wild_mvs {

void WritePly(const std::string& path, const PointCloud& cloud);
void WritePly(const std::string& path, const Mesh& mesh);

// Points [begin, end) of a cloud, with the same attributes for every range.
using PointChunkSource = std::function<PointCloud(size_t begin, size_t end)>;
// Writes a cloud of n points that `chunk` hands out chunk_points at a time
// (in order; a cloud of 0 points asks for [0, 0) for its attributes): the
// same bytes as WritePly of the whole cloud, holding one chunk at a time.
void WritePlyChunked(const std::string& path, size_t n,
                     const PointChunkSource& chunk,
                     size_t chunk_points = 65536);

// Vertices only (faces, if any, are read and checked but dropped).
PointCloud ReadPlyCloud(const std::string& path);
Mesh ReadPlyMesh(const std::string& path);

}  // namespace wild_mvs
