// Copyright wild_mvs authors. `wild_mvs reconstruct DATASET OUT`: depth
// maps of every (selected) view, then fusion and meshing; resumable.
#include <chrono>
#include <filesystem>
#include <iomanip>
#include <iostream>
#include <sstream>
#include <string>
#include <vector>

#include "wild_mvs/cli/args.h"
#include "wild_mvs/cli/colmap_export.h"
#include "wild_mvs/cli/commands.h"
#include "wild_mvs/cli/option_command.h"
#include "wild_mvs/cli/progress.h"
#include "wild_mvs/cli/reconstruct_config.h"
#include "wild_mvs/cli/run_steps.h"
#include "wild_mvs/cli/scene_setup.h"
#include "wild_mvs/core/mpgc_kernels.h"
#include "wild_mvs/io/atomic_file.h"
#include "wild_mvs/io/colmap.h"
#include "wild_mvs/io/colmap_dense.h"
#include "wild_mvs/io/image_files.h"

namespace wild_mvs {
namespace cli {
namespace {

namespace fs = std::filesystem;

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
       "published: plain windows, no explain test, photometric offset or "
       "consistency filter)",
       ""},
      {"dump-config", "", "print the effective options as YAML and exit", ""},
      {"views", "LIST",
       "only these reference views (comma-separated names or stems)", ""},
      {"shard", "K/N",
       "only share K of N of the (selected) views, for N concurrent "
       "processes on one OUT (views in dataset order, every N-th from the "
       "K-th); depth maps only, then run 'wild_mvs fuse OUT' once all "
       "have finished (docs/SCALE.md)",
       ""},
      {"force", "", "recompute views and outputs that already exist", ""},
      {"threads", "N", "worker threads, 0 = one per core (run.threads)",
       "run.threads"},
      {"max-image-size", "N",
       "downscale images whose longest side exceeds N pixels "
       "(image.max_image_size)",
       "image.max_image_size"},
      {"stages", "LIST",
       "subset of sparse,depth,fuse,mesh (run.stages); 'sparse' alone "
       "computes only the sparse tracks (before --shard runs)",
       "run.stages"},
      {"mask-dir", "DIR",
       "per-image masks DIR/<image name or stem>.png, 0 = ignore pixel", ""},
      {"model", "DIR", "sparse model folder (overrides detection)", ""},
      {"images", "DIR", "image folder (overrides detection)", ""},
      {"format", "NAME",
       "dataset format: auto|colmap|bundler|middlebury|strecha", ""},
      {"colmap-workspace", "DIR",
       "also write the maps and the cloud into this COLMAP dense workspace "
       "as colmap patch_match_stereo and stereo_fusion would "
       "(stereo/depth_maps, stereo/normal_maps, stereo/*.cfg, fused.ply, "
       "fused.ply.vis); default: DATASET when it is one (images/, sparse/, "
       "stereo/, as colmap image_undistorter writes); none = never",
       ""},
  };
  s.epilog =
      "Option precedence: defaults < --preset < --config file < "
      "command-line flags.\n"
      "Example: wild_mvs reconstruct data/templeSparseRing /tmp/temple "
      "--max-image-size 320\n"
      "Sharded (docs/SCALE.md): wild_mvs reconstruct DATA OUT --stages "
      "sparse (only for datasets without sparse points); then\n"
      "  wild_mvs reconstruct DATA OUT --shard K/N  for K = 1..N, in any "
      "order or concurrently; then wild_mvs fuse OUT; wild_mvs mesh OUT";
  return s;
}

// Applies --preset NAME to *config (before --config and the flags).
void ApplyPreset(const Args& args, ReconstructConfig* config) {
  if (!args.Has("preset")) return;
  const std::string preset = args.Get("preset");
  if (preset == "paper") {
    config->mvs = PaperMvsOptions();
  } else if (preset != "default") {
    throw UsageError(
        Msg("option --preset: unknown preset '", preset, "' (default, paper)"));
  }
}

// Output folder first: an unwritable OUT fails before any long work.
void CreateOutputFolder(const std::string& out) {
  std::error_code ec;
  fs::create_directories(out, ec);
  Require(!ec && fs::is_directory(out), out,
          ": cannot create the output folder: ",
          ec ? ec.message() : std::string("not a folder"));
}

