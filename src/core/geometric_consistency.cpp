// Copyright wild_mvs authors.
#include "wild_mvs/core/geometric_consistency.h"

#include <algorithm>
#include <cmath>

#include "wild_mvs/core/error.h"

namespace wild_mvs {

void GeometricConsistencyOptions::Check() const {
  Require(min_consistent >= 1 && min_consistent <= 32,
          "consistency.min_consistent = ", min_consistent,
          " must be in [1, 32]");
  Require(max_reprojection_px > 0 && max_reprojection_px <= 100,
          "consistency.max_reprojection_px = ", max_reprojection_px,
          " must be in (0, 100]");
  Require(max_relative_depth > 0 && max_relative_depth < 1,
          "consistency.max_relative_depth = ", max_relative_depth,
          " must be in (0, 1)");
  Require(search_px >= 0 && search_px <= 3,
          "consistency.search_px = ", search_px, " must be in [0, 3]");
  Require(free_space_margin >= 0 && free_space_margin < 1,
          "consistency.free_space_margin = ", free_space_margin,
          " must be in [0, 1)");
}

void RegisterOptions(OptionRegistry* registry, const std::string& prefix,
                     GeometricConsistencyOptions* o) {
  auto key = [&prefix](const char* name) {
    return OptionRegistry::Join(prefix, name);
  };
  registry
      ->Add(key("min_consistent"), &o->min_consistent,
            "neighbour maps that must confirm a sample")
      .Min(1)
      .Max(32);
  registry
      ->Add(key("max_reprojection_px"), &o->max_reprojection_px,
            "forward-backward reprojection distance allowed, pixels of R")
      .Above(0)
      .Max(100);
  registry
      ->Add(key("max_relative_depth"), &o->max_relative_depth,
            "relative depth difference allowed")
      .Above(0)
      .Below(1);
  registry
      ->Add(key("free_space_margin"), &o->free_space_margin,
            "count a neighbour whose depth lies beyond the sample by more "
            "than this relative margin as a violation (it sees through the "
            "sample); a sample needs at least as many confirmations as "
            "violations")
      .Min(0)
      .Below(1);
}

namespace {

// Where a round trip can come from. Any Y that round-trips to (p, z) lies
// within `reach` of X (world units): in R's frame, with x, y the normalised
// coordinates of p, e = r / f the reprojection tolerance r in normalised
// units and m the relative depth tolerance, Y_R - X_R = (z'x' - zx, z'y' -
// zy, z' - z) with |z' - z| <= m z and |x' - x| <= e_x, so each coordinate
// is at most m z (|x| + e_x) + z e_x (likewise y) and m z, and the
// distance at most their sum. A neighbour's depth differs from X's depth in
// that neighbour by at most |Y - X| (the depth is a unit projection), so a
// neighbour pixel whose depth differs by more cannot round-trip: the test
// skips it without reprojecting (twice the bound, far beyond rounding;
// the verdicts are exactly those of reprojecting every pixel).
struct RoundTripTarget {
  RoundTripTarget(const Camera& rc, const Eigen::Vector2d& p, double z,
                  const GeometricConsistencyOptions& o)
      : p(p), z(z), X(rc.Backproject(p, z)) {
    const double ex = o.max_reprojection_px / rc.fx;
    const double ey = o.max_reprojection_px / rc.fy;
    const double x = std::abs((p.x() - rc.cx) / rc.fx);
    const double y = std::abs((p.y() - rc.cy) / rc.fy);
    const double m = o.max_relative_depth;
    reach = z * (m * (1 + x + y + ex + ey) + ex + ey);
  }
  Eigen::Vector2d p;  // R's pixel centre
  double z;           // the sample's depth in R
  Eigen::Vector3d X;  // the sample's point
  double reach;       // |Y - X| of any Y that round-trips
};

// Whether the depth of pixel (qx, qy) of neighbour map `nb`, reprojected
// into R, lands within the tolerances of (p, z). zx: X's depth in nb.
bool RoundTrips(const Camera& rc, const DepthMap& nb, int qx, int qy,
                const RoundTripTarget& t, double zx,
                const GeometricConsistencyOptions& o) {
  if (qx < 0 || qy < 0 || qx >= nb.width() || qy >= nb.height()) return false;
  const float zv = nb.depth.at<float>(qy, qx);
  if (!(zv > 0)) return false;
  if (std::abs(zv - zx) > 2 * t.reach) return false;
  const Eigen::Vector3d Y =
      nb.camera.Backproject(Eigen::Vector2d(qx + 0.5, qy + 0.5), zv);
  Eigen::Vector2d pb;
  if (!rc.Project(Y, &pb)) return false;
  const double zb = rc.Depth(Y);
  return (pb - t.p).norm() <= o.max_reprojection_px &&
         std::abs(zb - t.z) <= o.max_relative_depth * t.z;
}

enum class Verdict { kNone, kConfirms, kViolates };

// What neighbour map `nb` says of the sample t.X of ref: it confirms it
// when the pixel of nb containing its projection q (or, with search_px > 0,
// any pixel of nb within search_px of it) round-trips; else it violates it
// when nb's depth at q lies beyond X by more than the margin.
Verdict Judge(const Camera& rc, const DepthMap& nb, const RoundTripTarget& t,
              const GeometricConsistencyOptions& o) {
  Eigen::Vector2d q;
  if (!nb.camera.Project(t.X, &q)) return Verdict::kNone;
  const int qx = static_cast<int>(std::floor(q.x()));
  const int qy = static_cast<int>(std::floor(q.y()));
  const double zx = nb.camera.Depth(t.X);
  if (RoundTrips(rc, nb, qx, qy, t, zx, o)) return Verdict::kConfirms;
  for (int dy = -o.search_px; dy <= o.search_px; ++dy)
    for (int dx = -o.search_px; dx <= o.search_px; ++dx)
      if ((dx != 0 || dy != 0) &&
          RoundTrips(rc, nb, qx + dx, qy + dy, t, zx, o))
        return Verdict::kConfirms;
  if (qx >= 0 && qy >= 0 && qx < nb.width() && qy < nb.height()) {
    const float zv = nb.depth.at<float>(qy, qx);
    if (zv > 0 && zv > (1 + o.free_space_margin) * zx)
      return Verdict::kViolates;
  }
  return Verdict::kNone;
}

}  // namespace

cv::Mat CountConsistentViews(const DepthMap& ref,
                             const std::vector<const DepthMap*>& neighbors,
                             const GeometricConsistencyOptions& options,
                             cv::Mat* violations) {
  options.Check();
  Require(!ref.empty() && ref.depth.type() == CV_32F,
          "CountConsistentViews: empty reference depth map");
  cv::Mat count = cv::Mat::zeros(ref.height(), ref.width(), CV_8U);
  cv::Mat seen_through = cv::Mat::zeros(ref.height(), ref.width(), CV_8U);
  for (int y = 0; y < ref.height(); ++y) {
    const float* d = ref.depth.ptr<float>(y);
    uint8_t* c = count.ptr<uint8_t>(y);
    uint8_t* v = seen_through.ptr<uint8_t>(y);
    for (int x = 0; x < ref.width(); ++x) {
      if (!(d[x] > 0)) continue;
      const RoundTripTarget target(
          ref.camera, Eigen::Vector2d(x + 0.5, y + 0.5), d[x], options);
      int n = 0, m = 0;
      for (const DepthMap* nb : neighbors) {
        if (!nb || nb->empty()) continue;
        const Verdict j = Judge(ref.camera, *nb, target, options);
        n += j == Verdict::kConfirms;
        m += j == Verdict::kViolates;
      }
      c[x] = static_cast<uint8_t>(std::min(n, 255));
      v[x] = static_cast<uint8_t>(std::min(m, 255));
    }
  }
  if (violations) *violations = seen_through;
  return count;
}

void FilterByConsistency(DepthMap* ref,
                         const std::vector<const DepthMap*>& neighbors,
                         const GeometricConsistencyOptions& options,
                         ConsistencyStats* stats) {
  Require(ref != nullptr, "FilterByConsistency: null map");
  ConsistencyStats st;
  st.samples = ref->empty() ? 0 : ref->CountValid();
  st.kept = st.samples;
  bool any = false;
  for (const DepthMap* nb : neighbors) any = any || (nb && !nb->empty());
  if (any && st.samples > 0) {
    cv::Mat violations;
    const cv::Mat count =
        CountConsistentViews(*ref, neighbors, options, &violations);
    st.kept = 0;
    for (int y = 0; y < ref->height(); ++y) {
      const uint8_t* c = count.ptr<uint8_t>(y);
      const uint8_t* v = violations.ptr<uint8_t>(y);
      float* d = ref->depth.ptr<float>(y);
      cv::Vec3f* n = ref->normal.ptr<cv::Vec3f>(y);
      float* f = ref->confidence.ptr<float>(y);
      for (int x = 0; x < ref->width(); ++x) {
        if (!(d[x] > 0)) continue;
        if (c[x] >= options.min_consistent && v[x] <= c[x]) {
          ++st.kept;
          continue;
        }
        d[x] = 0;
        n[x] = cv::Vec3f(0, 0, 0);
        f[x] = 0;
      }
    }
  }
  if (stats) *stats = st;
}

}  // namespace wild_mvs
