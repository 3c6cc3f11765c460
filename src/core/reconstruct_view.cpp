// Copyright wild_mvs authors.
#include "wild_mvs/core/reconstruct_view.h"

#include <time.h>

#include <chrono>
#include <cmath>
#include <memory>
#include <opencv2/imgproc.hpp>
#include <unordered_set>

#include "wild_mvs/core/error.h"
#include "wild_mvs/core/planar_prior.h"

namespace wild_mvs {

void MvsOptions::Check() const {
  global.Check();
  local.Check();
  mpgc.Check();
  growing.Check();
  sweep.Check();
  consistency.Check();
  Require(max_image_size >= 0, "mvs.max_image_size = ", max_image_size,
          " must be >= 0 (0 = no limit)");
  Require(mpgc.min_active_views <= local.num_active,
          "mvs.mpgc.min_active_views = ", mpgc.min_active_views,
          " must not exceed mvs.local.num_active = ", local.num_active);
}

MvsOptions PaperMvsOptions() {
  MvsOptions o;
  o.ablation.explain_test = false;
  o.ablation.bilateral_window = false;
  o.mpgc.window = 5;
  o.mpgc.window_step = 1;
  o.growing.revisit_margin = 0;
  o.sweep.below_seeds = 1;
  o.ablation.photometric_offset = false;
  o.ablation.consistency = false;
  o.ablation.planar_prior = false;
  o.ablation.coarse_fill = false;
  return o;
}

namespace {

// A matching copy of an image: contiguous interleaved float, RGB or grey.
struct OwnedImage {
  std::shared_ptr<const cv::Mat> rgb;  // keeps the cache entry alive
  std::vector<float> grey;
  MatchImage view;
};

OwnedImage MakeMatchImage(std::shared_ptr<const cv::Mat> img, bool color) {
  Require(img && !img->empty() && img->type() == CV_32FC3,
          "ReconstructView: images must be CV_32FC3 (ImageCache)");
  OwnedImage o;
  o.view.width = img->cols;
  o.view.height = img->rows;
  if (color) {
    if (!img->isContinuous())
      img = std::make_shared<const cv::Mat>(img->clone());
    o.rgb = img;
    o.view.data = o.rgb->ptr<float>();
    o.view.channels = 3;
  } else {
    o.grey.resize(static_cast<size_t>(img->cols) * img->rows);
    for (int r = 0; r < img->rows; ++r) {
      const float* p = img->ptr<float>(r);
      float* g = o.grey.data() + static_cast<size_t>(r) * img->cols;
      for (int c = 0; c < img->cols; ++c)
        g[c] = (p[3 * c] + p[3 * c + 1] + p[3 * c + 2]) * (1.0f / 3.0f);
    }
    o.view.data = o.grey.data();
    o.view.channels = 1;
  }
  return o;
}

}  // namespace

DepthMap ReconstructView(const Scene& scene, int ref, ImageCache& images,
                         const MvsOptions& options, ThreadPool* pool,
                         ViewReport* report, const cv::Mat& mask,
                         const std::vector<std::vector<int>>* points_per_view,
                         const std::atomic<bool>* cancel) {
  const auto wall0 = std::chrono::steady_clock::now();
  const double cpu0 = ThreadCpuSeconds();
  double body_cpu = 0;
  options.Check();
  Require(ref >= 0 && ref < static_cast<int>(scene.views.size()),
          "ReconstructView: no view ", ref, " (the scene has ",
          scene.views.size(), ")");
  const Camera& cam_full = scene.views[ref].camera;
  cam_full.Validate("view '" + scene.views[ref].name + "'");
  Require(
      mask.empty() || (mask.type() == CV_8U && mask.cols == cam_full.width &&
                       mask.rows == cam_full.height),
      "ReconstructView: mask of view '", scene.views[ref].name,
      "' must be CV_8U ", cam_full.width, "x", cam_full.height);
  ViewReport rep;
  std::vector<std::vector<int>> own_ppv;
  if (!points_per_view) own_ppv = scene.PointsPerView();
  const std::vector<std::vector<int>>& ppv =
      points_per_view ? *points_per_view : own_ppv;
  Require(ppv.size() == scene.views.size(),
          "ReconstructView: points_per_view has ", ppv.size(), " entries for ",
          scene.views.size(), " views");

  // 1. Global view selection.
  GlobalViewSelection sel = SelectGlobalViews(scene, ref, ppv, options.global);
  rep.fallbacks = sel.fallbacks;
  rep.neighbors = sel.neighbors;
  rep.neighbor_scores = sel.scores;

  double dmin = 0, dmax = 0;
  const double scene_depth = EstimateSceneDepth(scene, ref, ppv, &dmin, &dmax);
  const Eigen::Vector3d axis_point = cam_full.Backproject(
      Eigen::Vector2d(cam_full.width * 0.5, cam_full.height * 0.5),
      scene_depth > 0 ? scene_depth : 1.0);

  // 2. Rescaling.
  for (int v : sel.neighbors)
    rep.scales.push_back(ScaleRatio(scene, ref, v, ppv, &axis_point));
  const RescalingPlan plan =
      PlanRescaling(scene, ref, sel.neighbors, rep.scales,
                    options.ablation.rescaling, options.max_image_size);
  const Camera& cam = plan.ref_camera;
  rep.working_scale = static_cast<double>(cam.width) / cam_full.width;
  rep.width = cam.width;
  rep.height = cam.height;

  DepthMap dm;
  dm.view = ref;
  dm.camera = cam;
  dm.neighbors = sel.neighbors;
  dm.depth = cv::Mat::zeros(cam.height, cam.width, CV_32F);
  dm.normal = cv::Mat::zeros(cam.height, cam.width, CV_32FC3);
  dm.confidence = cv::Mat::zeros(cam.height, cam.width, CV_32F);

  if (sel.neighbors.empty()) {
    rep.fallbacks.push_back(
        Msg("fallback: view '", scene.views[ref].name,
            "' has no usable neighbour (no shared features and no "
            "overlapping view with parallax); its depth map is empty"));
  } else {
    // Images at their working resolutions.
    const OwnedImage ref_img = MakeMatchImage(
        images.GetResized(ref, cam.width, cam.height), options.ablation.color);
    std::vector<OwnedImage> nb_img;
    nb_img.reserve(sel.neighbors.size());
    PatchContext ctx;
    ctx.ref_camera = cam;
    ctx.ref_image = ref_img.view;
    ctx.ref_noise = images.noise_profiles().Get(ref, ref_img.view);
    ctx.window = options.mpgc.window;
    ctx.ablation = options.ablation;
    for (size_t i = 0; i < sel.neighbors.size(); ++i) {
      const Camera& nc = plan.neighbor_cameras[i];
      nb_img.push_back(MakeMatchImage(
          images.GetResized(sel.neighbors[i], nc.width, nc.height),
          options.ablation.color));
      ctx.AddView(sel.neighbors[i], nc, nb_img.back().view,
                  sel.scores[i] > 0 ? sel.scores[i] : 1e-6);
      ctx.views.back().noise =
          images.noise_profiles().Get(sel.neighbors[i], nb_img.back().view);
    }

    cv::Mat wmask;
    if (!mask.empty()) {
      if (mask.cols == cam.width && mask.rows == cam.height)
        wmask = mask.clone();
      else
        cv::resize(mask, wmask, cv::Size(cam.width, cam.height), 0, 0,
                   cv::INTER_NEAREST);
    }

    // 3. Seeds: R's features, then the neighbours' features projected in R.
    std::vector<Seed> seeds;
    std::unordered_set<int> used;
    auto add_point = [&](int p) {
      if (!used.insert(p).second) return;
      Eigen::Vector2d px;
      const Eigen::Vector3d& X = scene.points[p].xyz;
      if (!cam.Project(X, &px) || !cam.InImage(px)) return;
      const int x = static_cast<int>(std::floor(px.x()));
      const int y = static_cast<int>(std::floor(px.y()));
      if (x < 0 || y < 0 || x >= cam.width || y >= cam.height) return;
      seeds.push_back(Seed{x, y, cam.Depth(X)});
    };
    for (int p : ppv[ref]) add_point(p);
    const std::vector<Seed> own_points = seeds;  // R sees them
    for (int v : sel.neighbors)
      for (int p : ppv[v]) add_point(p);

    // The matching thresholds for this working size (wide windows).
    MpgcOptions mpgc = options.mpgc;
    LocalViewSelectionOptions local = options.local;
    UseWideThresholds(cam.width, cam.height, &mpgc, &local);
    GrowStats stats;
    if (!seeds.empty())
      GrowRegions(ctx, mpgc, local, options.growing, seeds, wmask, pool,
                  &dm.depth, &dm.normal, &dm.confidence, &stats, cancel);
    if (stats.seeds_accepted < options.sweep.below_seeds) {
      // No (or too few) sparse features produced a match: seed the pixels
      // still empty from a plane sweep.
      double lo = dmin, hi = dmax;
      if (!(lo > 0) || !(hi > lo)) {
        lo = scene_depth * 0.5;
        hi = scene_depth * 2.0;
      }
      lo *= 0.8;
      hi *= 1.25;
      std::vector<Seed> swept;
      cv::Mat empty = dm.depth <= 0;  // CV_8U, 255 where nothing grew
      if (!wmask.empty()) empty &= wmask;
      if (scene_depth > 0 && !(cancel && cancel->load()))
        swept = SweepSeeds(ctx, mpgc, local, options.sweep, lo, hi, empty, pool,
                           &body_cpu);
      const std::string why =
          seeds.empty()               ? "no sparse feature projects into it"
          : stats.seeds_accepted == 0 ? "no sparse feature could be matched"
                                      : Msg("only ", stats.seeds_accepted,
                                            " sparse features matched (< "
                                            "mvs.sweep.below_seeds)");
      rep.fallbacks.push_back(
          Msg("fallback: view '", scene.views[ref].name, "': ", why,
              "; seeded from a fronto-parallel depth sweep over [", lo, ", ",
              hi, "]: ", swept.size(), " seeds"));
      if (!swept.empty())
        GrowRegions(ctx, mpgc, local, options.growing, swept, wmask, pool,
                    &dm.depth, &dm.normal, &dm.confidence, &stats, cancel);
    }
    // 4. Planar prior where growth stopped (planar_prior.h).
    if (options.ablation.planar_prior && !(cancel && cancel->load())) {
      PlanarPriorStats planar;
      FillFromPlanarPrior(ctx, mpgc, local, own_points, wmask, pool, &dm,
                          &planar);
      body_cpu += planar.cpu_seconds;
      rep.planar_samples = planar.samples_added;
    }
    rep.seeds_tried = stats.seeds_tried;
    rep.seeds_accepted = stats.seeds_accepted;
    rep.pixel_visits = stats.pixel_visits;
    body_cpu += stats.cpu_seconds;
  }
  if (cancel && cancel->load())
    throw Cancelled(Msg("view '", scene.views[ref].name, "': cancelled"));
  rep.samples = dm.CountValid();
  rep.seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0)
          .count();
  // CPU: this thread's own time plus the work done on pool threads.
  const double own = ThreadCpuSeconds() - cpu0;
  rep.cpu_seconds = body_cpu + own;
  if (report) *report = rep;
  return dm;
}

void RegisterOptions(OptionRegistry* registry, const std::string& prefix,
                     MvsOptions* o) {
  auto key = [&prefix](const char* name) {
    return OptionRegistry::Join(prefix, name);
  };
  registry
      ->Add(key("max_image_size"), &o->max_image_size,
            "longest side of the reference view's working image, 0 = any "
            "(after image.max_image_size)")
      .Min(0);
  RegisterOptions(registry, key("global"), &o->global);
  RegisterOptions(registry, key("local"), &o->local);
  RegisterOptions(registry, key("mpgc"), &o->mpgc);
  RegisterOptions(registry, key("growing"), &o->growing);
  RegisterOptions(registry, key("sweep"), &o->sweep);
}

}  // namespace wild_mvs