// The dataset of this run as recorded in OUT/run.yaml.
DatasetRecord MakeDatasetRecord(const Args& args) {
  DatasetRecord record;
  record.path = fs::absolute(args.positional(0)).lexically_normal().string();
  record.model = args.Get("model");
  record.images = args.Get("images");
  record.format = args.Get("format", "auto");
  record.mask_dir = args.Get("mask-dir");
  return record;
}

// Which results of an earlier run in OUT are out of date.
struct EarlierRun {
  bool fusion_options_changed = true, mesh_options_changed = true;
};

// Compares with the options of an earlier run in OUT (run.yaml): depth maps
// computed with other depth options are kept (resuming is the point) but
// the user is told; the cloud and the mesh are redone when their options
// (or their inputs) changed.
EarlierRun CompareWithEarlierRun(const std::string& out, bool force,
                                 const OptionSet& options,
                                 const DatasetRecord& record,
                                 std::ostream& log) {
  EarlierRun r;
  if (!fs::exists(RunRecordPath(out)) || force) return r;
  ReconstructConfig before;
  DatasetRecord before_record;
  OptionSet previous;
  RegisterOptions(&before, &previous);
  RegisterDatasetRecord(&before_record, &previous);
  try {
    previous.LoadYamlFile(RunRecordPath(out));
    std::string depth_changes;
    r.fusion_options_changed = r.mesh_options_changed = false;
    for (size_t i = 0; i < options.options().size(); ++i) {
      const auto& now = options.options()[i];
      const auto& was = previous.options()[i];
      if (now.Text() == was.Text()) continue;
      if (now.key().rfind("run.", 0) == 0) continue;
      if (now.key().rfind("fusion.", 0) == 0) {
        r.fusion_options_changed = true;
      } else if (now.key().rfind("meshing.", 0) == 0) {
        r.mesh_options_changed = true;
      } else {
        depth_changes +=
            Msg("\n    ", now.key(), ": ", was.Text(), " -> ", now.Text());
      }
    }
    if (before_record.path != record.path) {
      log << "warning: " << out << " holds results of another dataset ("
          << before_record.path << "); views with the same names are "
          << "treated as done (use --force or another OUT)\n";
      r.fusion_options_changed = true;
    }
    if (!depth_changes.empty()) {
      log << "note: " << RunRecordPath(out)
          << ": finished depth maps were computed with other options; they "
             "are kept (use --force to recompute):"
          << depth_changes << "\n";
    }
  } catch (const Error& e) {
    log << "note: ignoring the earlier run record: " << e.what() << "\n";
    r.fusion_options_changed = r.mesh_options_changed = true;
  }
  return r;
}

// The dataset loaded, downscaled and masked; `views` the selected reference
// views.
Scene SetUpScene(const Args& args, const ReconstructConfig& config,
                 const DatasetRecord& record, std::vector<int>* views,
                 std::ostream& log) {
  DatasetOptions dopt = MakeDatasetOptions(args.positional(0), args);
  Scene scene = LoadDataset(dopt);
  const int scaled = LimitImageSize(&scene, config.image.max_image_size);
  if (!record.mask_dir.empty()) {
    const int masks = AssignMasks(&scene, record.mask_dir);
    log << "masks: " << masks << " of " << scene.views.size()
        << " views have a mask in " << record.mask_dir << "\n";
  }
  *views = SelectViews(scene, args.Get("views"));
  log << "dataset: " << scene.views.size() << " views, " << scene.points.size()
      << " sparse points (" << scene.source << ")";
  if (scaled) {
    log << "; " << scaled << " views downscaled to at most "
        << config.image.max_image_size << " px";
  }
  log << "\n";
  return scene;
}

// OUT/run.yaml: the dataset and options of this folder.
void WriteRunRecord(const std::string& out, const OptionSet& record_set) {
  WriteFileAtomically(RunRecordPath(out), [&](std::ostream& os) {
    os << "# wild_mvs reconstruct: the dataset and options of this folder "
          "(read by 'wild_mvs fuse' and 'wild_mvs mesh')\n"
       << record_set.ToYaml(false);
  });
}

