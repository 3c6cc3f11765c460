// Copyright wild_mvs authors. `wild_mvs reconstruct DATASET OUT`: depth
// maps of every (selected) view, then fusion and meshing; resumable.
#include <iostream>
#include <string>

#include "wild_mvs/cli/args.h"
#include "wild_mvs/cli/commands.h"
#include "wild_mvs/cli/reconstruct_config.h"

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
      "Option precedence: defaults < --config file < command-line flags.\n"
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
  throw Error("reconstruct: depth stage not available in this build yet");
}

}  // namespace cli
}  // namespace wild_mvs
