// Copyright wild_mvs authors.
#include "wild_mvs/core/fusion.h"

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>

#include "wild_mvs/core/error.h"
#include "wild_mvs/core/image.h"

namespace wild_mvs {

namespace {
constexpr double kMB = 1024.0 * 1024.0;

bool AllFinite(const Eigen::Vector3d& v) { return v.allFinite(); }
}  // namespace

void FusionOptions::Check() const {
  Require(min_support >= 1 && min_support <= 65535,
          "fusion.min_support = ", min_support, " must be in [1, 65535]");
  Require(std::isfinite(depth_tolerance) && depth_tolerance > 0 &&
              depth_tolerance < 1,
          "fusion.depth_tolerance = ", depth_tolerance, " must be in (0, 1)");
  Require(
      std::isfinite(reprojection_tolerance_px) && reprojection_tolerance_px > 0,
      "fusion.reprojection_tolerance_px = ", reprojection_tolerance_px,
      " must be > 0");
  Require(std::isfinite(normal_tolerance_deg) && normal_tolerance_deg > 0 &&
              normal_tolerance_deg <= 180,
          "fusion.normal_tolerance_deg = ", normal_tolerance_deg,
          " must be in (0, 180]");
  const char* const axes[] = {"x", "y", "z"};
  for (int i = 0; i < 3; ++i) {
    const double lo = bbox_min[i].value_or(0), hi = bbox_max[i].value_or(0);
    Require(std::isfinite(lo) && std::isfinite(hi) &&
                (!bbox_min[i] || !bbox_max[i] || lo <= hi),
            "fusion.bbox_min_", axes[i], " / bbox_max_", axes[i], " = ",
            bbox_min[i] ? Msg(lo) : "auto", " / ",
            bbox_max[i] ? Msg(hi) : "auto",
            " must be finite with min <= max (or auto: no bound)");
  }
  Require(std::isfinite(map_cache_mb) && map_cache_mb >= 0,
          "fusion.map_cache_mb = ", map_cache_mb, " must be >= 0");
  Require(std::isfinite(pending_mb) && pending_mb >= 0,
          "fusion.pending_mb = ", pending_mb, " must be >= 0");
  Require(std::isfinite(memory_mb) && memory_mb >= 0,
          "fusion.memory_mb = ", memory_mb, " must be >= 0");
}

void RegisterOptions(OptionRegistry* registry, const std::string& prefix,
                     FusionOptions* o) {
  auto key = [&prefix](const std::string& name) {
    return OptionRegistry::Join(prefix, name);
  };
  registry
      ->Add(key("min_support"), &o->min_support,
            "views (own included) that must agree with a sample")
      .Min(1)
      .Max(65535);
  registry
      ->Add(key("depth_tolerance"), &o->depth_tolerance,
            "relative depth tolerance of the consistency check")
      .Above(0)
      .Below(1);
  registry
      ->Add(key("reprojection_tolerance_px"), &o->reprojection_tolerance_px,
            "reprojection tolerance of the consistency check (px)")
      .Above(0);
  registry
      ->Add(key("normal_tolerance_deg"), &o->normal_tolerance_deg,
            "largest angle between agreeing normals (degrees)")
      .Above(0)
      .Max(180);
  const char* const axes[] = {"x", "y", "z"};
  for (int k = 0; k < 3; ++k) {
    registry
        ->Add(key(std::string("bbox_min_") + axes[k]), &o->bbox_min[k],
              Msg("bounding box minimum ", axes[k],
                  " (world units), auto = no bound"))
        .Note(Msg("<= bbox_max_", axes[k]));
  }
  for (int k = 0; k < 3; ++k) {
    registry
        ->Add(key(std::string("bbox_max_") + axes[k]), &o->bbox_max[k],
              Msg("bounding box maximum ", axes[k],
                  " (world units), auto = no bound"))
        .Note(Msg(">= bbox_min_", axes[k]));
  }
  registry
      ->Add(key("map_cache_mb"), &o->map_cache_mb,
            "budget of the depth-map cache in MB")
      .Min(0);
  registry
      ->Add(key("pending_mb"), &o->pending_mb,
            "budget of not-yet-supported samples in MB, 0 = none")
      .Min(0);
  registry
      ->Add(key("memory_mb"), &o->memory_mb,
            "joint budget of cached maps + pending samples + cloud in MB "
            "(maps are evicted for it), 0 = none")
      .Min(0);
}

// A depth map prepared for checking: filtered depth (0 = invalid), world
// normals, confidence.
struct StreamingFusion::Prepared {
  int view = -1;
  Camera camera;
  int width = 0, height = 0;
  std::vector<float> depth;             // 0 = invalid after all filters
  std::vector<Eigen::Vector3f> normal;  // world frame
  std::vector<float> confidence;
  std::vector<int> neighbors;
  size_t bytes() const {
    return depth.size() * (sizeof(float) * 2 + sizeof(Eigen::Vector3f)) +
           sizeof(Prepared);
  }
};

// A sample waiting for support.
struct StreamingFusion::Pending {
  Eigen::Vector3d X;
  Eigen::Vector3f N;
  Eigen::Vector3f rgb;  // linear
  float confidence;
  float footprint;
  uint16_t support;
};

// A sample ready to merge.
struct StreamingFusion::Sample {
  Eigen::Vector3d X;
  Eigen::Vector3f N;
  Eigen::Vector3f rgb;
  float confidence;
  float footprint;
  uint16_t support;
};

// A point of the cloud: confidence-weighted sums of its samples.
struct StreamingFusion::Accum {
  Eigen::Vector3d sum_x;
  Eigen::Vector3f sum_n;
  Eigen::Vector3f sum_rgb;
  float sum_w;
  float sum_conf;
  float radius;
  uint32_t next;  // next point in the same hash chain, or kNone
  uint16_t count;
  uint16_t support;
};

namespace {
constexpr uint32_t kNone = 0xffffffffu;

uint64_t CellKey(int level, int64_t x, int64_t y, int64_t z) {
  // Mix into 64 bits; collisions only lengthen a chain (merging still
  // requires the distance test).
  uint64_t h = static_cast<uint64_t>(level + 1024) * 0x9E3779B97F4A7C15ull;
  for (int64_t v : {x, y, z}) {
    h ^= static_cast<uint64_t>(v) + 0x9E3779B97F4A7C15ull + (h << 6) + (h >> 2);
    h *= 0xBF58476D1CE4E5B9ull;
  }
  return h ^ (h >> 31);
}

uint64_t CellKey(int level, const Eigen::Vector3d& X) {
  const double size = std::ldexp(1.0, level);
  return CellKey(level, static_cast<int64_t>(std::floor(X.x() / size)),
                 static_cast<int64_t>(std::floor(X.y() / size)),
                 static_cast<int64_t>(std::floor(X.z() / size)));
}

// Level whose cell size 2^level is in [radius, 2 radius).
int Level(double radius) {
  return static_cast<int>(std::ceil(std::log2(radius)));
}
}  // namespace

StreamingFusion::StreamingFusion(const FusionOptions& options,
                                 DepthMapProvider depth, ImageProvider image,
                                 MaskProvider mask, ThreadPool* pool)
    : options_(options),
      depth_(std::move(depth)),
      image_(std::move(image)),
      mask_(std::move(mask)),
      pool_(pool) {
  options_.Check();
  Require(static_cast<bool>(depth_),
          "StreamingFusion: the depth map provider is empty");
  cos_normal_tol_ = std::cos(options_.normal_tolerance_deg * M_PI / 180.0);
}

StreamingFusion::~StreamingFusion() = default;

bool StreamingFusion::HasView(int view) const {
  return added_index_.count(view) > 0;
}

size_t StreamingFusion::num_points() const { return points_.size(); }

size_t StreamingFusion::bytes() const {
  return maps_.cost() + PendingBytes() + CloudBytes();
}

size_t StreamingFusion::PendingBytes() const {
  return pending_count_ * sizeof(Pending);
}

size_t StreamingFusion::CloudBytes() const {
  // Points, plus hash nodes (key, value, next pointer, cached hash) and
  // buckets.
  return points_.bytes() +
         hash_.size() * (sizeof(uint64_t) * 2 + sizeof(void*) * 2) +
         hash_.bucket_count() * sizeof(void*);
}

size_t StreamingFusion::MapCap() const {
  size_t cap = static_cast<size_t>(options_.map_cache_mb * kMB);
  if (options_.memory_mb > 0) {
    const size_t total = static_cast<size_t>(options_.memory_mb * kMB);
    const size_t others = PendingBytes() + CloudBytes();
    cap = std::min(cap, total > others ? total - others : 0);
  }
  return cap;
}

void StreamingFusion::EvictMaps() {
  // Least recently used first; maps in use elsewhere (use_count > 1: the
  // view being added, the related map being checked) stay.
  maps_.Evict(MapCap(), /*keep=*/0,
              [](const std::shared_ptr<const Prepared>& p) {
                return p.use_count() > 1;
              });
}

void StreamingFusion::UpdatePeak() {
  stats_.held_map_bytes = maps_.cost();
  stats_.peak_held_map_bytes =
      std::max(stats_.peak_held_map_bytes, maps_.cost());
  stats_.peak_bytes = std::max(stats_.peak_bytes, bytes());
  stats_.pending = pending_count_;
  stats_.pending_bytes = PendingBytes();
  stats_.cloud_bytes = CloudBytes();
  stats_.points = points_.size();
}

std::shared_ptr<const StreamingFusion::Prepared> StreamingFusion::Prepare(
    int view, const DepthMap& m) {
  const std::string what = Msg("depth map of view ", view);
  Require(!m.depth.empty() && m.depth.type() == CV_32F, what,
          ": depth must be a non-empty CV_32F image");
  const int w = m.depth.cols, h = m.depth.rows;
  Require(m.normal.empty() || (m.normal.type() == CV_32FC3 &&
                               m.normal.size() == m.depth.size()),
          what, ": normal must be empty or CV_32FC3 of the depth's size ", w,
          "x", h);
  Require(m.confidence.empty() || (m.confidence.type() == CV_32F &&
                                   m.confidence.size() == m.depth.size()),
          what, ": confidence must be empty or CV_32F of the depth's size ", w,
          "x", h);
  Require(m.camera.width == w && m.camera.height == h, what, ": camera is ",
          m.camera.width, "x", m.camera.height, " but the map is ", w, "x", h);
  m.camera.Validate(what);

  cv::Mat mask;
  if (mask_) {
    cv::Mat raw = mask_(view);
    if (!raw.empty()) {
      Require(raw.type() == CV_8U, "mask of view ", view,
              " must be CV_8U (single channel)");
      if (raw.size() != m.depth.size()) {
        cv::resize(raw, mask, m.depth.size(), 0, 0, cv::INTER_NEAREST);
      } else {
        mask = raw;
      }
    }
  }

  auto p = std::make_shared<Prepared>();
  p->view = view;
  p->camera = m.camera;
  p->width = w;
  p->height = h;
  p->neighbors = m.neighbors;
  p->depth.assign(static_cast<size_t>(w) * h, 0.f);
  p->normal.assign(static_cast<size_t>(w) * h, Eigen::Vector3f::Zero());
  p->confidence.assign(static_cast<size_t>(w) * h, 0.f);
  const Camera& cam = m.camera;
  const Eigen::Matrix3f Rt = cam.R.transpose().cast<float>();
  auto valid_depth = [&](int c, int r) {
    if (c < 0 || r < 0 || c >= w || r >= h) return 0.f;
    const float d = m.depth.at<float>(r, c);
    return (std::isfinite(d) && d > 0) ? d : 0.f;
  };
  auto cam_point = [&](int c, int r, float d) {
    return cam.BackprojectCam({c + 0.5, r + 0.5}, d);
  };
  const double inf = std::numeric_limits<double>::infinity();
  Eigen::Vector3d box_min, box_max;  // +-inf: no bound
  bool has_box = false;
  for (int k = 0; k < 3; ++k) {
    box_min[k] = options_.bbox_min[k].value_or(-inf);
    box_max[k] = options_.bbox_max[k].value_or(inf);
    has_box = has_box || options_.bbox_min[k] || options_.bbox_max[k];
  }
  auto rows = [&](int r) {
    for (int c = 0; c < w; ++c) {
      const size_t i = static_cast<size_t>(r) * w + c;
      const float d = valid_depth(c, r);
      if (d <= 0) continue;
      const float conf =
          m.confidence.empty() ? 1.f : m.confidence.at<float>(r, c);
      if (!std::isfinite(conf)) continue;
      if (!mask.empty() && mask.at<uint8_t>(r, c) == 0) continue;
      const Eigen::Vector3d Xc = cam_point(c, r, d);
      if (has_box) {
        const Eigen::Vector3d X = cam.CameraToWorld(Xc);
        if ((X.array() < box_min.array()).any() ||
            (X.array() > box_max.array()).any())
          continue;
      }
      Eigen::Vector3d n = Eigen::Vector3d::Zero();
      if (!m.normal.empty()) {
        const cv::Vec3f nv = m.normal.at<cv::Vec3f>(r, c);
        n = Eigen::Vector3d(nv[0], nv[1], nv[2]);
      }
      if (!AllFinite(n) || n.norm() < 1e-6) {
        // Normal from the depth map: cross product of central (or one-sided)
        // differences of the back-projected neighbours.
        Eigen::Vector3d dx = Eigen::Vector3d::Zero(),
                        dy = Eigen::Vector3d::Zero();
        const float dl = valid_depth(c - 1, r), dr = valid_depth(c + 1, r);
        const float du = valid_depth(c, r - 1), dd = valid_depth(c, r + 1);
        if (dr > 0 && dl > 0)
          dx = cam_point(c + 1, r, dr) - cam_point(c - 1, r, dl);
        else if (dr > 0)
          dx = cam_point(c + 1, r, dr) - Xc;
        else if (dl > 0)
          dx = Xc - cam_point(c - 1, r, dl);
        if (dd > 0 && du > 0)
          dy = cam_point(c, r + 1, dd) - cam_point(c, r - 1, du);
        else if (dd > 0)
          dy = cam_point(c, r + 1, dd) - Xc;
        else if (du > 0)
          dy = Xc - cam_point(c, r - 1, du);
        n = dx.cross(dy);
        if (!AllFinite(n) || n.norm() < 1e-12) continue;
      }
      n.normalize();
      if (n.dot(Xc) > 0) n = -n;  // face the camera
      p->depth[i] = d;
      p->normal[i] = Rt * n.cast<float>();
      p->confidence[i] = std::max(conf, 1e-3f);
    }
  };
  if (pool_) {
    pool_->ParallelFor(h, rows);
  } else {
    for (int r = 0; r < h; ++r) rows(r);
  }
  return p;
}

std::shared_ptr<const StreamingFusion::Prepared> StreamingFusion::GetMap(
    int view, bool required) {
  if (const auto* hit = maps_.Find(view)) return *hit;
  std::shared_ptr<const DepthMap> m = depth_(view);
  if (!m && !required) return nullptr;
  Require(m != nullptr,
          "fusion: the depth map provider returned no map for view ", view);
  ++stats_.map_loads;
  std::shared_ptr<const Prepared> p = Prepare(view, *m);
  m.reset();
  maps_.Insert(view, p, p->bytes());
  EvictMaps();
  UpdatePeak();
  return p;
}

std::vector<int> StreamingFusion::RelatedViews(int view,
                                               const Prepared& map) const {
  std::vector<int> related;
  auto add = [&](int u) {
    if (u == view || !HasView(u)) return;
    if (std::find(related.begin(), related.end(), u) != related.end()) return;
    related.push_back(u);
  };
  if (!map.neighbors.empty()) {
    for (int u : map.neighbors) add(u);
    // The views that list v, in the order they were added (an index: no
    // scan of every added view).
    auto listing = listed_by_.find(view);
    if (listing != listed_by_.end())
      for (int u : listing->second) add(u);
    if (static_cast<int>(related.size()) > kMaxRelatedViews)
      related.resize(kMaxRelatedViews);
  } else {
    // Overlap: fraction of a grid of v's samples that the other camera sees
    // from a direction within 60 degrees.
    std::vector<Eigen::Vector3d> pts;
    const int step =
        std::max(1, static_cast<int>(std::sqrt(static_cast<double>(map.width) *
                                               map.height / 400.0)));
    for (int r = step / 2; r < map.height; r += step)
      for (int c = step / 2; c < map.width; c += step) {
        const float d = map.depth[static_cast<size_t>(r) * map.width + c];
        if (d > 0) pts.push_back(map.camera.Backproject({c + 0.5, r + 0.5}, d));
      }
    if (pts.empty()) return related;
    const Eigen::Vector3d Cv = map.camera.Center();
    std::vector<std::pair<double, int>> scored;
    for (const Added& a : added_) {
      if (a.view == view) continue;
      const Eigen::Vector3d Cu = a.camera.Center();
      int seen = 0;
      for (const Eigen::Vector3d& X : pts) {
        Eigen::Vector2d px;
        if (!a.camera.Project(X, &px) || !a.camera.InImage(px)) continue;
        const Eigen::Vector3d rv = (Cv - X).normalized(),
                              ru = (Cu - X).normalized();
        if (rv.dot(ru) >= 0.5) ++seen;
      }
      const double score = static_cast<double>(seen) / pts.size();
      if (score >= 0.05) scored.emplace_back(-score, a.view);
    }
    std::sort(scored.begin(), scored.end());
    for (size_t i = 0;
         i < scored.size() && static_cast<int>(i) < kMaxRelatedViews; ++i)
      related.push_back(scored[i].second);
  }
  // Process in the order the views were added (deterministic).
  std::sort(related.begin(), related.end(), [&](int a, int b) {
    return added_index_.at(a) < added_index_.at(b);
  });
  return related;
}

namespace {
// Does `u` agree with the world point X (normal N) seen from camera `src`
// at pixel px_src?
template <typename MapT>
bool Agrees(const MapT& u, const Eigen::Vector3d& X, const Eigen::Vector3f& N,
            const Camera& src, const Eigen::Vector2d& px_src, double depth_tol,
            double reproj_tol2, double cos_tol) {
  const Eigen::Vector3d Xu = u.camera.WorldToCamera(X);
  if (!(Xu.z() > 0)) return false;
  const Eigen::Vector2d p = u.camera.ProjectCam(Xu);
  if (!(p.x() >= 0 && p.y() >= 0 && p.x() < u.width && p.y() < u.height))
    return false;
  const int c = static_cast<int>(p.x()), r = static_cast<int>(p.y());
  const size_t i = static_cast<size_t>(r) * u.width + c;
  const float d = u.depth[i];
  if (d <= 0) return false;
  if (std::abs(d - Xu.z()) > depth_tol * Xu.z()) return false;
  if (static_cast<double>(u.normal[i].dot(N)) < cos_tol) return false;
  const Eigen::Vector3d Y = u.camera.Backproject({c + 0.5, r + 0.5}, d);
  Eigen::Vector2d q;
  if (!src.Project(Y, &q)) return false;
  return (q - px_src).squaredNorm() <= reproj_tol2;
}
}  // namespace

void StreamingFusion::Insert(const Sample& s) {
  // Cells of the sample's level are at least `radius` wide; the sample's
  // level and the two adjacent ones are searched (footprints vary across
  // views) in the cells that a ball of the merge radius overlaps.
  const double radius = kCellScale * s.footprint;
  const int level = Level(radius);
  const float w = s.confidence;
  uint32_t best = kNone;
  double best_d2 = radius * radius;
  for (int dl : {0, -1, 1}) {
    const int lv = level + dl;
    const double size = std::ldexp(1.0, lv);
    // Points of level lv have radius < size: only the cells that the ball
    // of radius min(radius, size) overlaps can hold a merge candidate.
    const double rr = std::min(radius, size);
    int64_t c0[3], c1[3];
    for (int ax = 0; ax < 3; ++ax) {
      c0[ax] = static_cast<int64_t>(std::floor((s.X[ax] - rr) / size));
      c1[ax] = static_cast<int64_t>(std::floor((s.X[ax] + rr) / size));
    }
    for (int64_t x = c0[0]; x <= c1[0]; ++x)
      for (int64_t y = c0[1]; y <= c1[1]; ++y)
        for (int64_t z = c0[2]; z <= c1[2]; ++z) {
          auto it = hash_.find(CellKey(lv, x, y, z));
          if (it == hash_.end()) continue;
          for (uint32_t k = it->second; k != kNone; k = points_[k].next) {
            const Accum& a = points_[k];
            const Eigen::Vector3d mean = a.sum_x / a.sum_w;
            const double d2 = (mean - s.X).squaredNorm();
            if (d2 >= best_d2 || d2 > static_cast<double>(a.radius) * a.radius)
              continue;
            if (static_cast<double>(a.sum_n.normalized().dot(s.N)) <
                cos_normal_tol_)
              continue;
            best = k;
            best_d2 = d2;
          }
        }
  }
  if (best != kNone) {
    Accum& a = points_[best];
    a.sum_x += static_cast<double>(w) * s.X;
    a.sum_n += w * s.N;
    a.sum_rgb += w * s.rgb;
    a.sum_w += w;
    a.sum_conf += s.confidence;
    if (a.count < 65535) ++a.count;
    a.support = std::max(a.support, s.support);
    ++stats_.accepted;
    return;
  }
  Accum a;
  a.sum_x = static_cast<double>(w) * s.X;
  a.sum_n = w * s.N;
  a.sum_rgb = w * s.rgb;
  a.sum_w = w;
  a.sum_conf = s.confidence;
  a.radius = static_cast<float>(radius);
  a.count = 1;
  a.support = s.support;
  const uint64_t key = CellKey(level, s.X);
  auto [it, inserted] = hash_.emplace(key, kNone);
  a.next = inserted ? kNone : it->second;
  it->second = static_cast<uint32_t>(points_.size());
  Require(points_.size() < kNone, "fusion: too many points");
  points_.push_back(a);
  ++stats_.accepted;
}

void StreamingFusion::TrimPending() {
  const size_t cap =
      static_cast<size_t>(options_.pending_mb * kMB / sizeof(Pending));
  while (pending_count_ > cap && !pending_.empty()) {
    auto& front = pending_.front().second;
    const size_t excess = pending_count_ - cap;
    if (front.size() <= excess) {
      pending_count_ -= front.size();
      stats_.pending_dropped += front.size();
      pending_.pop_front();
    } else {
      front.resize(front.size() - excess);
      front.shrink_to_fit();
      pending_count_ -= excess;
      stats_.pending_dropped += excess;
    }
  }
}

void StreamingFusion::Finish() {
  finished_ = true;
  maps_.Clear();
  pending_.clear();
  pending_count_ = 0;
  UpdatePeak();
}

void StreamingFusion::AddView(int view) {
  Require(!finished_, "fusion: view ", view, " added after Finish()");
  Require(!HasView(view), "fusion: view ", view, " was already added");
  std::shared_ptr<const Prepared> v = GetMap(view, true);
  const Prepared& V = *v;
  const int W = V.width, H = V.height;
  const size_t n = static_cast<size_t>(W) * H;

  // Colour of v's samples (linear RGB at the map's resolution).
  cv::Mat colour;
  if (image_) {
    cv::Mat img = image_(view);
    if (!img.empty()) {
      Require(img.type() == CV_32FC3, "fusion: image of view ", view,
              " must be CV_32FC3 linear RGB");
      if (img.size() != cv::Size(W, H)) {
        cv::resize(img, colour, cv::Size(W, H), 0, 0, cv::INTER_AREA);
      } else {
        colour = img;
      }
    }
  }

  const std::vector<int> related = RelatedViews(view, V);
  const double depth_tol = options_.depth_tolerance;
  const double reproj2 =
      options_.reprojection_tolerance_px * options_.reprojection_tolerance_px;
  auto parallel = [&](int count, const std::function<void(int)>& body) {
    if (pool_ && count > 1) {
      pool_->ParallelFor(count, body);
    } else {
      for (int i = 0; i < count; ++i) body(i);
    }
  };

  // 1. Support of v's samples from each related view, one map at a time.
  std::vector<uint16_t> support(n, 1);
  const Camera& cv_cam = V.camera;
  for (int u : related) {
    std::shared_ptr<const Prepared> um = GetMap(u, false);
    if (!um) continue;  // no longer available (e.g. a bounded ROS store)
    const Prepared& U = *um;
    parallel(H, [&](int r) {
      for (int c = 0; c < W; ++c) {
        const size_t i = static_cast<size_t>(r) * W + c;
        const float d = V.depth[i];
        if (d <= 0) continue;
        const Eigen::Vector2d px(c + 0.5, r + 0.5);
        const Eigen::Vector3d X = cv_cam.Backproject(px, d);
        if (Agrees(U, X, V.normal[i], cv_cam, px, depth_tol, reproj2,
                   cos_normal_tol_) &&
            support[i] < 65535)
          ++support[i];
      }
    });
  }

  // 2. Pending samples of related views gain support from v.
  for (auto& entry : pending_) {
    const int u = entry.first;
    std::vector<Pending>& samples = entry.second;
    if (std::find(related.begin(), related.end(), u) == related.end()) continue;
    const Camera& ucam = added_[added_index_.at(u)].camera;
    parallel(static_cast<int>(samples.size()), [&](int k) {
      Pending& p = samples[k];
      Eigen::Vector2d px;
      if (!ucam.Project(p.X, &px)) return;
      if (Agrees(V, p.X, p.N, ucam, px, depth_tol, reproj2, cos_normal_tol_) &&
          p.support < 65535)
        ++p.support;
    });
    std::vector<Pending> keep;
    for (const Pending& p : samples) {
      if (p.support >= options_.min_support) {
        Insert({p.X, p.N, p.rgb, p.confidence, p.footprint, p.support});
        ++stats_.promoted;
      } else {
        keep.push_back(p);
      }
    }
    pending_count_ -= samples.size() - keep.size();
    samples.swap(keep);
  }
  pending_.remove_if([](const auto& e) { return e.second.empty(); });

  // 3. v's samples: accept or keep pending.
  std::vector<Pending> new_pending;
  const Eigen::Vector3f grey = Eigen::Vector3f::Constant(SrgbToLinear(0.5f));
  const double pending_cap = options_.pending_mb * kMB;
  const Eigen::Vector3d cam_center = cv_cam.Center();
  for (int r = 0; r < H; ++r) {
    for (int c = 0; c < W; ++c) {
      const size_t i = static_cast<size_t>(r) * W + c;
      const float d = V.depth[i];
      if (d <= 0) continue;
      ++stats_.samples;
      Sample s;
      s.X = cv_cam.Backproject({c + 0.5, r + 0.5}, d);
      s.N = V.normal[i];
      if (!colour.empty()) {
        const cv::Vec3f col = colour.at<cv::Vec3f>(r, c);
        s.rgb = Eigen::Vector3f(col[0], col[1], col[2]).cwiseMax(0.f);
      } else {
        s.rgb = grey;
      }
      s.confidence = V.confidence[i];
      // Footprint on the surface: the pixel footprint stretched by the
      // slant (capped at 1.5x), so oblique views merge instead of piling up.
      const double cos_view = std::abs(static_cast<double>(
          s.N.dot((s.X - cam_center).normalized().cast<float>())));
      s.footprint = static_cast<float>(cv_cam.PixelFootprint(d) /
                                       std::max(cos_view, 2.0 / 3.0));
      s.support = support[i];
      if (s.support >= options_.min_support) {
        Insert(s);
      } else if (pending_cap > 0) {
        new_pending.push_back(
            {s.X, s.N, s.rgb, s.confidence, s.footprint, s.support});
      }
    }
  }
  if (!new_pending.empty()) {
    new_pending.shrink_to_fit();
    pending_count_ += new_pending.size();
    pending_.emplace_back(view, std::move(new_pending));
  }

  added_index_[view] = added_.size();
  added_.push_back({view, V.camera, V.neighbors});
  for (int u : V.neighbors) {
    std::vector<int>& l = listed_by_[u];
    if (l.empty() || l.back() != view) l.push_back(view);
  }
  ++stats_.views;
  UpdatePeak();  // pending counted before trimming: it was held
  TrimPending();
  v.reset();
  // Respect the map budget now that no map is in use (the cloud and the
  // pending samples may have grown).
  EvictMaps();
  UpdatePeak();
}

PointCloud StreamingFusion::Cloud() const { return Cloud(0, points_.size()); }

PointCloud StreamingFusion::Cloud(size_t begin, size_t end) const {
  Require(begin <= end && end <= points_.size(), "fusion: points [", begin,
          ", ", end, ") of ", points_.size());
  PointCloud pc;
  const size_t n = end - begin;
  pc.xyz.reserve(n);
  pc.normal.reserve(n);
  if (image_) pc.rgb.reserve(n);
  pc.confidence.reserve(n);
  pc.support.reserve(n);
  for (size_t k = begin; k < end; ++k) {
    const Accum& a = points_[k];
    pc.xyz.push_back((a.sum_x / a.sum_w).cast<float>());
    Eigen::Vector3f nn = a.sum_n;
    const float len = nn.norm();
    pc.normal.push_back(len > 0 ? Eigen::Vector3f(nn / len)
                                : Eigen::Vector3f(0, 0, 1));
    if (image_) {
      const Eigen::Vector3f lin = a.sum_rgb / a.sum_w;
      pc.rgb.emplace_back(LinearToSrgb(std::min(1.f, lin.x())),
                          LinearToSrgb(std::min(1.f, lin.y())),
                          LinearToSrgb(std::min(1.f, lin.z())));
    }
    pc.confidence.push_back(std::min(1.f, a.sum_conf / a.count));
    pc.support.push_back(a.support);
  }
  return pc;
}

PointCloud FuseDepthMaps(const std::vector<int>& views,
                         const FusionOptions& options,
                         const DepthMapProvider& depth,
                         const ImageProvider& image, const MaskProvider& mask,
                         ThreadPool* pool, FusionStats* stats) {
  StreamingFusion fusion(options, depth, image, mask, pool);
  for (int v : views) fusion.AddView(v);
  if (stats) *stats = fusion.stats();
  return fusion.Cloud();
}

}  // namespace wild_mvs