// OUT/run.yaml for a --shard process: written when missing (with run.* at
// their defaults, so that concurrent shards write the same bytes), else
// checked: every shard of one OUT must use the same dataset and options
// (run.* aside), which `wild_mvs fuse` then reads.
void WriteOrCheckShardRunRecord(const std::string& out, const Args& args,
                                const ReconstructConfig& config,
                                const DatasetRecord& record) {
  ReconstructConfig normalized = config;
  normalized.run = RunOptions();
  DatasetRecord record_copy = record;
  OptionSet now;
  RegisterOptions(&normalized, &now);
  RegisterDatasetRecord(&record_copy, &now);
  const std::string path = RunRecordPath(out);
  if (!fs::exists(path) || args.Has("force")) {
    WriteRunRecord(out, now);
    return;
  }
  ReconstructConfig before;
  DatasetRecord before_record;
  OptionSet previous;
  RegisterOptions(&before, &previous);
  RegisterDatasetRecord(&before_record, &previous);
  previous.LoadYamlFile(path);
  for (size_t i = 0; i < now.options().size(); ++i) {
    const auto& a = now.options()[i];
    const auto& b = previous.options()[i];
    if (a.key().rfind("run.", 0) == 0 || a.Text() == b.Text()) continue;
    throw Error(Msg(path, ": ", a.key(), " is ", b.Text(), " there but ",
                    a.Text(),
                    " in this shard: every shard of one OUT must run on the "
                    "same dataset with the same options (use another OUT, or "
                    "--force to overwrite the record)"));
  }
}

// What the stages did.
struct StageResults {
  DepthStageResult depth;
  bool depth_ran = false;
  SparseSummary sparse;
  bool sparse_ran = false;
  FuseResult fuse;
  bool fused_now = false;
  MeshResult mesh;
  bool meshed = false;
};

// The sparse tracks of a dataset without sparse points (scene->points
// empty): those of an earlier run on OUT when they match
// (OUT/sparse/tracks.txt), else computed and saved there; a shard never
// computes them (every shard would, at the cost of the whole tracker) and
// asks for a `--stages sparse` run first.
void SparseTracks(Scene* scene, const ReconstructConfig& config,
                  ThreadPool* pool, const std::string& out,
                  const std::vector<std::string>& fingerprint, bool force,
                  bool shard, const std::string& dataset, StageResults* r,
                  std::ostream& log) {
  if (!scene->points.empty()) return;
  // --force recomputes them, except in a shard (which never computes them).
  if ((!force || shard) && LoadSceneTracks(scene, out, fingerprint, log)) {
    return;
  }
  if (shard) {
    throw Error(Msg(
        dataset, ": the dataset has no sparse points and ",
        SparseTracksPath(out),
        " holds none for these views and options; compute them once before "
        "starting the shards: wild_mvs reconstruct ",
        dataset, " ", out,
        " --stages sparse (with the shards' options), then run the shards"));
  }
  r->sparse =
      ComputeAndSaveSceneTracks(scene, config, pool, out, fingerprint, log);
  r->sparse_ran = true;
}

// The depth stage (sparse tracks first when the dataset has none and some
// view is to be computed). Throws when a view failed. A shard (`shard`)
// leaves its maps in OUT/raw when the consistency filter is on.
void DepthStage(Scene* scene, const std::vector<int>& views, ImageCache& images,
                const ReconstructConfig& config, ThreadPool* pool,
                const std::string& out, bool force, bool shard,
                const std::vector<std::string>& fingerprint,
                const std::string& dataset, StageResults* r,
                std::ostream& log) {
  const bool raw_counts = shard && config.mvs.ablation.consistency;
  int todo = 0;
  for (int v : views) {
    const std::string stem = scene->views[v].Stem();
    todo +=
        (force || (!ViewOutputsComplete(out, stem) &&
                   !(raw_counts && ViewOutputsComplete(out + "/raw", stem))));
  }
  if (todo > 0) {
    SparseTracks(scene, config, pool, out, fingerprint, force, shard, dataset,
                 r, log);
  }
  log << "depth: " << views.size() << " views, " << todo << " to compute, "
      << pool->size() << " threads, SIMD " << mpgc_kernels::KernelTarget()
      << "\n";
  r->depth = RunDepthStage(*scene, views, images, config, pool, out, force, log,
                           !shard);
  r->depth_ran = true;
  if (!r->depth.failures.empty()) {
    std::string list;
    for (const std::string& f : r->depth.failures) list += "\n  " + f;
    throw Error(Msg(r->depth.failures.size(), " of ", views.size(),
                    " views failed (the others are saved; fix the input "
                    "and run again to resume):",
                    list));
  }
}

