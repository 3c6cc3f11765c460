// Copyright wild_mvs authors.
#include "wild_mvs/io/render.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <limits>
#include <opencv2/imgproc.hpp>
#include <vector>

#include "wild_mvs/core/error.h"
#include "wild_mvs/core/metrics.h"

namespace wild_mvs {

void RenderOptions::Check() const {
  Require(std::isfinite(point_size) && point_size >= 0,
          "RenderOptions: point_size must be >= 0 (got ", point_size, ")");
  Require(min_splat_px > 0 && max_splat_px >= min_splat_px &&
              std::isfinite(max_splat_px),
          "RenderOptions: need 0 < min_splat_px <= max_splat_px (got ",
          min_splat_px, ", ", max_splat_px, ")");
  Require(light_dir_cam.allFinite() && light_dir_cam.norm() > 0,
          "RenderOptions: light_dir_cam must be a non-zero vector");
  Require(ambient >= 0 && ambient <= 1,
          "RenderOptions: ambient must be in [0, 1] (got ", ambient, ")");
  Require(albedo >= 0 && albedo <= 1,
          "RenderOptions: albedo must be in [0, 1] (got ", albedo, ")");
  Require(supersample >= 1 && supersample <= 8,
          "RenderOptions: supersample must be in [1, 8] (got ", supersample,
          ")");
  Require(background.allFinite() && background.minCoeff() >= 0 &&
              background.maxCoeff() <= 1,
          "RenderOptions: background must be RGB in [0, 1]");
}

namespace {

// Every k-th point so that at most `max_count` remain.
std::vector<Eigen::Vector3f> Subsample(const std::vector<Eigen::Vector3f>& p,
                                       size_t max_count) {
  if (p.size() <= max_count) return p;
  const size_t step = (p.size() + max_count - 1) / max_count;
  std::vector<Eigen::Vector3f> out;
  out.reserve(p.size() / step + 1);
  for (size_t i = 0; i < p.size(); i += step) out.push_back(p[i]);
  return out;
}

double Quantile(std::vector<double> v, double q) {
  if (v.empty()) return 0;
  const size_t k = std::min(
      v.size() - 1, static_cast<size_t>(q * static_cast<double>(v.size())));
  std::nth_element(v.begin(), v.begin() + k, v.end());
  return v[k];
}

// Median distance to the nearest other point, over a subsample.
double MedianSpacing(const PointCloud& cloud) {
  if (cloud.size() < 2) return 0;
  const size_t step = std::max<size_t>(1, cloud.size() / 4000);
  PointCloud query, reference;
  for (size_t i = 0; i < cloud.size(); ++i) {
    if (i % step == 0 && i + 1 < cloud.size() && (i / step) % 2 == 0) {
      query.xyz.push_back(cloud.xyz[i]);
    } else {
      reference.xyz.push_back(cloud.xyz[i]);
    }
  }
  if (query.empty() || reference.empty()) return 0;
  std::vector<double> d = NearestDistances(query, reference, 1);
  return Quantile(std::move(d), 0.5);
}

struct Canvas {
  int width, height;
  std::vector<float> z;            // camera depth, +inf = empty
  std::vector<Eigen::Vector3f> c;  // RGB in [0, 1]
  Canvas(int w, int h)
      : width(w),
        height(h),
        z(static_cast<size_t>(w) * h, std::numeric_limits<float>::infinity()),
        c(static_cast<size_t>(w) * h, Eigen::Vector3f::Zero()) {}
  void Put(int x, int y, float depth, const Eigen::Vector3f& rgb) {
    const size_t i = static_cast<size_t>(y) * width + x;
    if (depth < z[i]) {
      z[i] = depth;
      c[i] = rgb;
    }
  }
  // BGR 8-bit, shrunk by `factor` (area average).
  cv::Mat ToImage(const Eigen::Vector3d& background, int factor) const {
    cv::Mat img(height, width, CV_32FC3);
    for (int y = 0; y < height; ++y) {
      cv::Vec3f* row = img.ptr<cv::Vec3f>(y);
      for (int x = 0; x < width; ++x) {
        const size_t i = static_cast<size_t>(y) * width + x;
        const Eigen::Vector3f rgb =
            std::isfinite(z[i]) ? c[i] : background.cast<float>();
        row[x] = cv::Vec3f(rgb.z(), rgb.y(), rgb.x());
      }
    }
    if (factor > 1) {
      cv::Mat small;
      cv::resize(img, small, cv::Size(width / factor, height / factor), 0, 0,
                 cv::INTER_AREA);
      img = small;
    }
    cv::Mat out;
    img.convertTo(out, CV_8UC3, 255.0);
    return out;
  }
};

// Lambert shading of a camera-frame normal seen at camera-frame point Xc.
float Shade(Eigen::Vector3d n, const Eigen::Vector3d& Xc,
            const Eigen::Vector3d& to_light, double ambient) {
  if (n.dot(Xc) > 0) n = -n;  // two-sided: face the viewer
  return static_cast<float>(ambient +
                            (1 - ambient) * std::max(0.0, n.dot(to_light)));
}

Camera Supersampled(const Camera& camera, int factor) {
  Require(camera.width > 0 && camera.height > 0,
          "render: camera has no image size");
  return factor > 1
             ? camera.Resized(camera.width * factor, camera.height * factor)
             : camera;
}

}  // namespace

Camera FitCameraToPoints(const std::vector<Eigen::Vector3f>& points,
                         const Eigen::Matrix3d& orientation, int width,
                         int height, double hfov_deg, double margin) {
  Require(!points.empty(), "FitCameraToPoints: no points");
  Require(width > 0 && height > 0, "FitCameraToPoints: bad image size ", width,
          "x", height);
  Require(hfov_deg > 0 && hfov_deg < 170,
          "FitCameraToPoints: hfov_deg must be in (0, 170)");
  Require(margin >= 0 && margin < 0.5,
          "FitCameraToPoints: margin must be in [0, 0.5)");
  const std::vector<Eigen::Vector3f> p = Subsample(points, 200000);
  // Robust box: 2nd..98th percentile per axis; its centre is the target.
  Eigen::Vector3d lo, hi;
  for (int a = 0; a < 3; ++a) {
    std::vector<double> v(p.size());
    for (size_t i = 0; i < p.size(); ++i) v[i] = p[i][a];
    lo[a] = Quantile(v, 0.02);
    hi[a] = Quantile(v, 0.98);
  }
  const Eigen::Vector3d centre = 0.5 * (lo + hi);
  Camera cam;
  cam.width = width;
  cam.height = height;
  cam.fx = cam.fy = 0.5 * width / std::tan(0.5 * hfov_deg * M_PI / 180.0);
  cam.cx = 0.5 * width;
  cam.cy = 0.5 * height;
  cam.R = NearestRotation(orientation);
  const double tx = (1 - 2 * margin) * 0.5 * width / cam.fx;
  const double ty = (1 - 2 * margin) * 0.5 * height / cam.fy;
  // Distance d along the axis such that point q (camera axes, relative to
  // the centre) projects inside: |q.x| <= tx (q.z + d), same for y.
  std::vector<double> need;
  need.reserve(p.size());
  double extent = 1e-9;
  for (const Eigen::Vector3f& x : p) {
    if (((x.cast<double>() - lo).array() < 0).any() ||
        ((x.cast<double>() - hi).array() > 0).any()) {
      continue;  // outside the robust box
    }
    const Eigen::Vector3d q = cam.R * (x.cast<double>() - centre);
    need.push_back(std::max(std::abs(q.x()) / tx, std::abs(q.y()) / ty) -
                   q.z());
    extent = std::max(extent, q.norm());
  }
  double d = need.empty() ? extent : Quantile(need, 0.99);
  d = std::max(d, 1e-3 * extent);
  const Eigen::Vector3d C = centre - d * cam.R.row(2).transpose();
  cam.t = -cam.R * C;
  return cam;
}

Eigen::Matrix3d AutoViewRotation(const PointCloud& cloud,
                                 const Eigen::Vector3d& up_hint) {
  Require(!cloud.empty(), "AutoViewRotation: empty cloud");
  const std::vector<Eigen::Vector3f> p = Subsample(cloud.xyz, 200000);
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (const auto& x : p) mean += x.cast<double>();
  mean /= static_cast<double>(p.size());
  Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
  for (const auto& x : p) {
    const Eigen::Vector3d d = x.cast<double>() - mean;
    cov += d * d.transpose();
  }
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(cov);
  // Eigenvalues ascending: column 0 = least spread, 2 = largest.
  Eigen::Vector3d axis = eig.eigenvectors().col(0).normalized();
  if (cloud.has_normal()) {
    Eigen::Vector3d mean_n = Eigen::Vector3d::Zero();
    for (const auto& n : cloud.normal) mean_n += n.cast<double>();
    if (mean_n.dot(axis) > 0) axis = -axis;  // look against the normals
  } else if (axis.z() < 0) {
    axis = -axis;
  }
  Eigen::Vector3d up = up_hint - up_hint.dot(axis) * axis;
  if (!(up.norm() > 1e-6 * std::max(1.0, up_hint.norm()))) {
    up = eig.eigenvectors().col(2);
    up -= up.dot(axis) * axis;
  }
  up.normalize();
  // Camera axes in world coordinates: z = axis, y = -up, x = y cross z.
  const Eigen::Vector3d y = -up;
  const Eigen::Vector3d x = y.cross(axis);
  Eigen::Matrix3d R;
  R.row(0) = x.transpose();
  R.row(1) = y.transpose();
  R.row(2) = axis.transpose();
  return R;
}

cv::Mat RenderPointCloud(const PointCloud& cloud, const Camera& camera,
                         const RenderOptions& options) {
  options.Check();
  const int s = options.supersample;
  const Camera cam = Supersampled(camera, s);
  Canvas canvas(cam.width, cam.height);
  double size = options.point_size;
  if (size <= 0) size = 1.5 * MedianSpacing(cloud);
  const Eigen::Vector3d to_light = -options.light_dir_cam.normalized();
  const bool colour = cloud.has_rgb();
  const double focal = 0.5 * (cam.fx + cam.fy);
  for (size_t i = 0; i < cloud.size(); ++i) {
    const Eigen::Vector3d Xc = cam.WorldToCamera(cloud.xyz[i].cast<double>());
    if (!(Xc.z() > 0)) continue;
    const Eigen::Vector2d px = cam.ProjectCam(Xc);
    const double side =
        std::clamp(focal * size / Xc.z(), options.min_splat_px * s,
                   options.max_splat_px * s);
    const int x0 = static_cast<int>(std::floor(px.x() - 0.5 * side + 0.5));
    const int y0 = static_cast<int>(std::floor(px.y() - 0.5 * side + 0.5));
    const int n = std::max(1, static_cast<int>(std::lround(side)));
    if (x0 + n <= 0 || y0 + n <= 0 || x0 >= cam.width || y0 >= cam.height) {
      continue;
    }
    float shade = 1.0f;
    if (cloud.has_normal() && (!colour || options.shade_colors)) {
      shade = Shade(cam.R * cloud.normal[i].cast<double>(), Xc, to_light,
                    options.ambient);
    }
    const Eigen::Vector3f rgb =
        colour ? Eigen::Vector3f(cloud.rgb[i] * shade)
               : Eigen::Vector3f::Constant(static_cast<float>(options.albedo) *
                                           shade);
    const float z = static_cast<float>(Xc.z());
    for (int y = std::max(0, y0); y < std::min(cam.height, y0 + n); ++y) {
      for (int x = std::max(0, x0); x < std::min(cam.width, x0 + n); ++x) {
        canvas.Put(x, y, z, rgb);
      }
    }
  }
  return canvas.ToImage(options.background, s);
}

cv::Mat RenderMesh(const Mesh& mesh, const Camera& camera,
                   const RenderOptions& options) {
  options.Check();
  const int s = options.supersample;
  const Camera cam = Supersampled(camera, s);
  Canvas canvas(cam.width, cam.height);
  const Eigen::Vector3d to_light = -options.light_dir_cam.normalized();
  const PointCloud& v = mesh.vertices;
  const bool colour = options.mesh_vertex_colors && v.has_rgb();
  const int nv = static_cast<int>(v.size());
  std::vector<Eigen::Vector3d> Xc(v.size());
  for (size_t i = 0; i < v.size(); ++i) {
    Xc[i] = cam.WorldToCamera(v.xyz[i].cast<double>());
  }
  for (const Eigen::Vector3i& f : mesh.faces) {
    if ((f.array() < 0).any() || (f.array() >= nv).any()) {
      throw Error(Msg("RenderMesh: face index out of range (", f.transpose(),
                      ", ", nv, " vertices)"));
    }
    const Eigen::Vector3d& A = Xc[f[0]];
    const Eigen::Vector3d& B = Xc[f[1]];
    const Eigen::Vector3d& C = Xc[f[2]];
    if (!(A.z() > 0 && B.z() > 0 && C.z() > 0)) continue;  // no clipping
    const Eigen::Vector3d n = (B - A).cross(C - A);
    if (!(n.norm() > 0)) continue;
    const float shade =
        Shade(n.normalized(), (A + B + C) / 3.0, to_light, options.ambient);
    const Eigen::Vector3f rgb =
        colour ? Eigen::Vector3f((v.rgb[f[0]] + v.rgb[f[1]] + v.rgb[f[2]]) /
                                 3.0f * shade)
               : Eigen::Vector3f::Constant(static_cast<float>(options.albedo) *
                                           shade);
    const Eigen::Vector2d a = cam.ProjectCam(A), b = cam.ProjectCam(B),
                          c = cam.ProjectCam(C);
    const double area = (b - a).x() * (c - a).y() - (b - a).y() * (c - a).x();
    if (!(std::abs(area) > 1e-12)) continue;
    const int xmin = std::max(
        0, static_cast<int>(std::floor(std::min({a.x(), b.x(), c.x()}))));
    const int xmax =
        std::min(cam.width - 1,
                 static_cast<int>(std::ceil(std::max({a.x(), b.x(), c.x()}))));
    const int ymin = std::max(
        0, static_cast<int>(std::floor(std::min({a.y(), b.y(), c.y()}))));
    const int ymax =
        std::min(cam.height - 1,
                 static_cast<int>(std::ceil(std::max({a.y(), b.y(), c.y()}))));
    const double inv_za = 1 / A.z(), inv_zb = 1 / B.z(), inv_zc = 1 / C.z();
    for (int y = ymin; y <= ymax; ++y) {
      for (int x = xmin; x <= xmax; ++x) {
        const Eigen::Vector2d p(x + 0.5, y + 0.5);
        // Barycentric weights from signed sub-areas.
        const double wa =
            ((b - p).x() * (c - p).y() - (b - p).y() * (c - p).x()) / area;
        const double wb =
            ((c - p).x() * (a - p).y() - (c - p).y() * (a - p).x()) / area;
        const double wc = 1 - wa - wb;
        if (wa < 0 || wb < 0 || wc < 0) continue;
        const double inv_z = wa * inv_za + wb * inv_zb + wc * inv_zc;
        canvas.Put(x, y, static_cast<float>(1 / inv_z), rgb);
      }
    }
  }
  return canvas.ToImage(options.background, s);
}

}  // namespace wild_mvs
