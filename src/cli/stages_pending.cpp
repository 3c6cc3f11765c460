// Copyright wild_mvs authors. TEMPORARY until the PLY writer (io/ply.h) and
// meshing (core/meshing.h) land: the fuse and mesh stages report that they
// are missing. Replaced by run_fuse_mesh.cpp.
#include "wild_mvs/cli/run_steps.h"

namespace wild_mvs {
namespace cli {
PointCloud LoadFusedCloud(const std::string&) {
  throw Error("reading PLY is not available in this build yet");
}
FuseResult RunFuseStage(const Scene&, ImageCache*, const ReconstructConfig&,
                        ThreadPool*, const std::string&, const std::string&,
                        std::ostream&, PointCloud*) {
  throw Error("the fuse stage is not available in this build yet");
}
MeshResult RunMeshStage(const PointCloud&, const ReconstructConfig&,
                        const std::string&, std::ostream&) {
  throw Error("the mesh stage is not available in this build yet");
}
}  // namespace cli
}  // namespace wild_mvs