// The fuse and mesh stages, each skipped when its output is up to date.
void FuseAndMeshStages(const Scene& scene, ImageCache* images,
                       const ReconstructConfig& config, ThreadPool* pool,
                       const std::string& out, bool force,
                       const EarlierRun& earlier, StageResults* r,
                       std::ostream& log) {
  const std::string fused = out + "/fused.ply", mesh_path = out + "/mesh.ply";
  PointCloud cloud;
  bool have_cloud = false;
  if (config.run.HasStage("fuse")) {
    // Maps that --shard runs left in OUT/raw are filtered first.
    const FilterStageResult pending =
        FilterPendingViews(scene, config.mvs, out, pool, log);
    if (!force && r->depth.computed == 0 && pending.filtered == 0 &&
        !earlier.fusion_options_changed && fs::exists(fused)) {
      log << "fuse: " << fused
          << " is up to date, skipped (--force recomputes)\n";
    } else {
      // The mesh stage takes the cloud from memory; without it the cloud
      // is only written (in chunks, no copy).
      r->fuse = RunFuseStage(scene, images, config, pool, out, fused, log,
                             config.run.HasStage("mesh") ? &cloud : nullptr);
      have_cloud = r->fused_now = true;
    }
  }
  if (config.run.HasStage("mesh")) {
    if (!force && !r->fused_now && !earlier.mesh_options_changed &&
        fs::exists(mesh_path)) {
      log << "mesh: " << mesh_path
          << " is up to date, skipped (--force recomputes)\n";
    } else {
      if (!have_cloud) {
        Require(fs::exists(fused), fused,
                ": no fused cloud to mesh (run the fuse stage first)");
        cloud = LoadFusedCloud(fused);
      }
      r->mesh = RunMeshStage(cloud, config, mesh_path, log);
      r->meshed = true;
    }
  }
}

// The COLMAP dense workspace to write into: --colmap-workspace DIR, or the
// dataset when it is one; "" = none.
std::string ColmapWorkspace(const Args& args) {
  if (args.Has("colmap-workspace")) {
    const std::string dir = args.Get("colmap-workspace");
    if (dir == "none") return "";
    if (!IsColmapDenseWorkspace(dir)) {
      throw UsageError(Msg("--colmap-workspace ", dir,
                           ": not a COLMAP dense workspace (expected "
                           "images/, stereo/ and a model in sparse/, as "
                           "colmap image_undistorter writes)"));
    }
    return dir;
  }
  return IsColmapDenseWorkspace(args.positional(0)) ? args.positional(0) : "";
}

// The summary line on stdout and OUT/summary.json.
void WriteSummary(const std::string& path, size_t views, const StageResults& r,
                  double secs, double cpu, int threads) {
  std::ostringstream sum;
  sum << "summary: " << views << " views";
  if (r.sparse_ran) sum << ", " << r.sparse.points << " sparse points";
  if (r.depth_ran) {
    sum << " (" << r.depth.computed << " computed, " << r.depth.skipped
        << " resumed), " << r.depth.samples << " valid depth samples";
    if (r.depth.unfiltered > 0) {
      sum << " (before the consistency filter of 'wild_mvs fuse', "
          << r.depth.unfiltered << " views)";
    }
  }
  if (r.fused_now) sum << ", " << r.fuse.points << " points";
  if (r.meshed) sum << ", " << r.mesh.faces << " faces";
  sum << "; " << std::fixed << std::setprecision(1) << secs << " s, " << cpu
      << " CPU-s, peak RSS " << std::setprecision(0) << PeakRssMb() << " MB";
  std::cout << sum.str() << "\n";
  WriteFileAtomically(path, [&](std::ostream& os) {
    os << "{\n  \"views\": " << views
       << ",\n  \"views_computed\": " << r.depth.computed
       << ",\n  \"views_unfiltered\": " << r.depth.unfiltered
       << ",\n  \"views_resumed\": " << r.depth.skipped
       << ",\n  \"valid_samples\": " << r.depth.samples
       << ",\n  \"fused_points\": " << (r.fused_now ? r.fuse.points : 0)
       << ",\n  \"mesh_faces\": " << (r.meshed ? r.mesh.faces : 0)
       << ",\n  \"seconds\": " << secs << ",\n  \"cpu_seconds\": " << cpu
       << ",\n  \"threads\": " << threads << "\n}\n";
  });
}

}  // namespace

