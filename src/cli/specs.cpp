// Copyright wild_mvs authors.
#include "wild_mvs/cli/specs.h"

namespace wild_mvs {
namespace cli {

std::vector<FlagSpec> DatasetFlags() {
  return {
      {"model", "DIR", "sparse model folder (overrides detection)", ""},
      {"images", "DIR", "image folder (overrides detection)", ""},
      {"format", "NAME",
       "dataset format: auto|colmap|bundler|middlebury|strecha (default auto)",
       ""},
  };
}

CommandSpec InfoSpec() {
  CommandSpec s;
  s.name = "info";
  s.usage = "DATASET [options]";
  s.summary =
      "Loads a dataset (format detected: COLMAP text/binary, Bundler,\n"
      "Middlebury *_par.txt, Strecha .camera) and prints its views and\n"
      "resolutions, sparse points and track statistics, observations per\n"
      "view, and sanity checks of baselines and overlap (twin views taken\n"
      "from the same position, views without shared points).";
  s.positionals = {"DATASET"};
  s.min_positionals = s.max_positionals = 1;
  s.flags = DatasetFlags();
  s.flags.push_back(
      {"check-images", "", "also open every image and check its size", ""});
  return s;
}

CommandSpec SparseSpec() {
  CommandSpec s;
  s.name = "sparse";
  s.usage = "DATASET OUT_MODEL_DIR [options]";
  s.summary =
      "Computes sparse tracks from the dataset's known camera poses (SIFT,\n"
      "epipolar-constrained matching, multi-view tracks, triangulation and\n"
      "filtering) and writes a COLMAP text model (cameras.txt, images.txt,\n"
      "points3D.txt) to OUT_MODEL_DIR. Existing points of the dataset are\n"
      "ignored and replaced.";
  s.positionals = {"DATASET", "OUT_MODEL_DIR"};
  s.min_positionals = s.max_positionals = 2;
  s.flags = DatasetFlags();
  s.flags.push_back({"config", "FILE.yaml",
                     "read options from a YAML file (tracker.* keys)", ""});
  s.flags.push_back(
      {"threads", "N", "worker threads, 0 = one per core", "run.threads"});
  s.flags.push_back({"max-image-size", "N",
                     "downscale images whose longest side exceeds N pixels",
                     "image.max_image_size"});
  return s;
}

CommandSpec FuseSpec() {
  CommandSpec s;
  s.name = "fuse";
  s.usage = "OUT [options]";
  s.summary =
      "Fuses the depth maps of a folder written by 'wild_mvs reconstruct'\n"
      "into OUT/fused.ply (binary PLY: position, normal, colour, confidence,\n"
      "support). Depth maps are streamed from disk (bounded memory). The\n"
      "dataset (for colours) is the one recorded in OUT/run.yaml unless\n"
      "--dataset is given. Views matched by 'reconstruct --shard K/N' runs\n"
      "(OUT/raw) are first given the geometric-consistency filter\n"
      "(consistency.*), which writes their final maps to OUT.";
  s.positionals = {"OUT"};
  s.min_positionals = s.max_positionals = 1;
  s.flags = {
      {"config", "FILE.yaml", "read options from a YAML file (fusion.* keys)",
       ""},
      {"dataset", "DIR", "dataset folder (default: from OUT/run.yaml)", ""},
      {"threads", "N", "worker threads, 0 = one per core", "run.threads"},
      {"output", "FILE.ply", "write here instead of OUT/fused.ply", ""},
  };
  return s;
}

CommandSpec MeshSpec() {
  CommandSpec s;
  s.name = "mesh";
  s.usage = "OUT [options]";
  s.summary =
      "Screened Poisson surface reconstruction of OUT/fused.ply (from\n"
      "'wild_mvs reconstruct' or 'wild_mvs fuse'), trimmed where the data\n"
      "does not support it, written to OUT/mesh.ply (binary PLY).";
  s.positionals = {"OUT"};
  s.min_positionals = s.max_positionals = 1;
  s.flags = {
      {"config", "FILE.yaml", "read options from a YAML file (mesh.* keys)",
       ""},
      {"threads", "N", "worker threads, 0 = one per core", "run.threads"},
      {"input", "FILE.ply", "mesh this cloud instead of OUT/fused.ply", ""},
      {"output", "FILE.ply", "write here instead of OUT/mesh.ply", ""},
  };
  return s;
}

CommandSpec EvalSpec() {
  CommandSpec s;
  s.name = "eval";
  s.usage =
      "depth --gt-dir DIR --est OUT [options]\n"
      "       wild_mvs eval cloud EST.ply GT.ply [--tau LIST]\n"
      "       wild_mvs eval make-gt-cloud --gt-dir DIR --dataset DATASET "
      "OUT.ply";
  s.summary =
      "depth: scores the depth maps of a reconstruct folder against\n"
      "  ground-truth depth maps (PFM or EXR, one per view, named by the\n"
      "  image stem): completeness over ground-truth-valid pixels, fraction\n"
      "  within relative and absolute thresholds, median errors.\n"
      "  --dataset applies a dataset's ground-truth adapter (fountain-P11's\n"
      "  principal-point mapping).\n"
      "cloud: scores a point cloud (or a mesh's vertices) against a\n"
      "  ground-truth cloud: accuracy (distance within which 90% of the\n"
      "  points lie), completeness, precision, recall and F-score per tau\n"
      "  (Middlebury / ETH3D definitions).\n"
      "make-gt-cloud: builds a ground-truth cloud from ground-truth depth\n"
      "  maps and the dataset's cameras.\n"
      "Ground truth is looked up as GT_DIR/<stem>.pfm|.exr (rendered with the\n"
      "view's camera); a folder named gt_depth_blender_exr (fountain-P11) "
      "gets\n"
      "the principal-point adapter. Without --gt-dir, DATASET/gt_depth/ and\n"
      "DATASET/gt_depth_blender_exr/ are used.";
  s.positionals = {"MODE", "ARGS"};
  s.min_positionals = 1;
  s.max_positionals = 3;
  s.flags = {
      {"gt-dir", "DIR", "ground-truth depth maps (depth mode)", ""},
      {"est", "OUT", "reconstruct output folder to score (depth mode)", ""},
      {"dataset", "DIR", "dataset folder (cameras, GT adapter)", ""},
      {"tau", "LIST",
       "distance thresholds in scene units (cloud mode; default "
       "0.01,0.02,0.05)",
       ""},
      {"cloud", "FILE.ply",
       "depth mode: also report the fraction of the depth samples within "
       "the first relative threshold that FILE (e.g. fused.ply) represents "
       "(a point within 2 pixel footprints)",
       ""},
      {"rel-thresholds", "LIST",
       "relative depth-error thresholds (depth mode; default 0.01,0.02,0.05)",
       ""},
      {"abs-thresholds", "LIST",
       "absolute depth-error thresholds in scene units (depth mode; default "
       "0.01,0.02)",
       ""},
      {"stride", "N", "use every N-th pixel (make-gt-cloud; default 2)", ""},
      {"voxel", "SIZE",
       "thin clouds to one point per voxel of this size (cloud, "
       "make-gt-cloud; default off)",
       ""},
      {"json", "FILE", "also write the scores as JSON", ""},
  };
  return s;
}

CommandSpec RenderSpec() {
  CommandSpec s;
  s.name = "render";
  s.usage = "IN.ply OUT.png [options]";
  s.summary =
      "Draws a point cloud (fused.ply) or a mesh (mesh.ply) offscreen and\n"
      "writes a PNG (atomically): z-buffered square splats sized by the\n"
      "sample spacing (in their colour; grey Lambert-shaded without colour)\n"
      "or flat-shaded triangles with Lambert lighting from the viewer's\n"
      "upper left. The view is a camera file of a reconstruct folder\n"
      "(--camera OUT/cameras/S.txt, optionally refitted with --fit) or, by\n"
      "default, fitted automatically: looking at the model's widest side,\n"
      "up from the reconstruct folder's cameras (IN.ply's folder/cameras/)\n"
      "or --up.";
  s.positionals = {"IN.ply", "OUT.png"};
  s.min_positionals = s.max_positionals = 2;
  s.flags = {
      {"camera", "FILE",
       "view from this camera file (OUT/cameras/S.txt), scaled to --width", ""},
      {"fit", "",
       "with --camera: keep its orientation, place the camera so that the "
       "model fills the image",
       ""},
      {"width", "N", "image width in pixels (default 800)", ""},
      {"height", "N",
       "image height (default: the camera's aspect, or 3/4 of the width)", ""},
      {"hfov", "DEG", "horizontal field of view of fitted views (default 40)",
       ""},
      {"up", "X,Y,Z", "world up direction of the automatic view", ""},
      {"roll", "DEG",
       "turn the view counter-clockwise about its axis (90: sideways "
       "photos upright; the picture's sides swap)",
       ""},
      {"points", "", "draw a mesh's vertices as points", ""},
      {"point-size", "S",
       "splat side in world units (default: 1.5 x median spacing)", ""},
      {"max-splat", "PX", "largest splat side in pixels (default 12)", ""},
      {"shade", "", "Lambert-shade coloured points too", ""},
      {"mesh-colors", "", "colour mesh faces by their vertex colours", ""},
      {"supersample", "N", "anti-aliasing factor (default 2)", ""},
  };
  return s;
}

}  // namespace cli
}  // namespace wild_mvs
