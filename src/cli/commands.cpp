// Copyright wild_mvs authors.
#include "wild_mvs/cli/commands.h"

#include <unistd.h>

#include <climits>

namespace wild_mvs {
namespace cli {

const std::vector<Command>& AllCommands() {
  static const std::vector<Command> commands = {
      {"info", "print a dataset's views, sparse points and sanity checks",
       &RunInfo},
      {"sparse", "compute sparse tracks from known poses (COLMAP text model)",
       &RunSparse},
      {"reconstruct",
       "depth maps, fused point cloud and mesh of a dataset (resumable)",
       &RunReconstruct},
      {"photos",
       "photos without poses -> cameras (COLMAP), cloud and mesh (resumable)",
       &RunPhotos},
      {"fuse", "fuse the depth maps of a reconstruct folder into fused.ply",
       &RunFuse},
      {"mesh", "Poisson mesh of a reconstruct folder's fused.ply (mesh.ply)",
       &RunMesh},
      {"eval", "score depth maps or a point cloud against ground truth",
       &RunEval},
      {"render", "draw a cloud or mesh to a PNG (offscreen, z-buffered)",
       &RunRender},
      {"to-bag", "write a dataset as a ROS bag (needs the ROS build)",
       &RunToBag},
  };
  return commands;
}

std::string ExecutableDir() {
  char buf[PATH_MAX];
  const ssize_t n = readlink("/proc/self/exe", buf, sizeof(buf) - 1);
  if (n <= 0) return "";
  std::string path(buf, static_cast<size_t>(n));
  const size_t slash = path.rfind('/');
  return slash == std::string::npos ? "" : path.substr(0, slash);
}

}  // namespace cli
}  // namespace wild_mvs