int RunReconstruct(const CommandArgs& argv) {
  // Options: defaults < --preset < --config < flags.
  ReconstructConfig config;
  OptionCommand command(ReconstructSpec(), argv, &config);
  if (command.PrintHelpIfAsked(std::cout)) return 0;
  const Args& args = command.args();
  ApplyPreset(args, &config);
  command.Configure();
  if (args.Has("dump-config")) {
    std::cout << command.options().ToYaml(true);
    return 0;
  }
  if (args.positionals().size() < 2) {
    throw UsageError(Msg(
        "missing argument ", args.positionals().empty() ? "DATASET OUT" : "OUT",
        " (usage: wild_mvs reconstruct ", command.spec().usage, ")"));
  }
  const auto t0 = std::chrono::steady_clock::now();
  const double cpu0 = CpuSeconds();
  const std::string dataset = args.positional(0), out = args.positional(1);
  const bool force = args.Has("force");
  const bool sharded = args.Has("shard");
  const Shard shard = sharded ? ParseShard(args.Get("shard")) : Shard();
  if (sharded && !config.run.HasStage("depth")) {
    throw UsageError(Msg("--shard ", args.Get("shard"), " with --stages ",
                         config.run.stages,
                         ": a shard computes depth maps (run the sparse stage "
                         "without --shard, fuse and mesh with 'wild_mvs fuse' "
                         "and 'wild_mvs mesh')"));
  }
  std::ostream& log = std::cerr;

  // Output folder and run record.
  const std::string workspace = ColmapWorkspace(args);
  CreateOutputFolder(out);
  DatasetRecord record = MakeDatasetRecord(args);
  const EarlierRun earlier =
      sharded
          ? EarlierRun()
          : CompareWithEarlierRun(out, force, command.options(), record, log);
  OptionSet record_set;
  ReconstructConfig record_config = config;
  RegisterOptions(&record_config, &record_set);
  RegisterDatasetRecord(&record, &record_set);

  // Scene.
  std::vector<int> views;
  Scene scene = SetUpScene(args, config, record, &views, log);
  const size_t selected = views.size();
  if (sharded) {
    views = ShardViews(views, shard);
    log << "shard " << shard.index << "/" << shard.count << ": " << views.size()
        << " of " << selected << " views\n";
  }
  // Written before the long work so that `fuse OUT` works on partial runs;
  // this also proves that OUT is writable. Shards share it: written once.
  // A sparse-only run leaves it to the depth runs (the tracks file records
  // the options it depends on), so its other options need not match theirs.
  if (sharded) {
    WriteOrCheckShardRunRecord(out, args, config, record);
  } else if (config.run.HasStage("depth") || config.run.HasStage("fuse") ||
             config.run.HasStage("mesh")) {
    WriteRunRecord(out, record_set);
  }

  // Stages.
  ThreadPool pool(config.run.threads);
  ImageCache images(MakeSceneLoader(scene, config.LoaderOptions()),
                    config.image.cache_mb);
  StageResults results;
  const std::vector<std::string> fingerprint =
      TracksFingerprint(command.options(), record.mask_dir);
  if (config.run.HasStage("sparse") && !config.run.HasStage("depth")) {
    if (!scene.points.empty()) {
      log << "sparse: the dataset has " << scene.points.size()
          << " sparse points; nothing to compute\n";
    }
    SparseTracks(&scene, config, &pool, out, fingerprint, force, false, dataset,
                 &results, log);
  }
  if (config.run.HasStage("depth")) {
    DepthStage(&scene, views, images, config, &pool, out, force, sharded,
               fingerprint, dataset, &results, log);
  }
  if (sharded) {
    if (config.run.HasStage("fuse") || config.run.HasStage("mesh")) {
      log << "fuse, mesh: not run by a shard (they need every shard's "
             "maps)\n";
    }
  } else {
    FuseAndMeshStages(scene, &images, config, &pool, out, force, earlier,
                      &results, log);
    if (!workspace.empty()) {
      ExportToColmapWorkspace(scene, views, out, workspace,
                              config.fusion.depth_tolerance, log);
    }
  }

  const double secs =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0)
          .count();
  const std::string summary = sharded ? Msg(out, "/summary_shard_", shard.index,
                                            "_of_", shard.count, ".json")
                                      : out + "/summary.json";
  WriteSummary(summary, views.size(), results, secs, CpuSeconds() - cpu0,
               pool.size());
  if (sharded) {
    std::cout << "shard " << shard.index << "/" << shard.count
              << " finished. When all " << shard.count
              << " shards have finished, run: wild_mvs fuse " << out
              << " && wild_mvs mesh " << out << "\n";
  }
  return 0;
}

}  // namespace cli
}  // namespace wild_mvs
