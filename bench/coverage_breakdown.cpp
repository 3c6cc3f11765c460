// Copyright wild_mvs authors. Where ground-truth coverage is lost (not a
// test): for a `wild_mvs reconstruct` folder and its dataset's ground
// truth, every ground-truth pixel of every view is put in one class, pooled
// over the views:
//   final_ok / final_bad   the final map (OUT) has an estimate within 1 % /
//                          off by more;
//   removed_ok / removed_bad  no final estimate, but the first-pass map
//                          (OUT/raw) had one within 1 % / off by more (the
//                          consistency filter removed it);
//   none_border            no first-pass estimate, the pixel lies within
//                          `--border` px of the image edge (no window);
//   none_few_views         no first-pass estimate, the surface point is
//                          seen (ground truth of the neighbour within 1 %)
//                          by fewer than `--min-views` of the view's
//                          neighbours (MPGC needs mpgc.min_active_views);
//   none_seen              no first-pass estimate although enough
//                          neighbours see it (growth did not reach it or
//                          MPGC rejected it).
// Also the estimates without ground truth (background) in raw and final,
// and per extra folder given by --also (e.g. filtered1, refined) its
// coverage.
// With --dump-gt DIR, the ground truth of every view at the working
// resolution is written to DIR/STEM.pfm (for analyses outside this tool).
//   coverage_breakdown DATASET OUT [--border 2] [--min-views 3]
//       [--also DIR1,DIR2] [--dump-gt DIR]
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "wild_mvs/core/error.h"
#include "wild_mvs/io/dataset.h"
#include "wild_mvs/io/depth_map_io.h"
#include "wild_mvs/io/ground_truth.h"
#include "wild_mvs/io/pfm.h"

using namespace wild_mvs;
namespace fs = std::filesystem;

