// Copyright wild_mvs authors.
#include "wild_mvs/core/coarse_fill.h"

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>

#include "wild_mvs/core/error.h"

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

}  // namespace

int FillFromCoarse(const DepthMap& coarse, double max_spread,
                   int interior_radius, const cv::Mat& fillable,
                   DepthMap* fine) {
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
                          int window, double kappa) {
  Require(image.type() == CV_32FC3, "WindowsBelowNoise: CV_32FC3 images");
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
