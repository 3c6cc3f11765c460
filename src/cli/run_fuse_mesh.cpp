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
#include "wild_mvs/pipeline/depth_controller.h"
#include "wild_mvs/pipeline/file_workspace.h"

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

// The fusion's progress: a bar on a terminal, nothing per view in logs.
class FuseProgress : public DepthRunObserver {
 public:
  FuseProgress(const Scene& scene, std::ostream& log)
      : scene_(scene), log_(log) {}
  void StepBegins(Step, int total) override {
    progress_ =
        std::make_unique<Progress>("fuse", total, log_, StderrIsTerminal());
  }
  void StepEnds(Step) override {
    progress_->Finish();
    progress_.reset();
  }
  void Begins(Step, int, int key) override {
    progress_->Begin(scene_.views[key].Stem());
  }
  void Done(Step, int, int, const ViewResult&) override { progress_->End(""); }

 private:
  const Scene& scene_;
  std::ostream& log_;
  std::unique_ptr<Progress> progress_;
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
  const DepthController controller(config.mvs, pool);
  // The final maps: OUT (filtered or not).
  const FileDepthWorkspace workspace(scene, out, false);
  DepthRun run;
  run.scene = &scene;
  for (size_t i = 0; i < scene.views.size(); ++i) {
    if (workspace.Has(DepthWorkspace::Stage::kFinal, static_cast<int>(i)))
      run.views.push_back(static_cast<int>(i));
  }
  Require(!run.views.empty(), out,
          ": no depth maps of this dataset's views (expected depth/S.pfm, "
          "cameras/S.txt and log/S.json, e.g. S = ",
          scene.views.empty() ? "?" : scene.views[0].Stem(),
          "); run 'wild_mvs reconstruct' first");
  run.images = images;
  run.mask = [&scene](int v) { return LoadViewMask(scene.views[v]); };
  FuseProgress progress(scene, log);
  FuseResult r;
  FusionStats st;
  r.views =
      controller.Fuse(run, config.fusion, workspace, &progress,
                      [&](const StreamingFusion& fusion) {
                        // Without a caller that needs the cloud it is written
                        // in chunks rather than copied whole.
                        if (cloud_out) {
                          *cloud_out = fusion.Cloud();
                          WritePly(ply, *cloud_out);
                        } else {
                          WritePlyChunked(ply, fusion.num_points(),
                                          [&](size_t begin, size_t end) {
                                            return fusion.Cloud(begin, end);
                                          });
                        }
                        r.points = fusion.num_points();
                        st = fusion.stats();
                      });
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