int main(int argc, char** argv) {
  try {
    Require(argc >= 3,
            "usage: coverage_breakdown DATASET OUT [--border B] "
            "[--min-views V] [--also DIR,...] [--dump-gt DIR]");
    const std::string dataset = argv[1], out = argv[2];
    int border = 2, min_views = 3;
    std::vector<std::string> also;
    std::string dump_gt;
    for (int i = 3; i + 1 < argc; i += 2) {
      const std::string k = argv[i], v = argv[i + 1];
      if (k == "--border") border = std::stoi(v);
      if (k == "--min-views") min_views = std::stoi(v);
      if (k == "--dump-gt") dump_gt = v;
      if (k == "--also") {
        std::stringstream ss(v);
        std::string d;
        while (std::getline(ss, d, ',')) also.push_back(d);
      }
    }
    DatasetOptions d;
    d.path = dataset;
    d.check_images = false;
    const Scene scene = LoadDataset(d);
    std::map<std::string, int> by_stem, by_name;
    for (size_t i = 0; i < scene.views.size(); ++i) {
      by_stem[scene.views[i].Stem()] = static_cast<int>(i);
      by_name[scene.views[i].name] = static_cast<int>(i);
    }
    // Final maps and ground truth of every view (working resolution).
    std::map<int, DepthMapFiles> fin;
    std::map<int, cv::Mat> gt;
    for (const auto& e : fs::directory_iterator(out + "/cameras")) {
      const std::string stem = e.path().stem().string();
      auto it = by_stem.find(stem);
      if (it == by_stem.end()) continue;
      fin[it->second] = ReadDepthMapFiles(out, stem);
      gt[it->second] = LoadGroundTruthDepthForView(
          dataset, scene.views[it->second], fin[it->second].map.camera);
      if (!dump_gt.empty() && !gt[it->second].empty()) {
        fs::create_directories(dump_gt);
        WritePfm(dump_gt + "/" + stem + ".pfm", gt[it->second]);
      }
    }
    const char* names[] = {"final_ok",    "final_bad",   "removed_ok",
                           "removed_bad", "none_border", "none_few_views",
                           "none_seen"};
    long long cls[7] = {0}, total = 0, bg_raw = 0, bg_fin = 0, est_raw = 0,
              est_fin = 0;
    std::vector<long long> also_cov(also.size(), 0), also_ok(also.size(), 0),
        also_est(also.size(), 0), also_bg(also.size(), 0);
    std::printf("%-10s %8s", "view", "gt_px");
    for (const char* n : names) std::printf(" %14s", n);
    std::printf("\n");
    for (auto& [v, files] : fin) {
      const DepthMap& f = files.map;
      const cv::Mat& g = gt[v];
      if (g.empty()) continue;
      const std::string stem = scene.views[v].Stem();
      const DepthMap raw = ReadDepthMapFiles(out + "/raw", stem).map;
      std::vector<DepthMap> extra;
      for (const std::string& a : also)
        extra.push_back(ReadDepthMapFiles(out + "/" + a, stem).map);
      std::vector<int> nbs;
      for (const std::string& n : files.neighbor_names)
        if (by_name.count(n) && gt.count(by_name[n])) nbs.push_back(by_name[n]);
      long long c[7] = {0}, t = 0;
      const Camera& rc = f.camera;
      for (int y = 0; y < f.height(); ++y) {
        for (int x = 0; x < f.width(); ++x) {
          const float gz = g.at<float>(y, x);
          const float fz = f.depth.at<float>(y, x);
          const float rz = raw.depth.at<float>(y, x);
          est_raw += rz > 0;
          est_fin += fz > 0;
          for (size_t k = 0; k < extra.size(); ++k) {
            const float ez = extra[k].depth.at<float>(y, x);
            also_est[k] += ez > 0;
            if (!(gz > 0)) {
              also_bg[k] += ez > 0;
            } else {
              also_cov[k] += ez > 0;
              also_ok[k] += ez > 0 && std::abs(ez - gz) < 0.01 * gz;
            }
          }
          if (!(gz > 0)) {
            bg_raw += rz > 0;
            bg_fin += fz > 0;
            continue;
          }
          ++t;
          if (fz > 0) {
            ++c[std::abs(fz - gz) < 0.01 * gz ? 0 : 1];
          } else if (rz > 0) {
            ++c[std::abs(rz - gz) < 0.01 * gz ? 2 : 3];
          } else if (x < border || y < border || x >= f.width() - border ||
                     y >= f.height() - border) {
            ++c[4];
          } else {
            const Eigen::Vector3d X =
                rc.Backproject(Eigen::Vector2d(x + 0.5, y + 0.5), gz);
            int seen = 0;
            for (int u : nbs) {
              const Camera& nc = fin[u].map.camera;
              Eigen::Vector2d q;
              if (!nc.Project(X, &q)) continue;
              const int qx = static_cast<int>(std::floor(q.x()));
              const int qy = static_cast<int>(std::floor(q.y()));
              if (qx < border || qy < border || qx >= nc.width - border ||
                  qy >= nc.height - border)
                continue;
              const float nz = gt[u].at<float>(qy, qx);
              const double z = nc.Depth(X);
              seen += nz > 0 && std::abs(nz - z) < 0.01 * z;
            }
            ++c[seen < min_views ? 5 : 6];
          }
        }
      }
      std::printf("%-10s %8lld", stem.c_str(), t);
      for (int k = 0; k < 7; ++k) {
        std::printf(" %14.4f", t ? double(c[k]) / t : 0.0);
        cls[k] += c[k];
      }
      std::printf("\n");
      total += t;
    }
    std::printf("%-10s %8lld", "all", total);
    for (int k = 0; k < 7; ++k)
      std::printf(" %14.4f", total ? double(cls[k]) / total : 0.0);
    std::printf(
        "\nbackground estimates (no GT) of all estimates: raw %.4f "
        "final %.4f\n",
        est_raw ? double(bg_raw) / est_raw : 0.0,
        est_fin ? double(bg_fin) / est_fin : 0.0);
    std::printf("final: gt covered %.4f, gt within 1 %% %.4f\n",
                double(cls[0] + cls[1]) / total, double(cls[0]) / total);
    std::printf("raw: gt covered %.4f\n",
                double(cls[0] + cls[1] + cls[2] + cls[3]) / total);
    for (size_t k = 0; k < also.size(); ++k)
      std::printf(
          "%s: gt covered %.4f, gt within 1 %% %.4f, estimates within "
          "1 %% %.4f, background %.4f\n",
          also[k].c_str(), double(also_cov[k]) / total,
          double(also_ok[k]) / total,
          also_cov[k] ? double(also_ok[k]) / also_cov[k] : 0.0,
          also_est[k] ? double(also_bg[k]) / also_est[k] : 0.0);
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "coverage_breakdown: %s\n", e.what());
    return 1;
  }
}
