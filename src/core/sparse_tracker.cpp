// Copyright wild_mvs authors. Sparse tracks from known poses.
#include "wild_mvs/core/sparse_tracker.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <mutex>
#include <numeric>
#include <set>
#include <utility>

#include "sparse_tracker_impl.h"
#include "wild_mvs/core/error.h"
#include "wild_mvs/core/triangulation.h"

namespace wild_mvs {

using sparse_internal::ViewData;

void TrackerOptions::Check() const {
  features.Check();
  Require(max_neighbors >= 1, "tracker.max_neighbors = ", max_neighbors,
          " must be >= 1");
  Require(!scene_depth || (*scene_depth > 0 && std::isfinite(*scene_depth)),
          "tracker.scene_depth = ", scene_depth.value_or(0),
          " must be > 0 (or auto: unset)");
  Require(max_reprojection_error > 0,
          "tracker.max_reprojection_error = ", max_reprojection_error,
          " must be > 0");
  Require(min_triangulation_angle_deg >= 0 && min_triangulation_angle_deg < 90,
          "tracker.min_triangulation_angle_deg = ", min_triangulation_angle_deg,
          " must be in [0, 90)");
  Require(min_track_length >= 2,
          "tracker.min_track_length = ", min_track_length, " must be >= 2");
}

void RegisterOptions(OptionRegistry* registry, const std::string& prefix,
                     TrackerOptions* o) {
  auto key = [&prefix](const char* name) {
    return OptionRegistry::Join(prefix, name);
  };
  RegisterOptions(registry, key("features"), &o->features);
  registry
      ->Add(key("max_neighbors"), &o->max_neighbors,
            "match each view against at most this many earlier views")
      .Min(1);
  registry
      ->Add(key("scene_depth"), &o->scene_depth,
            "typical scene depth for the overlap test (scene units), auto = "
            "estimated")
      .Above(0);
  registry
      ->Add(key("max_reprojection_error"), &o->max_reprojection_error,
            "remove observations reprojecting farther (px)")
      .Above(0);
  registry
      ->Add(key("min_triangulation_angle_deg"), &o->min_triangulation_angle_deg,
            "a point's largest pairwise viewing angle must reach this (deg)")
      .Min(0)
      .Below(90);
  registry
      ->Add(key("min_track_length"), &o->min_track_length,
            "tracks seen in fewer views produce no point")
      .Min(2);
  // `compact` is a test switch (the results are the same), not an option.
}

SparseTracker::SparseTracker(const TrackerOptions& options, ThreadPool* pool)
    : impl_(new Impl) {
  options.Check();
  impl_->opt = options;
  impl_->pool = pool;
}

SparseTracker::~SparseTracker() = default;

void SparseTracker::AddView(int view_index, const Camera& camera,
                            const cv::Mat& image) {
  Require(!image.empty(), "SparseTracker::AddView: view ", view_index,
          " has an empty image");
  Require(image.cols == camera.width && image.rows == camera.height,
          "SparseTracker::AddView: view ", view_index, " image is ", image.cols,
          "x", image.rows, " but its camera is ", camera.width, "x",
          camera.height);
  AddView(view_index, camera, ExtractFeatures(image, impl_->opt.features));
}

void SparseTracker::AddView(int view_index, const Camera& camera,
                            Features features) {
  Impl& m = *impl_;
  Require(view_index >= 0, "SparseTracker::AddView: view index ", view_index,
          " must be >= 0");
  Require(!m.slot_of_id.count(view_index), "SparseTracker::AddView: view ",
          view_index, " was already added");
  camera.Validate(Msg("SparseTracker::AddView view ", view_index));
  const int n = features.size();
  Require(static_cast<int>(features.scale.size()) == n &&
              (features.rgb.empty() ||
               static_cast<int>(features.rgb.size()) == n) &&
              (n == 0 || (features.descriptors.type() == CV_8U &&
                          features.descriptors.rows == n &&
                          features.descriptors.cols == 128)),
          "SparseTracker::AddView: view ", view_index,
          " has inconsistent features (", n, " positions, ",
          features.descriptors.rows, " descriptors)");
  if (m.opt.features.max_features > 0 && n > m.opt.features.max_features) {
    std::vector<int> keep(m.opt.features.max_features);
    std::iota(keep.begin(), keep.end(), 0);
    features.Select(keep);
  }

  ViewData v;
  v.id = view_index;
  v.camera = camera;
  v.features = std::move(features);
  v.count = v.features.size();
  v.offset = static_cast<int>(m.parent.size());

  const std::vector<int> nb = m.SelectNeighbors(camera);
  std::vector<std::vector<sparse_internal::Match>> matches(nb.size());
  auto run = [&](int k) {
    const ViewData& old = m.views[nb[k]];
    matches[k] = sparse_internal::GuidedMatches(v.camera, v.features,
                                                old.camera, old.features);
  };
  if (m.pool && nb.size() > 1) {
    m.pool->ParallelFor(static_cast<int>(nb.size()), run);
  } else {
    for (size_t k = 0; k < nb.size(); ++k) run(static_cast<int>(k));
  }

  const int slot = static_cast<int>(m.views.size());
  for (int s : nb) v.neighbors.push_back(m.views[s].id);
  m.views.push_back(std::move(v));
  m.slot_of_id[view_index] = slot;
  const ViewData& nv = m.views.back();
  for (int i = 0; i < nv.count; ++i) {
    m.parent.push_back(nv.offset + i);
    m.node_slot.push_back(slot);
  }
  // SIFT orientation twins (features at the same position) are one point:
  // link them so that matches through either twin build one track.
  m.LinkTwins(nv);
  std::vector<int> touched;
  for (size_t k = 0; k < nb.size(); ++k) {
    const ViewData& old = m.views[nb[k]];
    if (!matches[k].empty()) ++m.pairs_matched;
    m.matches += static_cast<long long>(matches[k].size());
    for (const sparse_internal::Match& mt : matches[k]) {
      touched.push_back(m.Union(nv.offset + mt.first, old.offset + mt.second));
    }
  }
  std::set<int> roots;
  for (int r : touched) roots.insert(m.Find(r));
  for (int r : roots) m.Rebuild(r);
}

void SparseTracker::RemoveView(int view_index) {
  Impl& m = *impl_;
  auto it = m.slot_of_id.find(view_index);
  if (it == m.slot_of_id.end()) return;
  ViewData& v = m.views[it->second];
  if (v.removed) return;
  v.removed = true;
  std::set<int> roots;
  for (int i = 0; i < v.count; ++i) {
    const int r = m.Find(v.offset + i);
    if (m.members.count(r)) roots.insert(r);
  }
  for (int r : roots) m.Rebuild(r);
  v.features = Features();  // free descriptors; positions no longer needed
  v.neighbors = std::vector<int>();
  m.slot_of_id.erase(it);
  m.removed_nodes += v.count;
  ++m.removed_views;
  // Amortised: compaction costs O(nodes + views) and runs once removed
  // nodes (or records) make up more than half of them.
  if (m.opt.compact &&
      (2 * m.removed_nodes > static_cast<long long>(m.parent.size()) ||
       2 * m.removed_views > static_cast<int>(m.views.size()))) {
    m.Compact();
  }
}

bool SparseTracker::HasView(int view_index) const {
  return impl_->slot_of_id.count(view_index) > 0;
}

std::vector<int> SparseTracker::MatchedNeighbors(int view_index) const {
  auto it = impl_->slot_of_id.find(view_index);
  if (it == impl_->slot_of_id.end()) return {};
  return impl_->views[it->second].neighbors;
}

std::vector<SparsePoint> SparseTracker::Points() const {
  std::vector<SparsePoint> out;
  for (const auto& kv : impl_->points) {
    if (kv.second.valid) out.push_back(kv.second.point);
  }
  return out;
}

void SparseTracker::FillScene(Scene* scene) const {
  std::vector<SparsePoint> pts = Points();
  for (const SparsePoint& p : pts) {
    for (const Observation& o : p.track) {
      Require(o.view >= 0 && o.view < static_cast<int>(scene->views.size()),
              "SparseTracker::FillScene: view index ", o.view,
              " is not a view of the scene (", scene->views.size(), " views)");
    }
  }
  scene->points = std::move(pts);
}

TrackerStats SparseTracker::Stats() const {
  const Impl& m = *impl_;
  TrackerStats s;
  for (const ViewData& v : m.views) {
    if (v.removed) continue;
    ++s.views;
    s.features += v.count;
  }
  s.pairs_matched = m.pairs_matched;
  s.matches = m.matches;
  s.tracks = static_cast<int>(m.points.size());
  for (const auto& kv : m.points) {
    if (kv.second.conflict) ++s.conflicting_tracks;
    if (kv.second.valid) ++s.points;
  }
  return s;
}

size_t SparseTracker::bytes() const {
  const Impl& m = *impl_;
  // Map nodes: key, value and ~32 B of tree links and allocator overhead.
  constexpr size_t kNode = 32;
  size_t b = (m.parent.capacity() + m.node_slot.capacity()) * sizeof(int);
  b += m.views.capacity() * sizeof(ViewData);
  for (const ViewData& v : m.views) {
    b += v.features.bytes() + v.neighbors.capacity() * sizeof(int);
  }
  b += m.slot_of_id.size() * (kNode + 2 * sizeof(int));
  b += m.dropped.size() * (kNode + 2 * sizeof(int));
  for (const auto& kv : m.members) {
    b += kNode + sizeof(kv) + kv.second.capacity() * sizeof(int);
  }
  for (const auto& kv : m.points) {
    b += kNode + sizeof(kv) +
         kv.second.point.track.capacity() * sizeof(Observation);
  }
  return b;
}

std::vector<SparsePoint> ComputeSparseTracks(const Scene& scene,
                                             ImageCache& images,
                                             const TrackerOptions& options,
                                             ThreadPool* pool,
                                             TrackerStats* stats) {
  options.Check();
  SparseTracker tracker(options, pool);
  const int n = static_cast<int>(scene.views.size());
  // Extract in chunks so only a few images / feature sets are held at once.
  const int chunk = pool ? std::max(2, 2 * (pool->size() + 1)) : 1;
  for (int start = 0; start < n; start += chunk) {
    const int count = std::min(chunk, n - start);
    std::vector<Features> feats(count);
    auto extract = [&](int k) {
      const int i = start + k;
      const View& view = scene.views[i];
      std::shared_ptr<const cv::Mat> img = images.Get(i);
      Require(img && !img->empty(), "ComputeSparseTracks: view ", i, " (",
              view.name, ") has no image");
      Require(img->cols == view.camera.width && img->rows == view.camera.height,
              "ComputeSparseTracks: view ", i, " (", view.name, ") image is ",
              img->cols, "x", img->rows, " but its camera is ",
              view.camera.width, "x", view.camera.height);
      feats[k] = ExtractFeatures(*img, options.features);
    };
    if (pool && count > 1) {
      pool->ParallelFor(count, extract);
    } else {
      for (int k = 0; k < count; ++k) extract(k);
    }
    for (int k = 0; k < count; ++k) {
      tracker.AddView(start + k, scene.views[start + k].camera,
                      std::move(feats[k]));
    }
  }
  if (stats) *stats = tracker.Stats();
  return tracker.Points();
}

}  // namespace wild_mvs
