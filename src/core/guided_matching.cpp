// Copyright wild_mvs authors. Guided matching of the sparse tracker: feature
// matches of a view pair along its epipolar geometry.
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>

#include "sparse_tracker_impl.h"
#include "wild_mvs/core/triangulation.h"

namespace wild_mvs {
namespace sparse_internal {

std::vector<Match> GuidedMatches(const Camera& ca, const Features& fa,
                                 const Camera& cb, const Features& fb) {
  const int na = fa.size(), nb = fb.size();
  std::vector<Match> out;
  if (na == 0 || nb == 0) return out;
  // x_b^T F x_a = 0.
  const Eigen::Matrix3f F = FundamentalMatrix(ca, cb).cast<float>();
  const float thr = static_cast<float>(sparse_internal::kMaxEpipolarDistance);
  std::vector<float> bx(nb), by(nb);
  for (int j = 0; j < nb; ++j) {
    bx[j] = fb.xy[j].x();
    by[j] = fb.xy[j].y();
  }
  // Epipolar lines of b's features in a (F^T x_b), normalised.
  std::vector<Eigen::Vector3f> lines_in_a(nb);
  for (int j = 0; j < nb; ++j) {
    Eigen::Vector3f l = F.transpose() * Eigen::Vector3f(bx[j], by[j], 1.0f);
    const float n = l.head<2>().norm();
    lines_in_a[j] = n > 0 ? Eigen::Vector3f(l / n) : Eigen::Vector3f::Zero();
  }
  // Epipolar-compatible candidates (both directions) with their squared
  // descriptor distances.
  struct Cand {
    int i, j, d;
  };
  std::vector<Cand> cands;
  std::vector<int> band;
  band.reserve(256);
  for (int i = 0; i < na; ++i) {
    const Eigen::Vector2f& p = fa.xy[i];
    Eigen::Vector3f l = F * Eigen::Vector3f(p.x(), p.y(), 1.0f);
    const float n = l.head<2>().norm();
    if (!(n > 0)) continue;
    l /= n;
    const float la = l.x(), lb = l.y(), lc = l.z();
    band.clear();
    for (int j = 0; j < nb; ++j) {
      if (std::abs(la * bx[j] + lb * by[j] + lc) <= thr) band.push_back(j);
    }
    const uint8_t* da = fa.descriptors.ptr<uint8_t>(i);
    for (int j : band) {
      const Eigen::Vector3f& m = lines_in_a[j];
      if (!(std::abs(m.x() * p.x() + m.y() * p.y() + m.z()) <= thr)) continue;
      cands.push_back(
          {i, j,
           DescriptorDistanceSquared(da, fb.descriptors.ptr<uint8_t>(j))});
    }
  }
  // Best and second-best per feature. SIFT reports one keypoint per dominant
  // orientation, so a feature may appear twice at the same position: such a
  // twin of the best candidate is the same physical point and must not fail
  // the ratio test, so the second best is taken among the candidates that
  // are not twins of the best.
  const int kInf = std::numeric_limits<int>::max();
  struct Best {
    int idx = -1, d1 = std::numeric_limits<int>::max(),
        d2 = std::numeric_limits<int>::max();
  };
  std::vector<Best> best_a(na), best_b(nb);
  for (const Cand& c : cands) {
    if (c.d < best_a[c.i].d1) best_a[c.i].d1 = c.d, best_a[c.i].idx = c.j;
    if (c.d < best_b[c.j].d1) best_b[c.j].d1 = c.d, best_b[c.j].idx = c.i;
  }
  for (const Cand& c : cands) {
    Best& ba = best_a[c.i];
    if (c.j != ba.idx && !AreOrientationTwins(fb, c.j, ba.idx)) {
      ba.d2 = std::min(ba.d2, c.d);
    }
    Best& bb = best_b[c.j];
    if (c.i != bb.idx && !AreOrientationTwins(fa, c.i, bb.idx)) {
      bb.d2 = std::min(bb.d2, c.d);
    }
  }
  const double max_d =
      sparse_internal::kMaxDescriptorDistance * Features::kDescriptorScale;
  const double max_d2 = max_d * max_d;
  const double r2 = sparse_internal::kRatio * sparse_internal::kRatio;
  auto passes = [&](const Best& b) {
    if (b.idx < 0 || b.d1 > max_d2) return false;
    return b.d2 == kInf || static_cast<double>(b.d1) < r2 * b.d2;
  };
  for (int i = 0; i < na; ++i) {
    const int j = best_a[i].idx;
    if (!passes(best_a[i])) continue;
    if ((best_b[j].idx != i || !passes(best_b[j]))) continue;
    out.emplace_back(i, j);
  }
  return out;
}

}  // namespace sparse_internal
}  // namespace wild_mvs
