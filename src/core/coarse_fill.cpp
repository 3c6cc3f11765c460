// Copyright wild_mvs authors.
#include "wild_mvs/core/coarse_fill.h"

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>

#include "wild_mvs/core/error.h"
#include "wild_mvs/core/patch.h"

namespace wild_mvs {
namespace {

// Depth along the camera-frame ray `ray` (z = 1) of the plane through the
// coarse sample at (x, y); 0 when the plane is seen edge-on there.
double PlaneDepth(const DepthMap& coarse, int x, int y,
                  const Eigen::Vector3d& ray) {
  const float d = coarse.depth.at<float>(y, x);
  const cv::Vec3f nv = coarse.normal.at<cv::Vec3f>(y, x);
  const Eigen::Vector3d n(nv[0], nv[1], nv[2]);
  const Eigen::Vector3d X =
      coarse.camera.BackprojectCam(Eigen::Vector2d(x + 0.5, y + 0.5), d);
  const double denom = n.dot(ray);
  // Grazing (within about 6 degrees of edge-on): the plane says little.
  if (std::abs(denom) < 0.1 * ray.norm() * std::max(n.norm(), 1e-9)) return 0;
  const double z = n.dot(X) / denom;
  return z > 0 ? z : 0;
}

// WindowsBelowNoise with colour weights (edge_aware_sigma > 0).
cv::Mat EdgeAwareBelowNoise(const cv::Mat& image, const NoiseProfile& noise,
                            int window, double kappa, double relative_sigma) {
  const int r = window / 2;
  cv::Mat out(image.size(), CV_8U, cv::Scalar(0));
  for (int y = 0; y < image.rows; ++y) {
    uchar* o = out.ptr<uchar>(y);
    for (int x = 0; x < image.cols; ++x) {
      const cv::Vec3f c0 = image.at<cv::Vec3f>(y, x);
      const double b0 = (c0[0] + c0[1] + c0[2]) / 3.0;
      const double noise_sigma = noise.Sigma(b0);
      const double s = relative_sigma * b0 + 2 * noise_sigma + 1e-6;
      const double inv = 1.0 / (2 * s * s);
      // Weighted sums over the window (borders replicated).
      double w1 = 0, w2 = 0, m[3] = {0, 0, 0}, q[3] = {0, 0, 0};
      for (int dy = -r; dy <= r; ++dy) {
        const int yy = std::min(image.rows - 1, std::max(0, y + dy));
        const cv::Vec3f* row = image.ptr<cv::Vec3f>(yy);
        for (int dx = -r; dx <= r; ++dx) {
          const cv::Vec3f c =
              row[std::min(image.cols - 1, std::max(0, x + dx))];
          double d2 = 0;
          for (int k = 0; k < 3; ++k) d2 += (c[k] - c0[k]) * (c[k] - c0[k]);
          const double w = std::exp(-d2 * inv);
          w1 += w;
          w2 += w * w;
          for (int k = 0; k < 3; ++k) {
            m[k] += w * c[k];
            q[k] += w * c[k] * c[k];
          }
        }
      }
      double ss = 0;
      for (int k = 0; k < 3; ++k) ss += std::max(0.0, q[k] - m[k] * m[k] / w1);
      if (WindowReliability(ss, noise_sigma * noise_sigma, 3, w1, w2) < kappa)
        o[x] = 255;
    }
  }
  return out;
}

// The noise profile of `image` (CV_32FC3, continuous).
NoiseProfile NoiseOf(const cv::Mat& image) {
  MatchImage view;
  view.data = image.ptr<float>();
  view.width = image.cols;
  view.height = image.rows;
  view.channels = 3;
  return NoiseProfile::Estimate(view);
}

}  // namespace

CoarseFillMasks PlanCoarseFill(const cv::Mat& image, const DepthMap& fine,
                               int window, double kappa) {
  Require(image.type() == CV_32FC3 && image.cols == fine.width() &&
              image.rows == fine.height(),
          "PlanCoarseFill: a CV_32FC3 image of the map's size");
  const cv::Mat full = image.isContinuous() ? image : image.clone();
  cv::Mat half;
  cv::resize(full, half, cv::Size((full.cols + 1) / 2, (full.rows + 1) / 2), 0,
             0, cv::INTER_AREA);
  CoarseFillMasks m;
  m.usable =
      ~WindowsBelowNoise(half, NoiseOf(half), window, kappa, kEdgeAwareSigma);
  cv::Mat textured;
  cv::resize(m.usable, textured, full.size(), 0, 0, cv::INTER_NEAREST);
  m.fillable = WindowsBelowNoise(full, NoiseOf(full), window, kappa) &
               (fine.depth <= 0) & textured;
  m.count = cv::countNonZero(m.fillable);
  return m;
}

int FillFromCoarse(const DepthMap& coarse, const cv::Mat& coarse_usable,
                   double max_spread, int interior_radius,
                   const cv::Mat& fillable, DepthMap* fine) {
  Require(fine != nullptr, "FillFromCoarse needs a fine map");
  Require(max_spread > 0 && max_spread < 1,
          "coarse fill: max_spread = ", max_spread, " must be in (0, 1)");
  if (coarse.empty() || fine->empty()) return 0;
  const Camera& cf = fine->camera;
  const Camera& cc = coarse.camera;
  const int W = coarse.width(), H = coarse.height();
  // Coarse samples whose whole window lies inside the coarse map: at a
  // silhouette the coarse window reaches past the surface by its half
  // width (fattening); those samples fill nothing.
  cv::Mat usable = coarse.depth > 0;
  if (interior_radius > 0)
    cv::erode(usable, usable,
              cv::getStructuringElement(
                  cv::MORPH_RECT,
                  cv::Size(2 * interior_radius + 1, 2 * interior_radius + 1)),
              cv::Point(-1, -1), 1, cv::BORDER_CONSTANT, cv::Scalar(0));
  if (!coarse_usable.empty()) {
    Require(
        coarse_usable.type() == CV_8U && coarse_usable.size() == usable.size(),
        "FillFromCoarse: coarse_usable must be CV_8U ", W, "x", H);
    usable &= coarse_usable;
  }
  int filled = 0;
  for (int y = 0; y < fine->height(); ++y) {
    float* depth = fine->depth.ptr<float>(y);
    for (int x = 0; x < fine->width(); ++x) {
      if (depth[x] > 0) continue;
      if (!fillable.empty() && fillable.at<uchar>(y, x) == 0) continue;
      // The fine pixel's ray (z = 1) and its position in the coarse map.
      const Eigen::Vector3d ray =
          cf.BackprojectCam(Eigen::Vector2d(x + 0.5, y + 0.5), 1.0);
      const Eigen::Vector2d pc = cc.ProjectCam(ray);
      const double gx = pc.x() - 0.5, gy = pc.y() - 0.5;
      const int x0 = static_cast<int>(std::floor(gx));
      const int y0 = static_cast<int>(std::floor(gy));
      if (x0 < 0 || y0 < 0 || x0 + 1 >= W || y0 + 1 >= H) continue;
      const double ax = gx - x0, ay = gy - y0;
      double z[4], w[4];
      bool ok = true;
      for (int k = 0; k < 4 && ok; ++k) {
        const int xs = x0 + (k & 1), ys = y0 + (k >> 1);
        ok = usable.at<uchar>(ys, xs) != 0;
        if (ok) z[k] = PlaneDepth(coarse, xs, ys, ray);
        ok = ok && z[k] > 0;
        w[k] = ((k & 1) ? ax : 1 - ax) * ((k >> 1) ? ay : 1 - ay);
      }
      if (!ok) continue;
      const double lo = std::min({z[0], z[1], z[2], z[3]});
      const double hi = std::max({z[0], z[1], z[2], z[3]});
      if (hi > lo * (1 + max_spread)) continue;  // not one surface
      double sum = 0;
      for (int k = 0; k < 4; ++k) sum += w[k] * z[k];
      const int xn = std::min(W - 1, std::max(0, static_cast<int>(pc.x())));
      const int yn = std::min(H - 1, std::max(0, static_cast<int>(pc.y())));
      depth[x] = static_cast<float>(sum);
      fine->normal.at<cv::Vec3f>(y, x) = coarse.normal.at<cv::Vec3f>(yn, xn);
      fine->confidence.at<float>(y, x) = coarse.confidence.at<float>(yn, xn);
      ++filled;
    }
  }
  return filled;
}

cv::Mat WindowsBelowNoise(const cv::Mat& image, const NoiseProfile& noise,
                          int window, double kappa, double edge_aware_sigma) {
  Require(image.type() == CV_32FC3, "WindowsBelowNoise: CV_32FC3 images");
  if (edge_aware_sigma > 0)
    return EdgeAwareBelowNoise(image, noise, window, kappa, edge_aware_sigma);
  const cv::Size box(window, window);
  cv::Mat mean, mean_sq;
  cv::boxFilter(image, mean, CV_32F, box, cv::Point(-1, -1), true,
                cv::BORDER_REFLECT);
  cv::boxFilter(image.mul(image), mean_sq, CV_32F, box, cv::Point(-1, -1), true,
                cv::BORDER_REFLECT);
  const double n = static_cast<double>(window) * window;
  cv::Mat out(image.size(), CV_8U, cv::Scalar(0));
  for (int y = 0; y < image.rows; ++y) {
    const cv::Vec3f* m = mean.ptr<cv::Vec3f>(y);
    const cv::Vec3f* q = mean_sq.ptr<cv::Vec3f>(y);
    uchar* o = out.ptr<uchar>(y);
    for (int x = 0; x < image.cols; ++x) {
      double ss = 0;
      for (int c = 0; c < 3; ++c)
        ss += std::max(0.0, double(q[x][c]) - double(m[x][c]) * m[x][c]) * n;
      const double sigma = noise.Sigma((m[x][0] + m[x][1] + m[x][2]) / 3.0);
      const double r = WindowReliability(ss, sigma * sigma, 3, n, n);
      if (r < kappa) o[x] = 255;
    }
  }
  return out;
}

}  // namespace wild_mvs
