// Copyright wild_mvs authors. libFuzzer harness: PLY clouds and meshes
// (ascii, binary little / big endian).
//
// An accepted mesh must be consistent: attribute arrays empty or of the
// vertex count, every face index a valid vertex. Accepted data must survive
// a write / read round trip.
#include <cstdint>
#include <string>

#include "fuzz_util.h"
#include "wild_mvs/core/error.h"
#include "wild_mvs/io/ply.h"

namespace {

void CheckCloud(const wild_mvs::PointCloud& c) {
  const size_t n = c.size();
  if ((c.has_normal() && c.normal.size() != n) ||
      (c.has_rgb() && c.rgb.size() != n) ||
      (c.has_confidence() && c.confidence.size() != n) ||
      (c.has_support() && c.support.size() != n))
    __builtin_trap();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace wild_mvs;
  const std::string path = fuzz::WriteScratch(
      "in.ply", std::string(reinterpret_cast<const char*>(data), size));
  Mesh mesh;
  try {
    mesh = ReadPlyMesh(path);
  } catch (const Error&) {
    // The cloud reader may accept what is no valid mesh (e.g. a face with
    // fewer than 3 vertices); what it accepts must be consistent.
    try {
      CheckCloud(ReadPlyCloud(path));
    } catch (const Error&) {
    }
    return 0;
  }
  CheckCloud(mesh.vertices);
  for (const Eigen::Vector3i& f : mesh.faces)
    for (int k = 0; k < 3; ++k)
      if (f[k] < 0 || f[k] >= static_cast<int>(mesh.vertices.size()))
        __builtin_trap();
  const PointCloud cloud = ReadPlyCloud(path);
  if (cloud.size() != mesh.vertices.size()) __builtin_trap();
  // Round trip through the writer (counts must be preserved).
  fuzz::WriteScratch("out.ply", "");
  const std::string out = fuzz::ScratchDir() + "/out.ply";
  WritePly(out, mesh);
  const Mesh back = ReadPlyMesh(out);
  if (back.vertices.size() != mesh.vertices.size() ||
      back.faces.size() != mesh.faces.size())
    __builtin_trap();
  return 0;
}
