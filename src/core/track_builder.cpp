// Copyright wild_mvs authors. Union-find tracks of the sparse tracker:
// features linked by matches (and SIFT orientation twins) form one track.
#include <algorithm>
#include <numeric>

#include "sparse_tracker_impl.h"

namespace wild_mvs {

using sparse_internal::AreOrientationTwins;

int SparseTracker::Impl::Union(int a, int b) {
  int ra = Find(a), rb = Find(b);
  if (ra == rb) return ra;
  auto size_of = [this](int r) {
    auto it = members.find(r);
    auto dt = dropped.find(r);
    return (it == members.end() ? size_t{1} : it->second.size()) +
           (dt == dropped.end() ? size_t{0} : size_t(dt->second));
  };
  // Larger component stays root; ties to the smaller index.
  const size_t sa = size_of(ra), sb = size_of(rb);
  if (sa < sb || (sa == sb && rb < ra)) std::swap(ra, rb);
  std::vector<int>& into = members[ra];
  if (into.empty()) into.push_back(ra);
  auto it = members.find(rb);
  if (it == members.end()) {
    into.push_back(rb);
  } else {
    into.insert(into.end(), it->second.begin(), it->second.end());
    members.erase(it);
  }
  auto dt = dropped.find(rb);
  if (dt != dropped.end()) {
    dropped[ra] += dt->second;
    dropped.erase(dt);
  }
  points.erase(rb);
  parent[rb] = ra;
  return ra;
}

void SparseTracker::Impl::LinkTwins(const ViewData& v) {
  std::vector<int> by_x(v.count);
  std::iota(by_x.begin(), by_x.end(), 0);
  const auto& xy = v.features.xy;
  std::sort(by_x.begin(), by_x.end(), [&xy](int a, int b) {
    return xy[a].x() < xy[b].x() || (xy[a].x() == xy[b].x() && a < b);
  });
  for (size_t a = 0; a < by_x.size(); ++a) {
    for (size_t b = a + 1;
         b < by_x.size() && xy[by_x[b]].x() - xy[by_x[a]].x() <= 0.01f; ++b) {
      if (AreOrientationTwins(v.features, by_x[a], by_x[b])) {
        Union(v.offset + by_x[a], v.offset + by_x[b]);
      }
    }
  }
}

}  // namespace wild_mvs
