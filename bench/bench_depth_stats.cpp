// Copyright wild_mvs authors. Quality statistics of a folder of depth maps
// (written by `bench_mvs --save DIR` or `wild_mvs reconstruct`); not a test.
//
//   bench_depth_stats MODEL_DIR IMAGES_DIR DEPTH_DIR
//       [--bbox x0 y0 z0 x1 y1 z1] [--margin M] [--consistency REL]
//       [--gt DATASET_DIR]
//
// Per view and in total:
//   samples      valid depth samples;
//   in_bbox      samples whose 3-D point lies in the box (enlarged by M);
//   consistent   samples that agree with at least one other view's depth
//                map: the point projected into that view lands on a sample
//                whose depth differs by at most REL (relative, default
//                0.01) from the point's depth there;
//   correct      in_bbox and consistent (all consistent without --bbox);
//   with --gt:   completeness (fraction of ground-truth pixels with an
//                estimate), fraction of the estimated pixels within 1 cm and
//                2 cm and within 1 % of the true depth (and their count,
//                correct_1pct: "correct" on fountain-P11), median absolute
//                error, over the pixels with ground truth.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <string>
#include <vector>

#include "wild_mvs/core/error.h"
#include "wild_mvs/core/metrics.h"
#include "wild_mvs/core/stats.h"
#include "wild_mvs/io/colmap.h"
#include "wild_mvs/io/depth_map_io.h"
#include "wild_mvs/io/ground_truth.h"

using namespace wild_mvs;

namespace {

struct Totals {
  long long samples = 0, in_bbox = 0, consistent = 0, correct = 0;
  long long gt_valid = 0, evaluated = 0, within1 = 0, within2 = 0;
  long long within_rel = 0;  // |d - g| <= 0.01 g
  std::vector<float> errors;
};

}  // namespace

int main(int argc, char** argv) {
  if (argc < 4) {
    std::cerr << "usage: bench_depth_stats MODEL_DIR IMAGES_DIR DEPTH_DIR "
                 "[--bbox x0 y0 z0 x1 y1 z1] [--margin M] "
                 "[--consistency REL] [--gt DATASET_DIR]\n";
    return 2;
  }
  try {
    bool have_box = false;
    double box[6] = {0, 0, 0, 0, 0, 0};
    double margin = 0, rel = 0.01;
    std::string gt_dir;
    for (int i = 4; i < argc; ++i) {
      const std::string a = argv[i];
      auto next = [&]() -> double {
        if (i + 1 >= argc) throw Error("missing value after " + a);
        return std::stod(argv[++i]);
      };
      if (a == "--bbox") {
        for (double& b : box) b = next();
        have_box = true;
      } else if (a == "--margin") {
        margin = next();
      } else if (a == "--consistency") {
        rel = next();
      } else if (a == "--gt") {
        if (i + 1 >= argc) throw Error("missing value after --gt");
        gt_dir = argv[++i];
      } else {
        throw Error("unknown option " + a);
      }
    }
    const Scene scene = ReadColmapModel(argv[1], argv[2]);
    const std::string dir = argv[3];
    std::vector<DepthMap> maps;
    for (const View& v : scene.views) {
      if (!DepthMapFilesExist(dir, v.Stem())) continue;
      maps.push_back(ReadDepthMapFiles(dir, v.Stem(), scene));
    }
    Require(!maps.empty(), dir, ": no depth maps of the scene's views");
    std::printf("%-20s %8s %8s %10s %8s", "view", "samples", "in_bbox",
                "consistent", "correct");
    if (!gt_dir.empty())
      std::printf(" %8s %7s %7s %9s", "complete", "<=1cm", "<=2cm", "median_m");
    std::printf("\n");
    Totals tot;
    for (size_t mi = 0; mi < maps.size(); ++mi) {
      const DepthMap& dm = maps[mi];
      const Camera& cam = dm.camera;
      cv::Mat gt;
      if (!gt_dir.empty())
        gt = LoadGroundTruthDepthForView(gt_dir, scene.views[dm.view], cam);
      Totals t;
      for (int y = 0; y < dm.depth.rows; ++y) {
        for (int x = 0; x < dm.depth.cols; ++x) {
          const float d = dm.depth.at<float>(y, x);
          const float g = gt.empty() ? 0.f : gt.at<float>(y, x);
          if (g > 0) ++t.gt_valid;
          if (!(d > 0)) continue;
          ++t.samples;
          if (g > 0) {
            const float e = std::abs(d - g);
            ++t.evaluated;
            if (e <= 0.01f) ++t.within1;
            if (e <= 0.02f) ++t.within2;
            if (e <= 0.01f * g) ++t.within_rel;
            t.errors.push_back(e);
          }
          const Eigen::Vector3d X =
              cam.Backproject(Eigen::Vector2d(x + 0.5, y + 0.5), d);
          bool inside = true;
          if (have_box)
            for (int k = 0; k < 3; ++k)
              inside = inside && X[k] >= box[k] - margin &&
                       X[k] <= box[k + 3] + margin;
          bool agree = false;
          for (size_t oj = 0; oj < maps.size() && !agree; ++oj)
            agree = oj != mi && AgreesWithDepthMap(X, maps[oj], rel);
          if (inside) ++t.in_bbox;
          if (agree) ++t.consistent;
          if (inside && agree) ++t.correct;
        }
      }
      std::printf("%-20s %8lld %8lld %10lld %8lld",
                  scene.views[dm.view].Stem().c_str(), t.samples, t.in_bbox,
                  t.consistent, t.correct);
      if (!gt_dir.empty()) {
        const double ev = std::max<long long>(1, t.evaluated);
        std::printf(" %8.3f %7.3f %7.3f %9.4f",
                    t.evaluated / std::max(1.0, double(t.gt_valid)),
                    t.within1 / ev, t.within2 / ev, Median(t.errors));
      }
      std::printf("\n");
      tot.samples += t.samples;
      tot.in_bbox += t.in_bbox;
      tot.consistent += t.consistent;
      tot.correct += t.correct;
      tot.gt_valid += t.gt_valid;
      tot.evaluated += t.evaluated;
      tot.within1 += t.within1;
      tot.within2 += t.within2;
      tot.within_rel += t.within_rel;
      tot.errors.insert(tot.errors.end(), t.errors.begin(), t.errors.end());
    }
    std::printf(
        "TOTAL views=%zu samples=%lld in_bbox=%lld consistent=%lld "
        "correct=%lld",
        maps.size(), tot.samples, tot.in_bbox, tot.consistent, tot.correct);
    if (!gt_dir.empty()) {
      const double ev = std::max<long long>(1, tot.evaluated);
      std::printf(
          " gt_completeness=%.4f within_1cm=%.4f within_2cm=%.4f "
          "within_1pct=%.4f correct_1pct=%lld median_error_m=%.5f",
          tot.evaluated / std::max(1.0, double(tot.gt_valid)), tot.within1 / ev,
          tot.within2 / ev, tot.within_rel / ev, tot.within_rel,
          Median(tot.errors));
    }
    std::printf("\n");
  } catch (const std::exception& e) {
    std::cerr << "bench_depth_stats: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
