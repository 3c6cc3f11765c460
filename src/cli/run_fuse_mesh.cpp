// Copyright wild_mvs authors. Fusion and meshing stages (run_steps.h).
#include <fcntl.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <memory>

#include "wild_mvs/cli/progress.h"
#include "wild_mvs/cli/run_steps.h"
#include "wild_mvs/cli/scene_setup.h"
#include "wild_mvs/core/fusion.h"
#include "wild_mvs/core/meshing.h"
#include "wild_mvs/core/stats.h"
#include "wild_mvs/io/depth_map_io.h"
#include "wild_mvs/io/image_files.h"
#include "wild_mvs/io/ply.h"

namespace wild_mvs {
namespace cli {
namespace {
using Clock = std::chrono::steady_clock;
double SecondsSince(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}
// PCL's Poisson code prints diagnostics ("Vertex pair not in list") on
// stdout, which belongs to the tool's results: silence fd 1 meanwhile.
class SilenceStdout {
 public:
  SilenceStdout() {
    std::cout.flush();
    std::fflush(stdout);
    saved_ = dup(STDOUT_FILENO);
    const int null = open("/dev/null", O_WRONLY | O_CLOEXEC);
    if (saved_ >= 0 && null >= 0) dup2(null, STDOUT_FILENO);
    if (null >= 0) close(null);
  }
  ~SilenceStdout() {
    std::cout.flush();
    std::fflush(stdout);
    if (saved_ >= 0) {
      dup2(saved_, STDOUT_FILENO);
      close(saved_);
    }
  }
  SilenceStdout(const SilenceStdout&) = delete;
  SilenceStdout& operator=(const SilenceStdout&) = delete;

 private:
  int saved_ = -1;
};

}  // namespace

PointCloud LoadFusedCloud(const std::string& path) {
  return ReadPlyCloud(path);
}

FuseResult RunFuseStage(const Scene& scene, ImageCache* images,
                        const ReconstructConfig& config, ThreadPool* pool,
                        const std::string& out, const std::string& ply,
                        std::ostream& log, PointCloud* cloud_out) {
  const auto t0 = Clock::now();
  std::vector<int> views;
  for (size_t i = 0; i < scene.views.size(); ++i) {
    if (DepthMapFilesExist(out, scene.views[i].Stem())) {
      views.push_back(static_cast<int>(i));
    }
  }
  Require(!views.empty(), out,
          ": no depth maps of this dataset's views (expected depth/S.pfm and "
          "cameras/S.txt, e.g. S = ",
          scene.views.empty() ? "?" : scene.views[0].Stem(),
          "); run 'wild_mvs reconstruct' first");
  Progress progress("fuse", static_cast<int>(views.size()), log,
                    StderrIsTerminal());
  DepthMapProvider depth = [&](int v) {
    return std::make_shared<const DepthMap>(
        ReadDepthMapFiles(out, scene.views[v].Stem(), scene));
  };
  // Fusion reads each view's image once (its samples' colours), so the
  // images cached for the earlier stages go and the fusion's own are not
  // cached: its memory depends neither on image.cache_mb nor on how much of
  // the collection that cache held.
  ImageProvider image;
  if (images) {
    images->Clear();
    ReleaseFreeMemory();
    image = [images](int v) { return images->Load(v); };
  }
  MaskProvider mask = [&](int v) { return LoadViewMask(scene.views[v]); };
  StreamingFusion fusion(config.fusion, depth, image, mask, pool);
  for (int v : views) {
    progress.Begin(scene.views[v].Stem());
    fusion.AddView(v);
    progress.End("");
  }
  progress.Finish();
  // Only the cloud is left to use: the maps and pending samples go first,
  // and without a caller that needs the cloud it is written in chunks
  // rather than copied whole.
  fusion.Finish();
  const FusionStats& st = fusion.stats();
  if (cloud_out) {
    *cloud_out = fusion.Cloud();
    WritePly(ply, *cloud_out);
  } else {
    WritePlyChunked(ply, fusion.num_points(), [&](size_t begin, size_t end) {
      return fusion.Cloud(begin, end);
    });
  }
  FuseResult r;
  r.views = static_cast<int>(views.size());
  r.points = fusion.num_points();
  r.seconds = SecondsSince(t0);
  log << "fuse: " << r.views << " depth maps, " << st.samples << " samples, "
      << st.accepted << " consistent -> " << r.points << " points, peak "
      << st.peak_bytes / (1024 * 1024) << " MB, "
      << Progress::FormatDuration(r.seconds) << " -> " << ply << std::endl;
  return r;
}

MeshResult RunMeshStage(const PointCloud& cloud,
                        const ReconstructConfig& config, const std::string& ply,
                        std::ostream& log) {
  const auto t0 = Clock::now();
  log << "mesh: Poisson reconstruction of " << cloud.size() << " points..."
      << std::endl;
  MeshingStats stats;
  Mesh mesh;
  {
    SilenceStdout quiet;
    mesh = MeshPointCloud(cloud, config.mesh, &stats);
  }
  WritePly(ply, mesh);
  MeshResult r;
  r.vertices = mesh.vertices.size();
  r.faces = mesh.faces.size();
  r.seconds = SecondsSince(t0);
  log << "mesh: " << stats.poisson_faces << " Poisson faces, "
      << stats.trimmed_vertices << " vertices trimmed -> " << r.vertices
      << " vertices, " << r.faces << " faces, "
      << Progress::FormatDuration(r.seconds) << " -> " << ply << std::endl;
  return r;
}

}  // namespace cli
}  // namespace wild_mvs
