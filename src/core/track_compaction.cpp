// Copyright wild_mvs authors. Compaction of the sparse tracker:
// forgets the union-find nodes and records of removed views.
#include "sparse_tracker_impl.h"

namespace wild_mvs {

// Forgets the nodes and records of removed views. A node is kept when its
// view is held or when it is the root of a component with a held node
// (the root's index orders Points() and breaks union ties); kept nodes are
// renumbered in their old order and every decision of the tracker depends
// only on that order and on component sizes (kept in `dropped`), so the
// results are those without compaction. Components without a held node
// (their points are invalid) are dropped.
void SparseTracker::Impl::Compact() {
  const int n = static_cast<int>(parent.size());
  std::vector<int> root(n);
  for (int i = 0; i < n; ++i) root[i] = Find(i);
  auto held = [this](int i) {
    return node_slot[i] >= 0 && !views[node_slot[i]].removed;
  };
  std::vector<char> keep(n, 0);
  for (int i = 0; i < n; ++i) {
    if (held(i)) keep[i] = keep[root[i]] = 1;
  }
  std::vector<int> new_index(n, -1);
  int kept = 0;
  for (int i = 0; i < n; ++i) {
    if (keep[i]) new_index[i] = kept++;
  }
  std::vector<int> new_slot(views.size(), -1);
  std::vector<ViewData> new_views;
  new_views.reserve(views.size() - removed_views);
  for (size_t s = 0; s < views.size(); ++s) {
    if (views[s].removed) continue;
    new_slot[s] = static_cast<int>(new_views.size());
    new_views.push_back(std::move(views[s]));
    ViewData& v = new_views.back();
    v.offset = v.count > 0 ? new_index[v.offset] : 0;
  }
  std::vector<int> new_parent(kept), new_node_slot(kept);
  for (int i = 0; i < n; ++i) {
    if (!keep[i]) continue;
    new_parent[new_index[i]] = new_index[root[i]];
    new_node_slot[new_index[i]] = held(i) ? new_slot[node_slot[i]] : -1;
  }
  std::map<int, std::vector<int>> new_members;
  std::map<int, int> new_dropped;
  for (auto& kv : members) {
    if (!keep[kv.first]) continue;
    std::vector<int> list;
    for (int m : kv.second) {
      if (keep[m]) list.push_back(new_index[m]);
    }
    const int r = new_index[kv.first];
    auto dt = dropped.find(kv.first);
    const int d = static_cast<int>(kv.second.size() - list.size()) +
                  (dt == dropped.end() ? 0 : dt->second);
    if (d > 0) new_dropped[r] = d;
    new_members[r] = std::move(list);
  }
  std::map<int, PointData> new_points;
  for (auto& kv : points) {
    if (keep[kv.first]) {
      new_points[new_index[kv.first]] = std::move(kv.second);
    }
  }
  for (auto& kv : slot_of_id) kv.second = new_slot[kv.second];
  views = std::move(new_views);
  parent = std::move(new_parent);
  node_slot = std::move(new_node_slot);
  members = std::move(new_members);
  dropped = std::move(new_dropped);
  points = std::move(new_points);
  removed_nodes = 0;
  removed_views = 0;
}

}  // namespace wild_mvs
