// Copyright wild_mvs authors. The patch (surface) model of the paper's
// stereo matching (section 6.2, docs/ALGORITHM.md section 4) and the sampling
// of the neighbour images under it.
//
// The n x n window centred at pixel (s, t) of the reference view R is a
// surface whose point at window offset (i, j) is
//     X(i, j) = o_R + r(s + i, t + j) * (h + i * h_s + j * h_t),
// r the unit viewing ray in world coordinates, h the distance along the ray
// (not the depth z; conversions below). Its projection into a neighbour V is
//     q = b_V + (h + i h_s + j h_t) * A_V (u, v, 1)^T / |K_R^-1 (u, v, 1)|,
// with A_V = K_V R_V R_R^T K_R^-1 and b_V = P_V (o_R, 1): both constant per
// (R, V) pair, so a window maps to a view with a few multiply-adds per pixel.
#pragma once

#include <Eigen/Core>
#include <cmath>
#include <vector>

#include "wild_mvs/core/ablation.h"
#include "wild_mvs/core/camera.h"
#include "wild_mvs/core/image_noise.h"

namespace wild_mvs {

constexpr int kMaxWindow = 9;  // n <= 9
constexpr int kMaxWindowPixels = kMaxWindow * kMaxWindow;
constexpr int kMaxNeighbors = 32;  // |N| <= 32
constexpr int kMaxActive = 8;      // m <= 8

// An image as matching sees it: contiguous row-major float, channels
// interleaved (1 = grey, 3 = RGB). Not owning.
struct MatchImage {
  const float* data = nullptr;
  int width = 0, height = 0, channels = 3;
};

// One neighbour V of the reference view, at its working resolution.
struct PatchView {
  int scene_view = -1;
  MatchImage image;
  NoiseProfile noise;  // image's noise (zero = none known)
  Eigen::Matrix3d A = Eigen::Matrix3d::Zero();  // see the file comment
  Eigen::Vector3d b = Eigen::Vector3d::Zero();
  Eigen::Vector3d epipole = Eigen::Vector3d::Zero();  // V's centre in R
  double global_score = 1;                            // g_R(V)
};

// Everything the matcher needs for one reference view.
struct PatchContext {
  Camera ref_camera;  // R at its working resolution
  MatchImage ref_image;
  NoiseProfile ref_noise;        // ref_image's noise (zero = none known)
  std::vector<PatchView> views;  // the neighbourhood N (<= kMaxNeighbors)
  int window = 5;                // n (odd)
  // Parts of the method turned off (local view selection, normal, colour
  // scales, photometric offset); all on by default.
  AblationOptions ablation;

  // Adds neighbour V with camera `cam` (at the resolution of `image`).
  void AddView(int scene_view, const Camera& cam, const MatchImage& image,
               double global_score);
};

// Unit ray through pixel coordinates (u, v) in R's camera frame.
inline Eigen::Vector3d RayAt(const Camera& c, double u, double v) {
  return Eigen::Vector3d((u - c.cx) / c.fx, (v - c.cy) / c.fy, 1.0)
      .normalized();
}

// Window parameters of a plane through the point at depth z of pixel centre
// (s + .5, t + .5) with camera-frame normal n: returns h and sets *hs, *ht
// (symmetric differences of the plane's h over one pixel).
double PlaneToPatch(const Camera& c, int s, int t, double z,
                    const Eigen::Vector3d& n, double* hs, double* ht);

// Camera-frame unit normal of the window surface (h, hs, ht) at pixel (s,
// t), oriented towards the camera.
Eigen::Vector3d PatchNormal(const Camera& c, int s, int t, double h, double hs,
                            double ht);

// Depth of a plane (point X0 with normal n, camera frame) along the ray of
// pixel centre (s + .5, t + .5), or `fallback` when the ray is (nearly)
// parallel to the plane or hits it behind the camera.
double PlaneDepthAt(const Camera& c, int s, int t, const Eigen::Vector3d& X0,
                    const Eigen::Vector3d& n, double fallback);

// Bilinear sample (interleaved channels) at continuous pixel coordinates
// (x, y) (pixel centres at +0.5). The caller guarantees
// 0.5 <= x < width - 0.5 and 0.5 <= y < height - 0.5 (InSampleRange).
inline bool InSampleRange(const MatchImage& im, double x, double y) {
  return x >= 0.5 && y >= 0.5 && x < im.width - 0.5 && y < im.height - 0.5;
}

// Samples `channels` values at (x, y) into out[c * stride]; when gx/gy are
// non-null also the image gradient (derivative of the bilinear interpolant).
inline void SampleBilinear(const MatchImage& im, double x, double y, float* out,
                           float* gx, float* gy, int stride) {
  const double fxd = x - 0.5, fyd = y - 0.5;
  int x0 = static_cast<int>(fxd), y0 = static_cast<int>(fyd);
  if (x0 > im.width - 2) x0 = im.width - 2;
  if (y0 > im.height - 2) y0 = im.height - 2;
  const float fx = static_cast<float>(fxd - x0),
              fy = static_cast<float>(fyd - y0);
  const int ch = im.channels;
  const float* p00 = im.data + (static_cast<size_t>(y0) * im.width + x0) * ch;
  const float* p10 = p00 + ch;
  const float* p01 = p00 + static_cast<size_t>(im.width) * ch;
  const float* p11 = p01 + ch;
  const float w00 = (1 - fx) * (1 - fy), w10 = fx * (1 - fy),
              w01 = (1 - fx) * fy, w11 = fx * fy;
  for (int c = 0; c < ch; ++c) {
    out[c * stride] = w00 * p00[c] + w10 * p10[c] + w01 * p01[c] + w11 * p11[c];
    if (gx) {
      gx[c * stride] = (1 - fy) * (p10[c] - p00[c]) + fy * (p11[c] - p01[c]);
      gy[c * stride] = (1 - fx) * (p01[c] - p00[c]) + fx * (p11[c] - p10[c]);
    }
  }
}

}  // namespace wild_mvs
