// Copyright wild_mvs authors.
#include "wild_mvs/core/planar_prior.h"

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>
#include <vector>

#include "wild_mvs/core/region_growing.h"

namespace wild_mvs {
namespace {

constexpr int kVertexCell = 16;   // pixels per side of a vertex cell
constexpr int kTestSamples = 48;  // pixels of a triangle scored, at most
constexpr double kShiftPx = 3.0;  // the shifted planes move this far in N
constexpr double kSigmas = 3.0;   // standard errors the plane must win by
constexpr int kMinTestSamples = 8;
// A vertex with a normal of its own (a match) must agree with the plane
// within this angle: a triangle across a depth edge tilts towards the rays.
constexpr double kMaxVertexNormalDeg = 60;

struct Vertex {
  int x, y;
  Eigen::Vector3d X;  // camera frame
  Eigen::Vector3d n;  // the match's normal (camera frame); zero = none
};

struct Triangle {
  int v[3];
  Eigen::Vector3d X0, n;  // the plane: a point and its unit normal (facing R)
  int x0, y0, x1, y1;     // bounding box, inclusive
};

// Barycentric inside test of pixel centre (x + .5, y + .5).
bool Inside(const Vertex* p[3], int x, int y) {
  const double px = x + 0.5, py = y + 0.5;
  auto edge = [&](const Vertex& a, const Vertex& b) {
    return (b.x - a.x) * (py - (a.y + 0.5)) - (b.y - a.y) * (px - (a.x + 0.5));
  };
  const double e0 = edge(*p[0], *p[1]), e1 = edge(*p[1], *p[2]),
               e2 = edge(*p[2], *p[0]);
  return (e0 >= 0 && e1 >= 0 && e2 >= 0) || (e0 <= 0 && e1 <= 0 && e2 <= 0);
}

std::vector<Vertex> PickVertices(const DepthMap& map,
                                 const std::vector<Seed>& points) {
  const Camera& cam = map.camera;
  std::vector<Vertex> out;
  const int gw = (map.width() + kVertexCell - 1) / kVertexCell;
  const int gh = (map.height() + kVertexCell - 1) / kVertexCell;
  std::vector<int> point_of(static_cast<size_t>(gw) * gh, -1);
  for (size_t i = 0; i < points.size(); ++i) {
    const Seed& p = points[i];
    if (p.x < 0 || p.y < 0 || p.x >= map.width() || p.y >= map.height() ||
        !(p.depth > 0))
      continue;
    int& slot = point_of[(p.y / kVertexCell) * gw + p.x / kVertexCell];
    if (slot < 0) slot = static_cast<int>(i);
  }
  for (int cy = 0; cy < map.height(); cy += kVertexCell) {
    for (int cx = 0; cx < map.width(); cx += kVertexCell) {
      float best = 0;
      int bx = -1, by = -1;
      for (int y = cy; y < std::min(cy + kVertexCell, map.height()); ++y) {
        const float* d = map.depth.ptr<float>(y);
        const float* c = map.confidence.ptr<float>(y);
        for (int x = cx; x < std::min(cx + kVertexCell, map.width()); ++x)
          if (d[x] > 0 && c[x] > best) {
            best = c[x];
            bx = x;
            by = y;
          }
      }
      double z = 0;
      Eigen::Vector3d n = Eigen::Vector3d::Zero();
      if (bx >= 0) {
        z = map.depth.at<float>(by, bx);
        const cv::Vec3f& m = map.normal.at<cv::Vec3f>(by, bx);
        n = Eigen::Vector3d(m[0], m[1], m[2]);
      } else {
        const int i = point_of[(cy / kVertexCell) * gw + cx / kVertexCell];
        if (i < 0) continue;
        bx = points[i].x;
        by = points[i].y;
        z = points[i].depth;
      }
      out.push_back(Vertex{
          bx, by, cam.BackprojectCam(Eigen::Vector2d(bx + 0.5, by + 0.5), z),
          n});
    }
  }
  return out;
}

std::vector<Triangle> Triangulate(const std::vector<Vertex>& vs,
                                  const Camera& cam) {
  std::vector<Triangle> out;
  if (vs.size() < 3) return out;
  cv::Subdiv2D subdiv(cv::Rect(0, 0, cam.width, cam.height));
  std::vector<int> id_of;  // Subdiv2D vertex id -> index into vs
  for (size_t i = 0; i < vs.size(); ++i) {
    const int id = subdiv.insert(cv::Point2f(vs[i].x + 0.5f, vs[i].y + 0.5f));
    if (id >= static_cast<int>(id_of.size())) id_of.resize(id + 1, -1);
    id_of[id] = static_cast<int>(i);
  }
  std::vector<cv::Vec6f> tris;
  subdiv.getTriangleList(tris);
  for (const cv::Vec6f& t : tris) {
    Triangle tri;
    bool ok = true;
    for (int k = 0; k < 3 && ok; ++k) {
      int edge = 0, vertex = 0;
      const int r =
          subdiv.locate(cv::Point2f(t[2 * k], t[2 * k + 1]), edge, vertex);
      ok = r == cv::Subdiv2D::PTLOC_VERTEX && vertex >= 0 &&
           vertex < static_cast<int>(id_of.size()) && id_of[vertex] >= 0;
      if (ok) tri.v[k] = id_of[vertex];
    }
    if (!ok) continue;
    const Eigen::Vector3d& A = vs[tri.v[0]].X;
    const Eigen::Vector3d& B = vs[tri.v[1]].X;
    const Eigen::Vector3d& C = vs[tri.v[2]].X;
    Eigen::Vector3d n = (B - A).cross(C - A);
    if (!(n.norm() > 0)) continue;
    n.normalize();
    const Eigen::Vector3d centroid = (A + B + C) / 3.0;
    if (n.dot(centroid) > 0) n = -n;  // facing the camera
    // The plane must face R at every corner (the paper's kMinFacing).
    if (-n.dot(A.normalized()) < kMinFacing ||
        -n.dot(B.normalized()) < kMinFacing ||
        -n.dot(C.normalized()) < kMinFacing)
      continue;
    const double min_cos = std::cos(kMaxVertexNormalDeg * M_PI / 180);
    bool agree = true;
    for (int k = 0; k < 3; ++k) {
      const Eigen::Vector3d& vn = vs[tri.v[k]].n;
      const double len = vn.norm();
      if (len > 0 && vn.dot(n) < min_cos * len) agree = false;
    }
    if (!agree) continue;
    tri.X0 = centroid;
    tri.n = n;
    tri.x0 = std::min({vs[tri.v[0]].x, vs[tri.v[1]].x, vs[tri.v[2]].x});
    tri.x1 = std::max({vs[tri.v[0]].x, vs[tri.v[1]].x, vs[tri.v[2]].x});
    tri.y0 = std::min({vs[tri.v[0]].y, vs[tri.v[1]].y, vs[tri.v[2]].y});
    tri.y1 = std::max({vs[tri.v[0]].y, vs[tri.v[1]].y, vs[tri.v[2]].y});
    out.push_back(tri);
  }
  return out;
}

// The relative depth change of point Xc (R's camera frame) that moves its
// projection kShiftPx pixels in the median view of N, in [0.005, 0.1].
double ShiftFor(const PatchContext& ctx, const Eigen::Vector3d& Xc) {
  const Camera& c = ctx.ref_camera;
  const Eigen::Vector3d p(c.fx * Xc.x() / Xc.z() + c.cx,
                          c.fy * Xc.y() / Xc.z() + c.cy, 1.0);
  std::vector<double> px_per_percent;
  for (const PatchView& v : ctx.views) {
    const Eigen::Vector3d q0 = v.b + Xc.z() * (v.A * p);
    const Eigen::Vector3d q1 = v.b + 1.01 * Xc.z() * (v.A * p);
    if (!(q0.z() > 0) || !(q1.z() > 0)) continue;
    px_per_percent.push_back(
        (q1.head<2>() / q1.z() - q0.head<2>() / q0.z()).norm());
  }
  if (px_per_percent.empty()) return 0.03;
  std::nth_element(px_per_percent.begin(),
                   px_per_percent.begin() + px_per_percent.size() / 2,
                   px_per_percent.end());
  const double d = px_per_percent[px_per_percent.size() / 2];
  if (!(d > 0)) return 0.1;
  return std::clamp(0.01 * kShiftPx / d, 0.005, 0.1);
}

}  // namespace

void PlaneEvidence::Add(double on_plane, double nearer, double farther) {
  if (on_plane <= -1 || nearer <= -1 || farther <= -1) return;
  const double d = on_plane - 0.5 * (nearer + farther);
  sum_ += on_plane;
  sum_d_ += d;
  sum_d2_ += d * d;
  ++n_;
}

bool PlaneEvidence::Supports() const {
  if (n_ < kMinTestSamples) return false;
  const double mean_d = sum_d_ / n_;
  const double var = std::max(0.0, sum_d2_ / n_ - mean_d * mean_d);
  const double se = std::sqrt(var / (n_ - 1));
  return mean_d > 0 && mean_d > kSigmas * se;
}

double PlaneEvidence::MeanScore() const { return n_ > 0 ? sum_ / n_ : -1; }

void FillFromPlanarPrior(const PatchContext& context, const MpgcOptions& mpgc,
                         const LocalViewSelectionOptions& local,
                         const std::vector<Seed>& points, const cv::Mat& mask,
                         ThreadPool* pool, DepthMap* map,
                         PlanarPriorStats* stats) {
  PlanarPriorStats st;
  const Camera& cam = map->camera;
  const std::vector<Vertex> vs = PickVertices(*map, points);
  st.vertices = static_cast<int>(vs.size());
  const std::vector<Triangle> tris = Triangulate(vs, cam);

  // Each triangle's empty pixels (a pixel on a shared edge goes to the
  // first triangle that claims it, in list order, so the result does not
  // depend on threads).
  cv::Mat owner(map->height(), map->width(), CV_32S, cv::Scalar(-1));
  std::vector<std::vector<cv::Point>> pixels(tris.size());
  for (size_t i = 0; i < tris.size(); ++i) {
    const Triangle& t = tris[i];
    const Vertex* p[3] = {&vs[t.v[0]], &vs[t.v[1]], &vs[t.v[2]]};
    for (int y = t.y0; y <= t.y1; ++y) {
      const float* d = map->depth.ptr<float>(y);
      int* o = owner.ptr<int>(y);
      const uint8_t* m = mask.empty() ? nullptr : mask.ptr<uint8_t>(y);
      for (int x = t.x0; x <= t.x1; ++x) {
        if (d[x] > 0 || o[x] >= 0 || (m && !m[x]) || !Inside(p, x, y)) continue;
        o[x] = static_cast<int>(i);
        pixels[i].push_back(cv::Point(x, y));
      }
    }
  }
  std::vector<int> tested;
  for (size_t i = 0; i < tris.size(); ++i)
    if (!pixels[i].empty()) tested.push_back(static_cast<int>(i));
  st.triangles = static_cast<int>(tested.size());

  std::vector<double> keep_score(tris.size(), -2);
  st.cpu_seconds =
      RunParallel(pool, static_cast<int>(tested.size()), [&](int j) {
        const int i = tested[j];
        const Triangle& t = tris[i];
        PatchMatcher m(context, mpgc, local);
        const std::vector<cv::Point>& px = pixels[i];
        const double shift = ShiftFor(context, t.X0);
        const size_t stride = std::max<size_t>(1, px.size() / kTestSamples);
        PlaneEvidence evidence;
        for (size_t k = stride / 2; k < px.size(); k += stride) {
          const int x = px[k].x, y = px[k].y;
          if (!m.WindowInside(x, y)) continue;
          const double z = PlaneDepthAt(cam, x, y, t.X0, t.n, -1);
          if (!(z > 0)) continue;
          const double on_plane = m.PlaneScore(x, y, z, t.n, 2);
          const double nearer = m.PlaneScore(x, y, z * (1 - shift), t.n, 2);
          const double farther = m.PlaneScore(x, y, z * (1 + shift), t.n, 2);
          evidence.Add(on_plane, nearer, farther);
        }
        if (evidence.Supports()) keep_score[i] = evidence.MeanScore();
      });

  for (int i : tested) {
    if (keep_score[i] < -1) continue;
    ++st.triangles_kept;
    const Triangle& t = tris[i];
    const float conf = static_cast<float>((keep_score[i] + 1) * 0.5);
    for (const cv::Point& p : pixels[i]) {
      const double z = PlaneDepthAt(cam, p.x, p.y, t.X0, t.n, -1);
      if (!(z > 0)) continue;
      map->depth.at<float>(p) = static_cast<float>(z);
      map->normal.at<cv::Vec3f>(p) =
          cv::Vec3f(static_cast<float>(t.n.x()), static_cast<float>(t.n.y()),
                    static_cast<float>(t.n.z()));
      map->confidence.at<float>(p) = conf;
      ++st.samples_added;
    }
  }
  if (stats) *stats = st;
}

}  // namespace wild_mvs
