// Copyright wild_mvs authors. `wild_mvs reconstruct DATASET OUT`: depth
// maps of every (selected) view, then fusion and meshing; resumable.
#include <chrono>
#include <filesystem>
#include <iomanip>
#include <iostream>
#include <string>

#include "wild_mvs/cli/args.h"
#include "wild_mvs/cli/commands.h"
#include "wild_mvs/cli/progress.h"
#include "wild_mvs/cli/reconstruct_config.h"
#include "wild_mvs/cli/run_steps.h"
#include "wild_mvs/cli/scene_setup.h"
#include "wild_mvs/io/atomic_file.h"
#include "wild_mvs/io/colmap.h"

namespace wild_mvs {
namespace cli {
namespace {

CommandSpec ReconstructSpec() {
  CommandSpec s;
  s.name = "reconstruct";
  s.usage = "DATASET OUT [options]";
  s.summary =
      "Computes a depth, normal and confidence map per view (Goesele et al.\n"
      "2007: global and local view selection, MPGC, region growing), fuses\n"
      "them into OUT/fused.ply and meshes it into OUT/mesh.ply. Per view with\n"
      "image stem S: OUT/depth/S.pfm, OUT/normal/S.pfm, OUT/confidence/S.pfm,\n"
      "OUT/cameras/S.txt, OUT/preview/S_*.png, OUT/log/S.json.\n"
      "Resumable: views whose files exist are skipped (use --force to redo).\n"
      "DATASET is a folder in any supported format (COLMAP, Bundler,\n"
      "Middlebury, Strecha); without sparse points they are computed first.";
  s.positionals = {"DATASET", "OUT"};
  s.min_positionals = 0;  // checked after --dump-config
  s.max_positionals = 2;
  s.flags = {
      {"config", "FILE.yaml", "read options from a YAML file (keys as below)",
       ""},
      {"preset", "NAME",
       "start from a preset: default, or paper (Goesele et al. 2007 as "
       "published: no acceptance threshold, texture guard, step control or "
       "consistency filter)",
       ""},
      {"dump-config", "", "print the effective options as YAML and exit", ""},
      {"views", "LIST",
       "only these reference views (comma-separated names or stems)", ""},
      {"force", "", "recompute views and outputs that already exist", ""},
      {"threads", "N", "worker threads, 0 = one per core (run.threads)",
       "run.threads"},
      {"max-image-size", "N",
       "downscale images whose longest side exceeds N pixels "
       "(image.max_image_size)",
       "image.max_image_size"},
      {"stages", "LIST", "subset of depth,fuse,mesh (run.stages)",
       "run.stages"},
      {"mask-dir", "DIR",
       "per-image masks DIR/<image name or stem>.png, 0 = ignore pixel", ""},
      {"model", "DIR", "sparse model folder (overrides detection)", ""},
      {"images", "DIR", "image folder (overrides detection)", ""},
      {"format", "NAME",
       "dataset format: auto|colmap|bundler|middlebury|strecha", ""},
  };
  s.epilog =
      "Option precedence: defaults < --preset < --config file < "
      "command-line flags.\n"
      "Example: wild_mvs reconstruct data/templeSparseRing /tmp/temple "
      "--max-image-size 320";
  return s;
}

}  // namespace

int RunReconstruct(const CommandArgs& argv) {
  ReconstructConfig config;
  OptionSet options;
  RegisterOptions(&config, &options);
  const CommandSpec spec = ReconstructSpec();
  Args args(spec, argv, &options);
  if (args.help()) {
    PrintCommandHelp(spec, &options, std::cout);
    return 0;
  }
  if (args.Has("preset")) {
    const std::string preset = args.Get("preset");
    if (preset == "paper") {
      config.mvs = PaperMvsOptions();
    } else if (preset != "default") {
      throw UsageError(Msg("option --preset: unknown preset '", preset,
                           "' (default, paper)"));
    }
  }
  if (args.Has("config")) options.LoadYamlFile(args.Get("config"));
  args.ApplyCoreAssignments(&options);
  config.Check();
  if (args.Has("dump-config")) {
    std::cout << options.ToYaml(true);
    return 0;
  }
  if (args.positionals().size() < 2) {
    throw UsageError(Msg("missing argument ",
                         args.positionals().empty() ? "DATASET OUT" : "OUT",
                         " (usage: wild_mvs reconstruct ", spec.usage, ")"));
  }
  const auto t0 = std::chrono::steady_clock::now();
  const double cpu0 = CpuSeconds();
  const std::string out = args.positional(1);
  const bool force = args.Has("force");
  std::ostream& log = std::cerr;

  // Output folder first: an unwritable OUT fails before any long work.
  namespace fs = std::filesystem;
  std::error_code ec;
  fs::create_directories(out, ec);
  Require(!ec && fs::is_directory(out), out,
          ": cannot create the output folder: ",
          ec ? ec.message() : std::string("not a folder"));

  DatasetRecord record;
  record.path = fs::absolute(args.positional(0)).lexically_normal().string();
  record.model = args.Get("model");
  record.images = args.Get("images");
  record.format = args.Get("format", "auto");
  record.mask_dir = args.Get("mask-dir");
  // Compare with the options of an earlier run in OUT (run.yaml): depth
  // maps computed with other depth options are kept (resuming is the point)
  // but the user is told; the cloud and the mesh are redone when their
  // options (or their inputs) changed.
  bool fusion_options_changed = true, mesh_options_changed = true;
  if (fs::exists(RunRecordPath(out)) && !force) {
    ReconstructConfig before;
    DatasetRecord before_record;
    OptionSet previous;
    RegisterOptions(&before, &previous);
    RegisterDatasetRecord(&before_record, &previous);
    try {
      previous.LoadYamlFile(RunRecordPath(out));
      std::string depth_changes;
      fusion_options_changed = mesh_options_changed = false;
      for (size_t i = 0; i < options.options().size(); ++i) {
        const auto& now = options.options()[i];
        const auto& was = previous.options()[i];
        if (now.Text() == was.Text()) continue;
        if (now.key().rfind("run.", 0) == 0) continue;
        if (now.key().rfind("fusion.", 0) == 0) {
          fusion_options_changed = true;
        } else if (now.key().rfind("meshing.", 0) == 0) {
          mesh_options_changed = true;
        } else {
          depth_changes +=
              Msg("\n    ", now.key(), ": ", was.Text(), " -> ", now.Text());
        }
      }
      if (before_record.path != record.path) {
        log << "warning: " << out << " holds results of another dataset ("
            << before_record.path << "); views with the same names are "
            << "treated as done (use --force or another OUT)\n";
        fusion_options_changed = true;
      }
      if (!depth_changes.empty()) {
        log << "note: " << RunRecordPath(out)
            << ": finished depth maps were computed with other options; they "
               "are kept (use --force to recompute):"
            << depth_changes << "\n";
      }
    } catch (const Error& e) {
      log << "note: ignoring the earlier run record: " << e.what() << "\n";
      fusion_options_changed = mesh_options_changed = true;
    }
  }
  OptionSet record_set;
  ReconstructConfig record_config = config;
  RegisterOptions(&record_config, &record_set);
  RegisterDatasetRecord(&record, &record_set);

  DatasetOptions dopt = MakeDatasetOptions(args.positional(0), args);
  Scene scene = LoadDataset(dopt);
  const int scaled = LimitImageSize(&scene, config.image.max_image_size);
  if (!record.mask_dir.empty()) {
    const int masks = AssignMasks(&scene, record.mask_dir);
    log << "masks: " << masks << " of " << scene.views.size()
        << " views have a mask in " << record.mask_dir << "\n";
  }
  const std::vector<int> views = SelectViews(scene, args.Get("views"));
  log << "dataset: " << scene.views.size() << " views, " << scene.points.size()
      << " sparse points (" << scene.source << ")";
  if (scaled) {
    log << "; " << scaled << " views downscaled to at most "
        << config.image.max_image_size << " px";
  }
  log << "\n";
  // Written before the long work so that `fuse OUT` works on partial runs;
  // this also proves that OUT is writable.
  WriteFileAtomically(RunRecordPath(out), [&](std::ostream& os) {
    os << "# wild_mvs reconstruct: the dataset and options of this folder "
          "(read by 'wild_mvs fuse' and 'wild_mvs mesh')\n"
       << record_set.ToYaml(false);
  });

  ThreadPool pool(config.run.threads);
  ImageCache images(MakeSceneLoader(scene, config.image),
                    config.image.cache_mb);
  DepthStageResult depth;
  bool depth_ran = false;
  if (config.run.HasStage("depth")) {
    int todo = 0;
    for (int v : views) {
      todo += (force || !ViewOutputsComplete(out, scene.views[v].Stem()));
    }
    if (todo > 0 && scene.points.empty()) {
      ComputeSceneTracks(&scene, config, &pool, log);
      WriteColmapText(scene, out + "/sparse");
      log << "sparse: model written to " << out << "/sparse\n";
    }
    log << "depth: " << views.size() << " views, " << todo << " to compute, "
        << pool.size() << " threads\n";
    depth = RunDepthStage(scene, views, images, config, &pool, out, force, log);
    depth_ran = true;
    if (!depth.failures.empty()) {
      std::string list;
      for (const std::string& f : depth.failures) list += "\n  " + f;
      throw Error(Msg(depth.failures.size(), " of ", views.size(),
                      " views failed (the others are saved; fix the input "
                      "and run again to resume):",
                      list));
    }
  }
  const std::string fused = out + "/fused.ply", mesh_path = out + "/mesh.ply";
  PointCloud cloud;
  bool have_cloud = false, fused_now = false;
  FuseResult fuse;
  if (config.run.HasStage("fuse")) {
    if (!force && depth.computed == 0 && !fusion_options_changed &&
        fs::exists(fused)) {
      log << "fuse: " << fused
          << " is up to date, skipped (--force recomputes)\n";
    } else {
      fuse =
          RunFuseStage(scene, &images, config, &pool, out, fused, log, &cloud);
      have_cloud = fused_now = true;
    }
  }
  MeshResult mesh;
  bool meshed = false;
  if (config.run.HasStage("mesh")) {
    if (!force && !fused_now && !mesh_options_changed &&
        fs::exists(mesh_path)) {
      log << "mesh: " << mesh_path
          << " is up to date, skipped (--force recomputes)\n";
    } else {
      if (!have_cloud) {
        Require(fs::exists(fused), fused,
                ": no fused cloud to mesh (run the fuse stage first)");
        cloud = LoadFusedCloud(fused);
      }
      mesh = RunMeshStage(cloud, config, mesh_path, log);
      meshed = true;
    }
  }

  const double secs =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0)
          .count();
  const double cpu = CpuSeconds() - cpu0;
  std::ostringstream sum;
  sum << "summary: " << views.size() << " views";
  if (depth_ran) {
    sum << " (" << depth.computed << " computed, " << depth.skipped
        << " resumed), " << depth.samples << " valid depth samples";
  }
  if (fused_now) sum << ", " << fuse.points << " points";
  if (meshed) sum << ", " << mesh.faces << " faces";
  sum << "; " << std::fixed << std::setprecision(1) << secs << " s, " << cpu
      << " CPU-s, peak RSS " << std::setprecision(0) << PeakRssMb() << " MB";
  std::cout << sum.str() << "\n";
  WriteFileAtomically(out + "/summary.json", [&](std::ostream& os) {
    os << "{\n  \"views\": " << views.size()
       << ",\n  \"views_computed\": " << depth.computed
       << ",\n  \"views_resumed\": " << depth.skipped
       << ",\n  \"valid_samples\": " << depth.samples
       << ",\n  \"fused_points\": " << (fused_now ? fuse.points : 0)
       << ",\n  \"mesh_faces\": " << (meshed ? mesh.faces : 0)
       << ",\n  \"seconds\": " << secs << ",\n  \"cpu_seconds\": " << cpu
       << ",\n  \"threads\": " << pool.size() << "\n}\n";
  });
  return 0;
}

}  // namespace cli
}  // namespace wild_mvs
