// Copyright wild_mvs authors. `wild_mvs fuse OUT` and `wild_mvs mesh OUT` on
// a folder written by `wild_mvs reconstruct`.
#include <filesystem>
#include <iostream>

#include "wild_mvs/cli/commands.h"
#include "wild_mvs/cli/option_command.h"
#include "wild_mvs/cli/run_steps.h"
#include "wild_mvs/cli/scene_setup.h"
#include "wild_mvs/cli/specs.h"
#include "wild_mvs/io/image_files.h"

namespace wild_mvs {
namespace cli {
namespace {

namespace fs = std::filesystem;

}  // namespace

int RunFuse(const CommandArgs& argv) {
  ReconstructConfig config;
  DatasetRecord record;
  OptionCommand command(FuseSpec(), argv, &config);
  if (command.PrintHelpIfAsked(std::cout)) return 0;
  const Args& args = command.args();
  const std::string out = args.positional(0);
  Require(fs::is_directory(out), out, ": not a folder");
  // Options: defaults < OUT/run.yaml < --config < flags.
  const bool has_record = command.ConfigureWithRunRecord(out, &record);
  if (args.Has("dataset")) {
    record = DatasetRecord();
    record.path = args.Get("dataset");
  }
  Require(!record.path.empty(), out,
          ": no run.yaml (not written by 'wild_mvs reconstruct'?); give the "
          "dataset with --dataset DIR");
  DatasetOptions dopt;
  dopt.path = record.path;
  dopt.model_dir = record.model;
  dopt.images_dir = record.images;
  dopt.format = ParseDatasetFormat(record.format,
                                   RunRecordPath(out) + ": dataset.format");
  Scene scene = LoadDataset(dopt);
  LimitImageSize(&scene, config.image.max_image_size);
  if (!record.mask_dir.empty()) AssignMasks(&scene, record.mask_dir);
  std::cerr << "dataset: " << scene.views.size() << " views from "
            << record.path << (has_record ? " (from run.yaml)" : "") << "\n";
  ThreadPool pool(config.run.threads);
  ImageCache images(MakeSceneLoader(scene, config.LoaderOptions()),
                    config.image.cache_mb);
  const std::string ply = args.Get("output", out + "/fused.ply");
  const double cpu0 = CpuSeconds();
  // Maps left in OUT/raw by `reconstruct --shard` runs: the consistency
  // filter first (it needs every neighbour's raw map).
  const FilterStageResult f =
      FilterPendingViews(scene, config.mvs, out, &pool, std::cerr);
  if (f.filtered > 0) {
    std::cout << "filtered " << f.filtered << " depth maps (kept " << f.kept
              << " of " << f.samples << " samples)\n";
  }
  const FuseResult r =
      RunFuseStage(scene, &images, config, &pool, out, ply, std::cerr);
  std::cout << "fused " << r.views << " depth maps into " << r.points
            << " points: " << ply << " (" << r.seconds << " s, "
            << CpuSeconds() - cpu0 << " CPU-s)\n";
  return 0;
}

int RunMesh(const CommandArgs& argv) {
  ReconstructConfig config;
  DatasetRecord record;
  OptionCommand command(MeshSpec(), argv, &config);
  if (command.PrintHelpIfAsked(std::cout)) return 0;
  const Args& args = command.args();
  const std::string out = args.positional(0);
  Require(fs::is_directory(out), out, ": not a folder");
  command.ConfigureWithRunRecord(out, &record);
  const std::string in = args.Get("input", out + "/fused.ply");
  const std::string ply = args.Get("output", out + "/mesh.ply");
  const PointCloud cloud = LoadFusedCloud(in);
  const MeshResult r = RunMeshStage(cloud, config, ply, std::cerr);
  std::cout << "meshed " << cloud.size() << " points into " << r.vertices
            << " vertices, " << r.faces << " faces: " << ply << " ("
            << r.seconds << " s)\n";
  return 0;
}

}  // namespace cli
}  // namespace wild_mvs
