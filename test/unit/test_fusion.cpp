// Copyright wild_mvs authors. Tests of depth-map fusion on analytic scenes.
#include <gtest/gtest.h>

#include <map>
#include <unordered_map>

#include "test_fusion_scene.h"
#include "wild_mvs/core/error.h"
#include "wild_mvs/core/fusion.h"
#include "wild_mvs/core/image.h"

namespace wild_mvs {
namespace {

using fusion_test::AnalyticScene;
using fusion_test::Corrupt;

// Fraction of `query` points that have a `ref` point within tau (uniform
// grid of cell tau, 27-cell search).
double FractionWithin(const std::vector<Eigen::Vector3d>& query,
                      const std::vector<Eigen::Vector3d>& ref, double tau) {
  std::unordered_multimap<int64_t, int> grid;
  auto key = [&](int64_t x, int64_t y, int64_t z) {
    return (x * 73856093) ^ (y * 19349663) ^ (z * 83492791);
  };
  auto cell = [&](double v) {
    return static_cast<int64_t>(std::floor(v / tau));
  };
  for (size_t i = 0; i < ref.size(); ++i)
    grid.emplace(key(cell(ref[i].x()), cell(ref[i].y()), cell(ref[i].z())),
                 static_cast<int>(i));
  size_t hit = 0;
  for (const Eigen::Vector3d& q : query) {
    const int64_t cx = cell(q.x()), cy = cell(q.y()), cz = cell(q.z());
    bool found = false;
    for (int dx = -1; dx <= 1 && !found; ++dx)
      for (int dy = -1; dy <= 1 && !found; ++dy)
        for (int dz = -1; dz <= 1 && !found; ++dz) {
          auto range = grid.equal_range(key(cx + dx, cy + dy, cz + dz));
          for (auto it = range.first; it != range.second; ++it)
            if ((ref[it->second] - q).norm() <= tau) {
              found = true;
              break;
            }
        }
    hit += found;
  }
  return query.empty() ? 0.0 : static_cast<double>(hit) / query.size();
}

std::vector<Eigen::Vector3d> ToD(const PointCloud& pc) {
  std::vector<Eigen::Vector3d> out;
  for (const auto& p : pc.xyz) out.push_back(p.cast<double>());
  return out;
}

struct Score {
  double precision, recall, f;
};

Score Evaluate(const AnalyticScene& scene, const PointCloud& pc, int n,
               double tau) {
  size_t good = 0;
  for (const auto& p : pc.xyz) good += scene.Distance(p.cast<double>()) <= tau;
  Score s;
  s.precision = pc.empty() ? 0.0 : static_cast<double>(good) / pc.size();
  s.recall = FractionWithin(scene.GroundTruth(n, 3), ToD(pc), tau);
  s.f = s.precision + s.recall > 0
            ? 2 * s.precision * s.recall / (s.precision + s.recall)
            : 0.0;
  return s;
}

// A provider of corrupted analytic maps that counts its calls.
struct Provider {
  AnalyticScene scene;
  int n = 12;
  double noise = 0.002, normal_noise = 0.05, outliers = 0.1;
  int* calls = nullptr;
  bool neighbors = true;
  DepthMapProvider Get() const {
    Provider self = *this;
    return [self](int view) {
      if (self.calls) ++*self.calls;
      auto m = std::make_shared<DepthMap>(self.scene.Render(view, self.n));
      Corrupt(m.get(), self.noise, self.normal_noise, self.outliers,
              1000 + view);
      if (!self.neighbors) m->neighbors.clear();
      return std::shared_ptr<const DepthMap>(m);
    };
  }
};

std::vector<int> Range(int n) {
  std::vector<int> v(n);
  for (int i = 0; i < n; ++i) v[i] = i;
  return v;
}

TEST(FusionOptions, CheckRejectsBadValues) {
  FusionOptions o;
  EXPECT_NO_THROW(o.Check());
  auto bad = [](auto mutate, const std::string& name) {
    FusionOptions b;
    mutate(b);
    try {
      b.Check();
      ADD_FAILURE() << "no error for " << name;
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find(name), std::string::npos)
          << e.what();
    }
  };
  bad([](FusionOptions& b) { b.min_support = 0; }, "min_support");
  bad([](FusionOptions& b) { b.depth_tolerance = -1; }, "depth_tolerance");
  bad([](FusionOptions& b) { b.normal_tolerance_deg = NAN; },
      "normal_tolerance_deg");
  bad([](FusionOptions& b) { b.bbox_min[0] = 5, b.bbox_max[0] = 1; }, "bbox");
  bad([](FusionOptions& b) { b.map_cache_mb = -1; }, "map_cache_mb");
  bad([](FusionOptions& b) { b.memory_mb = NAN; }, "memory_mb");
  bad([](FusionOptions& b) { b.reprojection_tolerance_px = 0; },
      "reprojection_tolerance_px");
}

// Noisy maps with 10 % outliers: the consistency check removes the outliers
// (precision), keeps the surface (recall); without it precision collapses.
TEST(Fusion, ConsistencyCheckRemovesOutliers) {
  Provider prov;
  const AnalyticScene& scene = prov.scene;
  const double tau = 0.005 * scene.SceneSize();
  ThreadPool pool(2);
  FusionOptions o;
  FusionStats stats;
  const PointCloud pc = FuseDepthMaps(Range(prov.n), o, prov.Get(), nullptr,
                                      nullptr, &pool, &stats);
  const Score s = Evaluate(scene, pc, prov.n, tau);
  std::printf("k=3: %zu points, precision %.4f recall %.4f F %.4f\n", pc.size(),
              s.precision, s.recall, s.f);
  EXPECT_GT(s.precision, 0.98);
  EXPECT_GT(s.recall, 0.95);
  EXPECT_GT(s.f, 0.97);

  FusionOptions none = o;
  none.min_support = 1;
  const PointCloud raw =
      FuseDepthMaps(Range(prov.n), none, prov.Get(), nullptr, nullptr, &pool);
  const Score r = Evaluate(scene, raw, prov.n, tau);
  std::printf("k=1: %zu points, precision %.4f recall %.4f F %.4f\n",
              raw.size(), r.precision, r.recall, r.f);
  EXPECT_LT(r.precision, 0.93);  // the outliers stay without the check
  EXPECT_GT(s.precision, r.precision + 0.05);

  // Every point carries a unit normal close to the true one, support >= k,
  // confidence of the input.
  ASSERT_TRUE(pc.has_normal() && pc.has_support() && pc.has_confidence());
  EXPECT_FALSE(pc.has_rgb());  // no image provider
  int good_normals = 0;
  for (size_t i = 0; i < pc.size(); ++i) {
    EXPECT_GE(pc.support[i], 3);
    EXPECT_NEAR(pc.normal[i].norm(), 1.0, 1e-4);
    EXPECT_NEAR(pc.confidence[i], 0.8, 1e-4);
    const Eigen::Vector3d p = pc.xyz[i].cast<double>();
    Eigen::Vector3d gt = (p.z() < scene.ground_z + 0.01)
                             ? Eigen::Vector3d::UnitZ()
                             : (p - scene.sphere_center).normalized();
    good_normals += gt.dot(pc.normal[i].cast<double>()) > std::cos(0.2);
  }
  EXPECT_GT(good_normals, 0.97 * pc.size());
  // Duplicates merged: far fewer points than accepted samples.
  EXPECT_LT(pc.size(), stats.accepted / 2);
}

// Streaming (no pool, one view at a time) equals batch with a pool, bit for
// bit; the cloud is valid while it grows.
TEST(Fusion, StreamingEqualsBatch) {
  Provider prov;
  prov.n = 8;
  FusionOptions o;
  ThreadPool pool(2);
  const PointCloud batch =
      FuseDepthMaps(Range(prov.n), o, prov.Get(), nullptr, nullptr, &pool);
  StreamingFusion s(o, prov.Get());
  size_t last = 0;
  for (int v = 0; v < prov.n; ++v) {
    s.AddView(v);
    EXPECT_GE(s.num_points(), last);
    last = s.num_points();
  }
  const PointCloud stream = s.Cloud();
  ASSERT_EQ(batch.size(), stream.size());
  ASSERT_GT(batch.size(), 1000u);
  for (size_t i = 0; i < batch.size(); ++i) {
    ASSERT_EQ(batch.xyz[i], stream.xyz[i]) << i;
    ASSERT_EQ(batch.normal[i], stream.normal[i]) << i;
    ASSERT_EQ(batch.support[i], stream.support[i]) << i;
  }
}

// Cloud(begin, end) are the slices of Cloud(); Finish() keeps the cloud,
// releases maps and pending samples, and refuses more views.
TEST(Fusion, CloudRangesAndFinish) {
  Provider prov;
  prov.n = 6;
  FusionOptions o;
  StreamingFusion s(o, prov.Get());
  for (int v = 0; v < prov.n; ++v) s.AddView(v);
  EXPECT_GT(s.stats().pending, 0u);
  const PointCloud whole = s.Cloud();
  ASSERT_GT(whole.size(), 10000u);  // several ranges of 7001 below
  s.Finish();
  EXPECT_EQ(s.stats().pending, 0u);
  EXPECT_EQ(s.stats().held_map_bytes, 0u);
  EXPECT_EQ(s.num_points(), whole.size());
  EXPECT_THROW(s.AddView(prov.n), Error);
  const size_t n = whole.size();
  for (size_t begin = 0; begin < n;) {
    const size_t end = std::min(n, begin + 7001);
    const PointCloud part = s.Cloud(begin, end);
    ASSERT_EQ(part.size(), end - begin);
    for (size_t i = begin; i < end; ++i) {
      ASSERT_EQ(part.xyz[i - begin], whole.xyz[i]) << i;
      ASSERT_EQ(part.normal[i - begin], whole.normal[i]) << i;
      ASSERT_EQ(part.confidence[i - begin], whole.confidence[i]) << i;
      ASSERT_EQ(part.support[i - begin], whole.support[i]) << i;
    }
    begin = end;
  }
  EXPECT_EQ(s.Cloud(n, n).size(), 0u);
  EXPECT_THROW(s.Cloud(0, n + 1), Error);
}

// Samples of early views that lack support wait as pending samples and are
// promoted when later views agree; without pending samples the first views
// contribute less.
TEST(Fusion, IncrementalPromotesPendingSamples) {
  Provider prov;
  prov.n = 8;
  prov.outliers = 0;
  FusionOptions o;
  StreamingFusion s(o, prov.Get());
  s.AddView(0);
  EXPECT_EQ(s.num_points(), 0u);  // nothing to agree with yet
  EXPECT_GT(s.stats().pending, 10000u);
  s.AddView(1);
  s.AddView(2);
  EXPECT_GT(s.stats().promoted, 5000u);  // view 0's samples from 1 and 2
  for (int v = 3; v < prov.n; ++v) s.AddView(v);

  FusionOptions no_pending = o;
  no_pending.pending_mb = 0;
  StreamingFusion t(no_pending, prov.Get());
  for (int v = 0; v < prov.n; ++v) t.AddView(v);
  EXPECT_EQ(t.stats().promoted, 0u);
  EXPECT_GT(s.num_points(), t.num_points());
  const double tau = 0.005 * prov.scene.SceneSize();
  const Score a = Evaluate(prov.scene, s.Cloud(), prov.n, tau);
  const Score b = Evaluate(prov.scene, t.Cloud(), prov.n, tau);
  std::printf("with pending: recall %.4f, without: %.4f\n", a.recall, b.recall);
  EXPECT_GE(a.recall, b.recall);
  EXPECT_GT(a.precision, 0.98);
}

// Held depth maps are bounded by the LRU option and the peak does not grow
// with the number of views (8 vs 32 views of the same scene).
TEST(Fusion, PeakMemoryFlatWhenViewsAdded) {
  auto run = [](int n, FusionStats* stats) {
    Provider prov;
    prov.n = n;
    prov.outliers = 0.05;
    int calls = 0;
    prov.calls = &calls;
    FusionOptions o;
    o.map_cache_mb = 2;  // ~2 prepared maps of 240x180 (0.86 MB each)
    o.pending_mb = 4;
    StreamingFusion s(o, prov.Get());
    for (int v = 0; v < n; ++v) s.AddView(v);
    *stats = s.stats();
    return calls;
  };
  FusionStats s8, s32;
  run(8, &s8);
  const int calls32 = run(32, &s32);
  const size_t map_bytes = 240 * 180 * 20;
  const size_t mb = 1024 * 1024;
  std::printf(
      "8 views: peak %zu B (maps %zu B, cloud %zu B, %zu points); 32 views: "
      "peak %zu B (maps %zu B, cloud %zu B, %zu points); all 32 maps would "
      "be %zu B\n",
      s8.peak_bytes, s8.peak_held_map_bytes, s8.cloud_bytes, s8.points,
      s32.peak_bytes, s32.peak_held_map_bytes, s32.cloud_bytes, s32.points,
      32 * map_bytes);
  // Held maps: at most the budget plus the two in use by one AddView, the
  // same for 8 and 32 views.
  EXPECT_LE(s32.peak_held_map_bytes, 2 * mb + 2 * map_bytes + 1024);
  EXPECT_LE(s32.peak_held_map_bytes, s8.peak_held_map_bytes + 1024);
  // Pending samples within their budget.
  EXPECT_LE(s32.pending_bytes, 4 * mb);
  // The peak is the bounded part plus the cloud: it grows with the output
  // (the same surface: the cloud barely grows), not with views x image size.
  EXPECT_LE(s32.peak_bytes,
            2 * mb + 2 * map_bytes + 4 * mb + s32.cloud_bytes + 1024);
  EXPECT_LT(s32.points, 1.5 * s8.points);
  EXPECT_LT(s32.peak_bytes, 32 * map_bytes / 2);
  // 24 more views (20 MB of maps) add less than a quarter of their size.
  EXPECT_LT(s32.peak_bytes, s8.peak_bytes + 24 * map_bytes / 4);
  EXPECT_GE(calls32, 32);  // maps really were re-loaded, not kept
}

// The joint budget memory_mb: the cloud takes the cached maps' room as it
// grows, so the fusion's account (maps + pending + cloud) stays within the
// budget plus the maps one AddView holds; only maps are given up (and read
// again), so the cloud is the same point for point.
TEST(Fusion, JointBudgetEvictsMapsNotResults) {
  const size_t map_bytes = 240 * 180 * 20;
  const size_t mb = 1024 * 1024;
  auto run = [](int n, double memory_mb, int* calls, FusionStats* stats) {
    Provider prov;
    prov.n = n;
    prov.outliers = 0.05;
    prov.calls = calls;
    FusionOptions o;
    o.map_cache_mb = 64;  // every map fits: only memory_mb evicts
    o.pending_mb = 2;
    o.memory_mb = memory_mb;
    StreamingFusion s(o, prov.Get());
    for (int v = 0; v < n; ++v) {
      s.AddView(v);
      // Between views: within the budget (the cloud alone is below it).
      if (memory_mb > 0) {
        EXPECT_LE(s.bytes(), static_cast<size_t>(memory_mb * 1024 * 1024))
            << "after view " << v;
      }
    }
    *stats = s.stats();
    return s.Cloud();
  };
  int calls_free = 0, calls_budget = 0, calls8 = 0;
  FusionStats free_stats, budget_stats, stats8;
  const PointCloud free_cloud = run(24, 0, &calls_free, &free_stats);
  // Room for the pending samples, the cloud and about two maps.
  const double budget_mb =
      (2.0 * mb + free_stats.cloud_bytes + 2 * map_bytes) / mb;
  const PointCloud cloud = run(24, budget_mb, &calls_budget, &budget_stats);
  std::printf(
      "no joint budget: peak %zu B, %d map loads; memory_mb %.2f: peak %zu "
      "B, %d map loads, cloud %zu B\n",
      free_stats.peak_bytes, calls_free, budget_mb, budget_stats.peak_bytes,
      calls_budget, budget_stats.cloud_bytes);
  // The same cloud, point for point.
  ASSERT_GT(cloud.size(), 10000u);
  ASSERT_EQ(cloud.size(), free_cloud.size());
  for (size_t i = 0; i < cloud.size(); ++i) {
    ASSERT_EQ(cloud.xyz[i], free_cloud.xyz[i]) << i;
    ASSERT_EQ(cloud.normal[i], free_cloud.normal[i]) << i;
    ASSERT_EQ(cloud.confidence[i], free_cloud.confidence[i]) << i;
    ASSERT_EQ(cloud.support[i], free_cloud.support[i]) << i;
  }
  // Without it all 24 maps stay (loaded once); with it maps were evicted
  // and read again.
  EXPECT_EQ(calls_free, 24);
  EXPECT_GT(calls_budget, calls_free);
  EXPECT_GT(free_stats.peak_bytes, 20 * map_bytes);
  // The peak: the budget plus the maps in use by one AddView (the view's
  // and one related map) and one view's new pending samples before they
  // are trimmed.
  const size_t view_pending = 240 * 180 * 64;
  EXPECT_LE(budget_stats.peak_bytes,
            static_cast<size_t>(budget_mb * mb) + 2 * map_bytes + view_pending);
  EXPECT_LT(budget_stats.peak_bytes, free_stats.peak_bytes / 2);
  // Flat in the number of views: 8 views under the same budget peak at
  // nearly the same account (their cloud is smaller, their maps more).
  run(8, budget_mb, &calls8, &stats8);
  EXPECT_GT(stats8.peak_bytes, budget_stats.peak_bytes * 8 / 10);
}

// Masks (0 = ignore), bounding box and minimum confidence filter samples.
TEST(Fusion, MasksBoundingBoxAndConfidence) {
  Provider prov;
  prov.n = 8;
  prov.outliers = 0;
  FusionOptions o;
  // Bounding box: only the upper half of the sphere.
  FusionOptions box = o;
  box.bbox_min = {-1.0, -1.0, 0.1};
  box.bbox_max = {1.0, 1.0, 1.0};
  const PointCloud pb = FuseDepthMaps(Range(prov.n), box, prov.Get());
  ASSERT_GT(pb.size(), 1000u);
  for (const auto& p : pb.xyz) {
    EXPECT_GE(p.z(), 0.1f - 1e-4f);
    EXPECT_LE(p.z(), 1.0f);
  }
  // Mask of the left half of every image: all points fall in the masked
  // half... of at least one view; concretely, every point projects into the
  // unmasked half of the view it came from, so the cloud shrinks.
  MaskProvider half = [&](int) {
    cv::Mat m(prov.scene.height / 2, prov.scene.width / 2, CV_8U,
              cv::Scalar(255));  // other size: resized
    m.colRange(0, m.cols / 2).setTo(0);
    return m;
  };
  const PointCloud full = FuseDepthMaps(Range(prov.n), o, prov.Get());
  const PointCloud masked =
      FuseDepthMaps(Range(prov.n), o, prov.Get(), nullptr, half);
  EXPECT_LT(masked.size(), 0.75 * full.size());
  EXPECT_GT(masked.size(), 0.2 * full.size());
}

// Colour comes from the image provider (linear) and is returned as sRGB;
// normals are derived from the depth when a map has none; related views
// come from camera overlap when maps have no neighbour list.
TEST(Fusion, ColourMissingNormalsAndOverlapNeighbours) {
  Provider prov;
  prov.n = 8;
  prov.outliers = 0;
  prov.noise = 0;
  prov.neighbors = false;
  DepthMapProvider no_normals = [base = prov.Get()](int v) {
    auto m = std::make_shared<DepthMap>(*base(v));
    m->normal = cv::Mat();
    return std::shared_ptr<const DepthMap>(m);
  };
  ImageProvider colour = [&](int) {
    return cv::Mat(prov.scene.height, prov.scene.width, CV_32FC3,
                   cv::Scalar(0.2, 0.5, 0.05));
  };
  const PointCloud pc =
      FuseDepthMaps(Range(prov.n), FusionOptions(), no_normals, colour);
  ASSERT_GT(pc.size(), 5000u);
  ASSERT_TRUE(pc.has_rgb());
  int good = 0;
  for (size_t i = 0; i < pc.size(); ++i) {
    EXPECT_NEAR(pc.rgb[i].x(), LinearToSrgb(0.2f), 1e-4);
    EXPECT_NEAR(pc.rgb[i].y(), LinearToSrgb(0.5f), 1e-4);
    const Eigen::Vector3d p = pc.xyz[i].cast<double>();
    Eigen::Vector3d gt = (p.z() < prov.scene.ground_z + 0.01)
                             ? Eigen::Vector3d::UnitZ()
                             : (p - prov.scene.sphere_center).normalized();
    good += gt.dot(pc.normal[i].cast<double>()) > std::cos(0.2);
  }
  EXPECT_GT(good, 0.95 * pc.size());
  const Score s =
      Evaluate(prov.scene, pc, prov.n, 0.005 * prov.scene.SceneSize());
  EXPECT_GT(s.f, 0.95);
}

TEST(Fusion, RejectsMalformedInput) {
  Provider prov;
  prov.n = 4;
  // Normal map of the wrong size.
  DepthMapProvider bad = [base = prov.Get()](int v) {
    auto m = std::make_shared<DepthMap>(*base(v));
    m->normal = cv::Mat(10, 10, CV_32FC3, cv::Scalar(0, 0, -1));
    return std::shared_ptr<const DepthMap>(m);
  };
  StreamingFusion a(FusionOptions(), bad);
  EXPECT_THROW(a.AddView(0), Error);
  // Camera that does not match the map size.
  DepthMapProvider cam = [base = prov.Get()](int v) {
    auto m = std::make_shared<DepthMap>(*base(v));
    m->camera.width *= 2;
    return std::shared_ptr<const DepthMap>(m);
  };
  StreamingFusion b(FusionOptions(), cam);
  EXPECT_THROW(b.AddView(0), Error);
  // Provider without a map, NaN depths, a view added twice.
  StreamingFusion c(FusionOptions(),
                    [](int) { return std::shared_ptr<const DepthMap>(); });
  EXPECT_THROW(c.AddView(0), Error);
  DepthMapProvider nan = [base = prov.Get()](int v) {
    auto m = std::make_shared<DepthMap>(*base(v));
    m->depth.rowRange(0, 50).setTo(NAN);
    return std::shared_ptr<const DepthMap>(m);
  };
  StreamingFusion d(FusionOptions(), nan);
  d.AddView(0);
  d.AddView(1);
  EXPECT_THROW(d.AddView(1), Error);
  for (const auto& p : d.Cloud().xyz) EXPECT_TRUE(p.allFinite());
  EXPECT_THROW(StreamingFusion(FusionOptions(), nullptr), Error);
  // A supporter that is no longer available gives no support; the view
  // itself must exist. A malformed supporter leaves the fusion unchanged.
  bool gone = false;
  DepthMapProvider store = [&gone, base = prov.Get()](int v) {
    if (gone && v == 0) return std::shared_ptr<const DepthMap>();
    return base(v);
  };
  FusionOptions tiny;
  tiny.map_cache_mb = 0;  // force reloads
  tiny.min_support = 2;
  StreamingFusion e(tiny, store);
  e.AddView(0);
  gone = true;
  EXPECT_NO_THROW(e.AddView(1));
  EXPECT_THROW(e.AddView(0), Error);  // already added
  StreamingFusion f(tiny, [&](int v) {
    if (v == 0) return prov.Get()(v);
    auto m = std::make_shared<DepthMap>(*prov.Get()(v));
    m->confidence = cv::Mat(3, 3, CV_32F);
    return std::shared_ptr<const DepthMap>(m);
  });
  f.AddView(0);
  const size_t pending = f.stats().pending;
  EXPECT_THROW(f.AddView(1), Error);
  EXPECT_FALSE(f.HasView(1));
  EXPECT_EQ(f.stats().pending, pending);
  EXPECT_EQ(f.num_points(), 0u);
}

}  // namespace
}  // namespace wild_mvs
