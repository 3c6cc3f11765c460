// Copyright wild_mvs authors.
#include "wild_mvs/cli/reconstruct_config.h"

#include <limits>

#include "wild_mvs/cli/args.h"
#include "wild_mvs/core/error.h"

namespace wild_mvs {
namespace cli {
namespace {
constexpr int kIntMax = std::numeric_limits<int>::max();
constexpr double kInf = std::numeric_limits<double>::infinity();
const char* const kStages[] = {"depth", "fuse", "mesh"};
}  // namespace

void RunOptions::Check() const {
  Require(threads >= 0, "run.threads = ", threads,
          " must be >= 0 (0 = one per core)");
  const auto list = SplitList(stages);
  Require(!list.empty(),
          "run.stages is empty: give a subset of depth,fuse,mesh");
  for (const std::string& s : list) {
    bool known = false;
    for (const char* k : kStages) known |= (s == k);
    Require(known, "run.stages: unknown stage '", s,
            "' (stages are depth, fuse, mesh)");
  }
}

bool RunOptions::HasStage(const std::string& stage) const {
  for (const std::string& s : SplitList(stages)) {
    if (s == stage) return true;
  }
  return false;
}

void ReconstructConfig::Check() const {
  run.Check();
  image.Check();
  tracker.Check();
  mvs.Check();
  fusion.Check();
  mesh.Check();
}

void RegisterOptions(ReconstructConfig* c, OptionSet* set) {
  set->Add("run.threads", &c->run.threads,
           "worker threads, 0 = one per core; results do not depend on it", 0,
           4096);
  set->Add("run.stages", &c->run.stages,
           "stages of reconstruct: comma-separated subset of depth,fuse,mesh");

  set->Add("image.linearize", &c->image.linearize,
           "apply the inverse sRGB curve at load (match in linear radiance)");
  set->Add("image.cache_mb", &c->image.cache_mb,
           "image cache budget in MB (least recently used images evicted)",
           1e-3, kInf);
  set->Add("image.max_image_size", &c->image.max_image_size,
           "downscale images (and cameras) whose longest side exceeds this "
           "many pixels; 0 = full size",
           0, kIntMax);

  // Sparse tracks from known poses (used when the dataset has no points).
  TrackerOptions& t = c->tracker;
  FeatureOptions& f = t.features;
  set->Add("tracker.features.max_features", &f.max_features,
           "keep at most this many SIFT features per view, 0 = no cap", 0,
           kIntMax);
  set->Add("tracker.features.contrast_threshold", &f.contrast_threshold,
           "SIFT contrast threshold (lower finds more on weak texture)", 0,
           kInf);
  set->Add("tracker.features.edge_threshold", &f.edge_threshold,
           "SIFT edge threshold", 0, kInf);
  set->Add("tracker.features.octave_layers", &f.octave_layers,
           "SIFT layers per octave", 1, 32);
  set->Add("tracker.features.sigma", &f.sigma, "SIFT base blur sigma", 0, kInf);
  set->Add("tracker.features.downscale", &f.downscale,
           "detect features on the image shrunk by this factor (>= 1)", 1,
           kInf);
  set->Add("tracker.features.max_image_size", &f.max_image_size,
           "detect features on images shrunk to this longest side, 0 = no "
           "limit",
           0, kIntMax);
  set->Add("tracker.features.srgb_encode", &f.srgb_encode,
           "sRGB-encode the grey image before SIFT");
  set->Add("tracker.features.root_sift", &f.root_sift,
           "use RootSIFT descriptors");
  set->Add("tracker.max_neighbors", &t.max_neighbors,
           "match each view against at most this many earlier views", 1,
           kIntMax);
  set->Add("tracker.min_overlap", &t.min_overlap,
           "minimum frustum overlap fraction of a candidate pair", 0, 1);
  set->Add("tracker.max_pair_angle_deg", &t.max_pair_angle_deg,
           "do not match pairs whose optical axes differ by more (degrees)", 0,
           180);
  set->Add("tracker.scene_depth", &t.scene_depth,
           "typical scene depth for the overlap test, 0 = automatic", 0, kInf);
  set->Add("tracker.max_epipolar_distance", &t.max_epipolar_distance,
           "accept matches within this distance of the epipolar line (px)", 0,
           kInf);
  set->Add("tracker.ratio", &t.ratio, "Lowe's ratio test threshold", 0, 1);
  set->Add("tracker.max_descriptor_distance", &t.max_descriptor_distance,
           "bound on the descriptor L2 distance (0..2)", 0, 2);
  set->Add("tracker.mutual", &t.mutual,
           "keep a match only when best in both directions");
  set->Add("tracker.max_reprojection_error", &t.max_reprojection_error,
           "remove observations reprojecting farther (px)", 0, kInf);
  set->Add("tracker.max_outlier_removals", &t.max_outlier_removals,
           "at most this many observations removed per track", 0, kIntMax);
  set->Add(
      "tracker.min_triangulation_angle_deg", &t.min_triangulation_angle_deg,
      "a point's largest pairwise viewing angle must reach this (deg)", 0, 180);
  set->Add("tracker.max_scale_ratio", &t.max_scale_ratio,
           "feature scales of a track may differ by at most this factor, "
           "0 = off",
           0, kInf);
  set->Add("tracker.resolve_conflicts", &t.resolve_conflicts,
           "keep the best feature of a view with two in one track (else "
           "reject the track)");
  set->Add("tracker.min_track_length", &t.min_track_length,
           "tracks seen in fewer views produce no point", 2, kIntMax);
  set->Add("tracker.refine_iterations", &t.refine_iterations,
           "Gauss-Newton iterations of the triangulation refinement", 0,
           kIntMax);

  // Per-view depth maps (Goesele et al. 2007).
  MvsOptions& m = c->mvs;
  set->Add("mvs.use_color", &m.use_color,
           "match colour images; false = grey (ablation)");
  set->Add("mvs.max_image_size", &m.max_image_size,
           "longest side of the reference view's working image, 0 = any "
           "(after image.max_image_size)",
           0, kIntMax);
  set->Add("mvs.global.num_neighbors", &m.global.num_neighbors,
           "global view selection: neighbourhood size |N| (paper: 10)", 1,
           kIntMax);
  set->Add("mvs.global.max_parallax_deg", &m.global.max_parallax_deg,
           "parallax weight a_max in degrees (paper: 10)", 0, 180);
  set->Add("mvs.global.min_baseline_deg", &m.global.min_baseline_deg,
           "views with a smaller median triangulation angle never enter N "
           "(twins)",
           0, 180);
  set->Add("mvs.global.fallback_max_baseline_deg",
           &m.global.fallback_max_baseline_deg,
           "fallback without shared features: largest triangulation angle", 0,
           180);
  set->Add("mvs.rescaling.enabled", &m.rescaling.enabled,
           "rescale the reference and neighbours to a common scale");
  set->Add("mvs.rescaling.min_scale", &m.rescaling.min_scale,
           "downsample the reference when the coarsest neighbour's scale is "
           "below (paper: 0.6)",
           0, kInf);
  set->Add("mvs.rescaling.max_scale", &m.rescaling.max_scale,
           "downsample neighbours whose scale exceeds this (paper: 1.2)", 0,
           kInf);
  set->Add("mvs.local.enabled", &m.local.enabled,
           "local view selection per pixel; false = fixed best views "
           "(ablation)");
  set->Add("mvs.local.num_active", &m.local.num_active,
           "active views per pixel |A| (paper: 4)", 1, kIntMax);
  set->Add("mvs.local.max_epipolar_angle_deg", &m.local.max_epipolar_angle_deg,
           "epipolar-angle spread g_max in degrees (paper: 10)", 0, 180);
  set->Add("mvs.local.min_ncc", &m.local.min_ncc,
           "NCC needed to enter the active set (paper: 0.3)", -1, 1);
  set->Add("mvs.mpgc.window", &m.mpgc.window,
           "matching window side n of n x n (paper: 5)", 1, 99);
  set->Add("mvs.mpgc.settle_iterations", &m.mpgc.settle_iterations,
           "iterations before any test (paper: 5)", 0, kIntMax);
  set->Add("mvs.mpgc.drop_ncc", &m.mpgc.drop_ncc,
           "drop active views whose NCC falls below (paper: 0.4)", -1, 1);
  set->Add("mvs.mpgc.convergence_eps", &m.mpgc.convergence_eps,
           "converged when every NCC changes less (paper: 0.001)", 0, kInf);
  set->Add("mvs.mpgc.max_iterations", &m.mpgc.max_iterations,
           "fail after this many iterations (paper: 20)", 1, kIntMax);
  set->Add("mvs.mpgc.full_update_interval", &m.mpgc.full_update_interval,
           "optimise normal and colour scales every k-th iteration "
           "(paper: 5)",
           1, kIntMax);
  set->Add("mvs.mpgc.oscillation_iteration", &m.mpgc.oscillation_iteration,
           "from this iteration drop oscillating views (paper: 14)", 0,
           kIntMax);
  set->Add("mvs.mpgc.min_facing", &m.mpgc.min_facing,
           "normal . (-ray) must exceed this (paper: 0.1)", -1, 1);
  set->Add("mvs.mpgc.min_active_views", &m.mpgc.min_active_views,
           "fail when fewer active views remain", 1, kIntMax);
  set->Add("mvs.mpgc.accept_ncc", &m.mpgc.accept_ncc,
           "accept a match only when its mean NCC reaches this; -1 = any "
           "(paper)",
           -1, 1);
  set->Add("mvs.mpgc.min_texture_levels", &m.mpgc.min_texture_levels,
           "do not match reference windows whose spread is below this many "
           "8-bit sRGB levels; 0 = off (paper)",
           0, 64);
  set->Add("mvs.mpgc.normal_step_halvings", &m.mpgc.normal_step_halvings,
           "halve a normal step that turns the patch away up to this many "
           "times; 0 = off (paper)",
           0, 8);
  set->Add("mvs.mpgc.photometric_offset", &m.mpgc.photometric_offset,
           "photometric model I_R = c I_V + b (offset per view and channel); "
           "false = c I_V (paper)");
  set->Add("mvs.mpgc.optimize_normal", &m.mpgc.optimize_normal,
           "optimise the normal; false = fronto-parallel (ablation)");
  set->Add("mvs.mpgc.optimize_color_scale", &m.mpgc.optimize_color_scale,
           "optimise per-view colour scales; false = fixed 1 (lab data)");
  set->Add("mvs.growing.tile_size", &m.growing.tile_size,
           "region growing tile side in pixels (parallel unit)", 1, kIntMax);
  set->Add("mvs.growing.seeds_from_neighbors", &m.growing.seeds_from_neighbors,
           "also seed from the neighbours' features projected into R");
  set->Add("mvs.growing.revisit_margin", &m.growing.revisit_margin,
           "revisit a pixel only from a candidate whose mean NCC beats the "
           "stored one by more than this (paper: 0)",
           0, 2);
  set->Add("mvs.consistency.enabled", &m.consistency.enabled,
           "filter each depth map against its neighbours' maps "
           "(forward-backward reprojection); false = paper");
  set->Add("mvs.consistency.min_consistent", &m.consistency.min_consistent,
           "neighbour maps that must confirm a sample", 1, 32);
  set->Add("mvs.consistency.max_reprojection_px",
           &m.consistency.max_reprojection_px,
           "forward-backward reprojection distance allowed, pixels", 0, 100);
  set->Add("mvs.consistency.max_relative_depth",
           &m.consistency.max_relative_depth,
           "relative depth difference allowed", 0, 1);
  set->Add("mvs.sweep.step", &m.sweep.step,
           "fallback depth sweep: test every step-th pixel", 1, kIntMax);
  set->Add("mvs.sweep.num_depths", &m.sweep.num_depths,
           "fallback depth sweep: depths tested (uniform in 1/z)", 2, kIntMax);
  set->Add("mvs.sweep.num_views", &m.sweep.num_views,
           "fallback depth sweep: score = mean of the best k NCCs", 1, kIntMax);
  set->Add("mvs.sweep.min_score", &m.sweep.min_score,
           "fallback depth sweep: seed only above this mean NCC", -1, 1);

  // Fusion of the depth maps into one point cloud.
  FusionOptions& u = c->fusion;
  set->Add("fusion.min_support", &u.min_support,
           "views (own included) that must agree with a sample", 1, kIntMax);
  set->Add("fusion.min_confidence", &u.min_confidence,
           "ignore samples with lower confidence", 0, 1);
  set->Add("fusion.depth_tolerance", &u.depth_tolerance,
           "relative depth tolerance of the consistency check", 0, kInf);
  set->Add("fusion.reprojection_tolerance_px", &u.reprojection_tolerance_px,
           "reprojection tolerance of the consistency check (px)", 0, kInf);
  set->Add("fusion.normal_tolerance_deg", &u.normal_tolerance_deg,
           "largest angle between agreeing normals (degrees)", 0, 180);
  set->Add("fusion.cell_scale", &u.cell_scale,
           "merge radius as a multiple of the pixel footprint", 0, kInf);
  set->Add("fusion.max_neighbors", &u.max_neighbors,
           "related views per view at most", 1, kIntMax);
  for (int k = 0; k < 3; ++k) {
    const char axis[] = {'x', 'y', 'z'};
    set->Add(Msg("fusion.bbox_min_", axis[k]), &u.bbox_min[k],
             Msg("bounding box minimum ", axis[k], " (world units)"), -kInf,
             kInf, true);
  }
  for (int k = 0; k < 3; ++k) {
    const char axis[] = {'x', 'y', 'z'};
    set->Add(Msg("fusion.bbox_max_", axis[k]), &u.bbox_max[k],
             Msg("bounding box maximum ", axis[k], " (world units)"), -kInf,
             kInf, true);
  }
  set->Add("fusion.map_cache_mb", &u.map_cache_mb,
           "budget of the depth-map cache in MB", 0, kInf);
  set->Add("fusion.pending_mb", &u.pending_mb,
           "budget of not-yet-supported samples in MB, 0 = none", 0, kInf);

  // Poisson mesh of the fused cloud.
  MeshingOptions& h = c->mesh;
  set->Add("meshing.depth", &h.depth,
           "maximum octree depth of the Poisson solve (resolution 2^depth)", 4,
           14);
  set->Add("meshing.point_weight", &h.point_weight,
           "screening weight of the points, 0 = unscreened Poisson", 0, kInf);
  set->Add("meshing.samples_per_node", &h.samples_per_node,
           "minimum samples per octree node (more for noisy data)", 1, kInf);
  set->Add("meshing.scale", &h.scale,
           "reconstruction cube / bounding cube of the samples", 1, 4);
  set->Add("meshing.trim_distance", &h.trim_distance,
           "remove surface farther than this x local sample spacing from "
           "the samples, 0 = no trimming",
           0, kInf);
  set->Add("meshing.spacing_neighbors", &h.spacing_neighbors,
           "neighbours defining the local sample spacing", 1, 64);
  set->Add("meshing.min_component_faces", &h.min_component_faces,
           "drop connected pieces with fewer faces after trimming", 0, kIntMax);
  set->Add("meshing.decimation_cell", &h.decimation_cell,
           "vertex-clustering cell in world units, 0 = no decimation", 0, kInf);
  set->Add("meshing.threads", &h.threads, "threads of the Poisson solver", 1,
           256);
}

}  // namespace cli
}  // namespace wild_mvs
