// Copyright wild_mvs authors.
#include "wild_mvs/core/view_refinement.h"

#include <cmath>

#include "wild_mvs/core/error.h"

namespace wild_mvs {

void RefinementOptions::Check() const {
  Require(neighbor_seed_stride >= 0 && neighbor_seed_stride <= 64,
          "mvs.refine.neighbor_seed_stride = ", neighbor_seed_stride,
          " must be in [0, 64] (0 = no seeds from the neighbours)");
  Require(min_consistent_new >= 1 && min_consistent_new <= 32,
          "mvs.refine.min_consistent_new = ", min_consistent_new,
          " must be in [1, 32]");
}

void RegisterOptions(OptionRegistry* registry, const std::string& prefix,
                     RefinementOptions* o) {
  auto key = [&prefix](const char* name) {
    return OptionRegistry::Join(prefix, name);
  };
  registry->Add(key("enabled"), &o->enabled,
                "after the consistency filter, grow each view again from its "
                "consistent samples and its neighbours' (reprojected), then "
                "filter again; needs consistency.enabled; false = paper");
  registry->Add(key("grow_from_consistent"), &o->grow_from_consistent,
                "second pass: grow from the view's own consistent samples "
                "into its empty pixels");
  registry
      ->Add(key("neighbor_seed_stride"), &o->neighbor_seed_stride,
            "second pass: one seed from the neighbours' reprojected "
            "consistent samples per block of this many pixels square of "
            "empty pixels; 0 = none")
      .Min(0)
      .Max(64);
  registry
      ->Add(key("min_consistent_new"), &o->min_consistent_new,
            "the filter after the second pass: neighbour maps that must "
            "confirm a sample the pass added or changed")
      .Min(1)
      .Max(32);
}

std::vector<Seed> RefinementSeeds(const DepthMap& own,
                                  const std::vector<const DepthMap*>& neighbors,
                                  const cv::Mat& mask,
                                  const RefinementOptions& options,
                                  RefinementSeedStats* stats) {
  options.Check();
  Require(!own.empty() && own.depth.type() == CV_32F &&
              own.normal.type() == CV_32FC3 &&
              own.normal.size() == own.depth.size(),
          "RefinementSeeds: empty or malformed map of view ", own.view);
  Require(
      mask.empty() || (mask.type() == CV_8U && mask.size() == own.depth.size()),
      "RefinementSeeds: mask must be CV_8U of the map's size");
  const int W = own.width(), H = own.height();
  auto allowed = [&](int x, int y) {
    return mask.empty() || mask.at<uint8_t>(y, x) != 0;
  };
  auto empty_at = [&](int x, int y) {
    return !(own.depth.at<float>(y, x) > 0) && allowed(x, y);
  };
  RefinementSeedStats st;
  std::vector<Seed> seeds;
  // (a) R's consistent samples on the border of a hole.
  if (options.grow_from_consistent) {
    static const int dx[4] = {1, -1, 0, 0}, dy[4] = {0, 0, 1, -1};
    for (int y = 0; y < H; ++y) {
      for (int x = 0; x < W; ++x) {
        if (!(own.depth.at<float>(y, x) > 0)) continue;
        bool border = false;
        for (int k = 0; k < 4 && !border; ++k) {
          const int nx = x + dx[k], ny = y + dy[k];
          border = nx >= 0 && ny >= 0 && nx < W && ny < H && empty_at(nx, ny);
        }
        if (!border) continue;
        Seed s;
        s.x = x;
        s.y = y;
        s.depth = own.depth.at<float>(y, x);
        s.held = true;
        seeds.push_back(s);
        ++st.held;
      }
    }
  }
  // (b) The neighbours' samples reprojected into R's empty pixels: the
  // nearest per pixel (a z-buffer), with its normal in R's frame.
  const int stride = options.neighbor_seed_stride;
  if (stride > 0) {
    cv::Mat zbuf = cv::Mat::zeros(H, W, CV_32F);
    cv::Mat nbuf = cv::Mat::zeros(H, W, CV_32FC3);
    const Camera& rc = own.camera;
    for (const DepthMap* nb : neighbors) {
      if (!nb || nb->empty()) continue;
      const Camera& vc = nb->camera;
      // Camera-frame rotation V -> R.
      const Eigen::Matrix3d rot = rc.R * vc.R.transpose();
      for (int v = 0; v < nb->height(); ++v) {
        const float* d = nb->depth.ptr<float>(v);
        const cv::Vec3f* n = nb->normal.ptr<cv::Vec3f>(v);
        for (int u = 0; u < nb->width(); ++u) {
          if (!(d[u] > 0)) continue;
          const Eigen::Vector3d X =
              vc.Backproject(Eigen::Vector2d(u + 0.5, v + 0.5), d[u]);
          Eigen::Vector2d q;
          if (!rc.Project(X, &q)) continue;
          const int qx = static_cast<int>(std::floor(q.x()));
          const int qy = static_cast<int>(std::floor(q.y()));
          if (qx < 0 || qy < 0 || qx >= W || qy >= H) continue;
          if (!empty_at(qx, qy)) continue;
          const float z = static_cast<float>(rc.Depth(X));
          float& zb = zbuf.at<float>(qy, qx);
          if (zb > 0 && zb <= z) continue;
          zb = z;
          Eigen::Vector3d nr = rot * Eigen::Vector3d(n[u][0], n[u][1], n[u][2]);
          // Facing R, else fronto-parallel.
          const Eigen::Vector3d ray =
              rc.BackprojectCam(Eigen::Vector2d(qx + 0.5, qy + 0.5), 1.0);
          if (!(nr.norm() > 0.5) || nr.dot(ray) >= -0.1 * ray.norm())
            nr.setZero();
          else
            nr.normalize();
          nbuf.at<cv::Vec3f>(qy, qx) =
              cv::Vec3f(static_cast<float>(nr.x()), static_cast<float>(nr.y()),
                        static_cast<float>(nr.z()));
        }
      }
    }
    // One seed per block: the reprojected pixel nearest the block's centre.
    for (int by = 0; by < H; by += stride) {
      for (int bx = 0; bx < W; bx += stride) {
        const double cx = bx + 0.5 * (stride - 1), cy = by + 0.5 * (stride - 1);
        int best_x = -1, best_y = -1;
        double best = 0;
        for (int y = by; y < std::min(H, by + stride); ++y) {
          for (int x = bx; x < std::min(W, bx + stride); ++x) {
            if (!(zbuf.at<float>(y, x) > 0)) continue;
            const double d2 = (x - cx) * (x - cx) + (y - cy) * (y - cy);
            if (best_x < 0 || d2 < best) {
              best = d2;
              best_x = x;
              best_y = y;
            }
          }
        }
        if (best_x < 0) continue;
        Seed s;
        s.x = best_x;
        s.y = best_y;
        s.depth = zbuf.at<float>(best_y, best_x);
        const cv::Vec3f& n = nbuf.at<cv::Vec3f>(best_y, best_x);
        s.normal = Eigen::Vector3d(n[0], n[1], n[2]);
        seeds.push_back(s);
        ++st.neighbor;
      }
    }
  }
  if (stats) *stats = st;
  return seeds;
}

}  // namespace wild_mvs
