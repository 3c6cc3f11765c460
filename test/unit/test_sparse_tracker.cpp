// Copyright wild_mvs authors. Tests of the incremental sparse tracker on
// synthetic features with exact ground truth: random 3-D points seen by ring
// cameras, each point with its own random descriptor (perturbed per view),
// plus distractor features. Checks track purity, 3-D and reprojection error,
// incremental order independence, view removal, the epipolar gate and
// option validation.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <iostream>
#include <map>
#include <numeric>
#include <random>
#include <set>
#include <vector>

#include "wild_mvs/core/error.h"
#include "wild_mvs/core/sparse_tracker.h"
#include "wild_mvs/core/triangulation.h"

namespace wild_mvs {
namespace {

Camera LookAt(const Eigen::Vector3d& center, const Eigen::Vector3d& target) {
  Camera c;
  c.fx = c.fy = 600;
  c.cx = 320;
  c.cy = 240;
  c.width = 640;
  c.height = 480;
  const Eigen::Vector3d z = (target - center).normalized();
  const Eigen::Vector3d x = z.cross(Eigen::Vector3d::UnitZ()).normalized();
  const Eigen::Vector3d y = z.cross(x);
  c.R.row(0) = x;
  c.R.row(1) = y;
  c.R.row(2) = z;
  c.t = -c.R * center;
  return c;
}

struct FeatureWorld {
  std::vector<Camera> cameras;
  std::vector<Eigen::Vector3d> points;
  std::vector<Features> features;          // per view
  std::vector<std::vector<int>> point_of;  // per view, per feature: GT point
                                           // index or -1 (distractor)
};

void SetDescriptor(const std::vector<double>& v, uint8_t* out) {
  for (int k = 0; k < 128; ++k) {
    out[k] = static_cast<uint8_t>(std::min(
        255L, std::lround(std::max(0.0, v[k]) * Features::kDescriptorScale)));
  }
}

std::vector<double> Normalised(std::vector<double> v) {
  double n = 0;
  for (double x : v) n += x * x;
  n = std::sqrt(n);
  for (double& x : v) x = std::abs(x) / n;
  return v;
}

// n_views cameras on a ring arc of `arc_deg`, radius 3, looking at the
// origin; n_points random points in a 1.2-unit cube; pixel noise `noise`.
FeatureWorld MakeWorld(int n_views, double arc_deg, int n_points, double noise,
                       unsigned seed) {
  FeatureWorld w;
  std::mt19937 rng(seed);
  std::normal_distribution<double> gauss(0, 1);
  std::uniform_real_distribution<double> uni(0, 1);
  for (int i = 0; i < n_views; ++i) {
    const double a = arc_deg * M_PI / 180 * i / (n_views - 1);
    w.cameras.push_back(
        LookAt({3 * std::cos(a), 3 * std::sin(a), 0.8}, {0, 0, 0}));
  }
  std::vector<std::vector<double>> desc(n_points);
  // World size of each point's blob; its SIFT scale in a view is that size
  // over the pixel footprint at the point's depth (+5 % detection noise).
  std::vector<double> size(n_points);
  for (int p = 0; p < n_points; ++p) {
    w.points.emplace_back(1.2 * uni(rng) - 0.6, 1.2 * uni(rng) - 0.6,
                          1.2 * uni(rng) - 0.6);
    std::vector<double> d(128);
    for (double& x : d) x = gauss(rng);
    desc[p] = Normalised(d);
    size[p] = 0.005 + 0.02 * uni(rng);
  }
  for (int i = 0; i < n_views; ++i) {
    std::vector<Eigen::Vector2f> xy;
    std::vector<float> scale;
    std::vector<int> ids;
    for (int p = 0; p < n_points; ++p) {
      Eigen::Vector2d px;
      if (!w.cameras[i].Project(w.points[p], &px) ||
          !w.cameras[i].InImage(px, 2) || uni(rng) > 0.85) {
        continue;  // outside, or occluded / not detected
      }
      px += noise * Eigen::Vector2d(gauss(rng), gauss(rng));
      xy.push_back(px.cast<float>());
      scale.push_back(static_cast<float>(
          size[p] /
          w.cameras[i].PixelFootprint(w.cameras[i].Depth(w.points[p])) *
          (1 + 0.05 * gauss(rng))));
      ids.push_back(p);
    }
    const int n_distract = static_cast<int>(xy.size()) / 5;
    for (int k = 0; k < n_distract; ++k) {
      xy.emplace_back(640 * uni(rng), 480 * uni(rng));
      scale.push_back(static_cast<float>(2 + 6 * uni(rng)));
      ids.push_back(-1);
    }
    // Shuffle the feature order.
    std::vector<int> order(xy.size());
    std::iota(order.begin(), order.end(), 0);
    std::shuffle(order.begin(), order.end(), rng);
    Features f;
    f.descriptors.create(static_cast<int>(order.size()), 128, CV_8U);
    std::vector<int> point_of;
    for (size_t k = 0; k < order.size(); ++k) {
      const int o = order[k];
      f.xy.push_back(xy[o]);
      f.scale.push_back(scale[o]);
      f.rgb.push_back(Eigen::Matrix<uint8_t, 3, 1>(10, 20, 30));
      std::vector<double> d(128);
      if (ids[o] >= 0) {
        for (int c = 0; c < 128; ++c)
          d[c] = desc[ids[o]][c] + 0.02 * gauss(rng);
      } else {
        for (double& x : d) x = gauss(rng);
      }
      SetDescriptor(Normalised(d),
                    f.descriptors.ptr<uint8_t>(static_cast<int>(k)));
      point_of.push_back(ids[o]);
    }
    w.features.push_back(std::move(f));
    w.point_of.push_back(std::move(point_of));
  }
  return w;
}

// The ground-truth point of an output track (-1 when impure).
int TrackPoint(const FeatureWorld& w, const SparsePoint& p) {
  int id = -2;
  for (const Observation& o : p.track) {
    const Features& f = w.features[o.view];
    int found = -1;
    for (int k = 0; k < f.size(); ++k) {
      if ((f.xy[k].cast<double>() - o.xy).norm() < 1e-4) {
        found = w.point_of[o.view][k];
        break;
      }
    }
    if (found < 0) return -1;
    if (id == -2) id = found;
    if (id != found) return -1;
  }
  return id;
}

struct Quality {
  int points = 0, impure = 0;
  double median_3d = 0, p95_3d = 0, median_reproj = 0, max_reproj = 0;
};

Quality Evaluate(const FeatureWorld& w, const std::vector<SparsePoint>& pts) {
  Quality q;
  q.points = static_cast<int>(pts.size());
  std::vector<double> e3, er;
  for (const SparsePoint& p : pts) {
    const int id = TrackPoint(w, p);
    if (id < 0) {
      ++q.impure;
      continue;
    }
    e3.push_back((p.xyz - w.points[id]).norm());
    for (const Observation& o : p.track) {
      er.push_back(ReprojectionError(w.cameras[o.view], p.xyz, o.xy));
    }
  }
  auto pct = [](std::vector<double> v, double f) {
    if (v.empty()) return 1e9;
    std::sort(v.begin(), v.end());
    return v[std::min(v.size() - 1, static_cast<size_t>(f * v.size()))];
  };
  q.median_3d = pct(e3, 0.5);
  q.p95_3d = pct(e3, 0.95);
  q.median_reproj = pct(er, 0.5);
  q.max_reproj = pct(er, 1.0);
  return q;
}

// Ground-truth points visible (as features) in >= 2 views.
int Trackable(const FeatureWorld& w) {
  std::map<int, int> count;
  for (const auto& ids : w.point_of)
    for (int id : ids)
      if (id >= 0) count[id]++;
  int n = 0;
  for (const auto& kv : count) n += kv.second >= 2;
  return n;
}

std::vector<SparsePoint> RunTracker(const FeatureWorld& w,
                                    const TrackerOptions& opt,
                                    const std::vector<int>& order,
                                    TrackerStats* stats = nullptr) {
  SparseTracker tracker(opt);
  for (int i : order) tracker.AddView(i, w.cameras[i], w.features[i]);
  if (stats) *stats = tracker.Stats();
  return tracker.Points();
}

std::vector<int> Iota(int n) {
  std::vector<int> v(n);
  std::iota(v.begin(), v.end(), 0);
  return v;
}

TEST(SparseTracker, ExactFeaturesGiveExactPoints) {
  const FeatureWorld w = MakeWorld(6, 60, 600, 0.0, 1);
  TrackerOptions opt;
  TrackerStats stats;
  const auto pts = RunTracker(w, opt, Iota(6), &stats);
  const Quality q = Evaluate(w, pts);
  EXPECT_EQ(q.impure, 0);
  EXPECT_GE(q.points, 0.9 * Trackable(w));
  // Features are stored as float: ~1e-5 px rounding at 640 px.
  EXPECT_LT(q.max_reproj, 1e-3);
  EXPECT_LT(q.p95_3d, 1e-4);
  EXPECT_EQ(stats.points, q.points);
  for (const SparsePoint& p : pts) {
    EXPECT_NEAR(p.rgb.x(), 10 / 255.0, 1e-6);
    for (size_t k = 1; k < p.track.size(); ++k) {
      EXPECT_LT(p.track[k - 1].view, p.track[k].view);
    }
  }
}

TEST(SparseTracker, NoisyFeaturesWithinBounds) {
  const double noise = 0.5;  // px
  const FeatureWorld w = MakeWorld(8, 90, 1500, noise, 2);
  TrackerOptions opt;
  const auto pts = RunTracker(w, opt, Iota(8));
  const Quality q = Evaluate(w, pts);
  std::cout << q.points << " points of " << Trackable(w) << " trackable, "
            << q.impure << " impure; 3-D error median " << q.median_3d
            << " p95 " << q.p95_3d << "; reprojection median "
            << q.median_reproj << " px" << std::endl;
  // Ring of radius 3, focal 600: one pixel is ~5 mm at the object; adjacent
  // views are ~13 degrees apart.
  EXPECT_LE(q.impure, 0.01 * q.points);
  EXPECT_GE(q.points, 0.85 * Trackable(w));
  // Residual of a 2-D Gaussian of sigma `noise` has median 1.18 * noise;
  // the fit absorbs part of it.
  EXPECT_LT(q.median_reproj, 1.18 * noise);
  EXPECT_LE(q.max_reproj, opt.max_reprojection_error);
  EXPECT_LT(q.median_3d, 0.005);
  EXPECT_LT(q.p95_3d, 0.012);
}

// The pairwise matching is symmetric, so the order views arrive in changes
// only which pairs are candidates, not the quality.
TEST(SparseTracker, IncrementalOrderGivesSimilarResult) {
  const FeatureWorld w = MakeWorld(8, 90, 1000, 0.3, 3);
  TrackerOptions opt;
  std::vector<int> reversed = Iota(8);
  std::reverse(reversed.begin(), reversed.end());
  std::vector<int> shuffled = Iota(8);
  std::shuffle(shuffled.begin(), shuffled.end(), std::mt19937(4));
  const Quality a = Evaluate(w, RunTracker(w, opt, Iota(8)));
  const Quality b = Evaluate(w, RunTracker(w, opt, reversed));
  const Quality c = Evaluate(w, RunTracker(w, opt, shuffled));
  EXPECT_NEAR(a.points, b.points, 0.05 * a.points);
  EXPECT_NEAR(a.points, c.points, 0.05 * a.points);
  EXPECT_NEAR(a.median_3d, b.median_3d, 0.3 * a.median_3d);
  EXPECT_NEAR(a.median_3d, c.median_3d, 0.3 * a.median_3d);
  // Same order twice: identical (deterministic).
  const auto p1 = RunTracker(w, opt, shuffled),
             p2 = RunTracker(w, opt, shuffled);
  ASSERT_EQ(p1.size(), p2.size());
  for (size_t k = 0; k < p1.size(); ++k) EXPECT_EQ(p1[k].xyz, p2[k].xyz);
}

TEST(SparseTracker, TracksGrowAsViewsArrive) {
  const FeatureWorld w = MakeWorld(8, 90, 800, 0.2, 5);
  SparseTracker tracker(TrackerOptions{});
  size_t last_obs = 0;
  for (int i = 0; i < 8; ++i) {
    tracker.AddView(i, w.cameras[i], w.features[i]);
    size_t obs = 0;
    for (const SparsePoint& p : tracker.Points()) obs += p.track.size();
    if (i >= 1) {
      EXPECT_GT(obs, last_obs) << "view " << i;
    }
    last_obs = obs;
    EXPECT_TRUE(tracker.HasView(i));
    if (i >= 1) {
      EXPECT_FALSE(tracker.MatchedNeighbors(i).empty());
    }
    EXPECT_LE(static_cast<int>(tracker.MatchedNeighbors(i).size()),
              TrackerOptions{}.max_neighbors);
  }
  // Long tracks exist: points seen in many views were linked across pairs.
  int longest = 0;
  for (const SparsePoint& p : tracker.Points())
    longest = std::max(longest, static_cast<int>(p.track.size()));
  EXPECT_GE(longest, 6);
  EXPECT_THROW(tracker.AddView(3, w.cameras[3], w.features[3]), Error);
  EXPECT_THROW(tracker.AddView(-1, w.cameras[3], w.features[3]), Error);
}

TEST(SparseTracker, NeighboursAreBounded) {
  const FeatureWorld w = MakeWorld(12, 120, 300, 0.2, 6);
  TrackerOptions opt;
  opt.max_neighbors = 3;
  SparseTracker tracker(opt);
  for (int i = 0; i < 12; ++i) tracker.AddView(i, w.cameras[i], w.features[i]);
  for (int i = 0; i < 12; ++i) {
    const std::vector<int> nb = tracker.MatchedNeighbors(i);
    EXPECT_EQ(static_cast<int>(nb.size()), std::min(i, 3)) << "view " << i;
    // The nearest earlier views on the arc are chosen.
    for (int j : nb) EXPECT_LE(i - j, 4) << "view " << i;
  }
}

TEST(SparseTracker, RemoveViewDropsItsObservations) {
  const FeatureWorld w = MakeWorld(6, 60, 600, 0.2, 7);
  SparseTracker tracker(TrackerOptions{});
  for (int i = 0; i < 6; ++i) tracker.AddView(i, w.cameras[i], w.features[i]);
  const size_t before = tracker.Points().size();
  const size_t bytes_before = tracker.bytes();
  tracker.RemoveView(2);
  EXPECT_FALSE(tracker.HasView(2));
  EXPECT_LT(tracker.bytes(), bytes_before);
  const auto pts = tracker.Points();
  EXPECT_GT(pts.size(), 0.5 * before);
  EXPECT_LE(pts.size(), before);
  for (const SparsePoint& p : pts) {
    EXPECT_GE(p.track.size(), 2u);
    for (const Observation& o : p.track) EXPECT_NE(o.view, 2);
  }
  tracker.RemoveView(2);   // no-op
  tracker.RemoveView(99);  // unknown: no-op
  EXPECT_EQ(tracker.Points().size(), pts.size());
  // A new view can still join.
  tracker.AddView(10, w.cameras[2], w.features[2]);
  EXPECT_GE(tracker.Points().size(), pts.size());
}

// A stream with a bounded store: views are added and the oldest removed
// (4 held) for 200 additions on a ring of 12 cameras, each camera coming
// back under a new id every 12 additions. With compaction the memory follows
// the views held, not the views ever added, and every result is identical
// to the tracker without compaction.
TEST(SparseTracker, CompactionBoundsMemoryAndKeepsResults) {
  const int n = 12, kHeld = 4, kAdds = 200;
  const FeatureWorld w = MakeWorld(n, 360.0 * (n - 1) / n, 400, 0.2, 11);
  TrackerOptions opt;
  SparseTracker compact(opt);
  opt.compact = false;
  SparseTracker plain(opt);
  size_t bytes_20 = 0, plain_20 = 0, peak = 0;
  for (int id = 0; id < kAdds; ++id) {
    for (SparseTracker* t : {&compact, &plain}) {
      t->AddView(id, w.cameras[id % n], w.features[id % n]);
      if (id >= kHeld) t->RemoveView(id - kHeld);
    }
    if (id + 1 == 20) bytes_20 = compact.bytes(), plain_20 = plain.bytes();
    if (id >= 20) peak = std::max(peak, compact.bytes());
    const auto a = compact.Points(), b = plain.Points();
    ASSERT_EQ(a.size(), b.size()) << "after view " << id;
    for (size_t k = 0; k < a.size(); ++k) {
      ASSERT_EQ(a[k].xyz, b[k].xyz) << "after view " << id;
      ASSERT_EQ(a[k].track.size(), b[k].track.size());
      for (size_t o = 0; o < a[k].track.size(); ++o) {
        EXPECT_EQ(a[k].track[o].view, b[k].track[o].view);
        EXPECT_EQ(a[k].track[o].xy, b[k].track[o].xy);
      }
      EXPECT_EQ(a[k].rgb, b[k].rgb);
      EXPECT_EQ(a[k].error, b[k].error);
    }
    EXPECT_EQ(compact.MatchedNeighbors(id), plain.MatchedNeighbors(id));
    EXPECT_EQ(compact.Stats().points, plain.Stats().points);
    EXPECT_EQ(compact.Stats().views, std::min(id + 1, kHeld));
  }
  const auto pts = compact.Points();
  EXPECT_GT(pts.size(), 100u);
  for (const SparsePoint& p : pts) {
    for (const Observation& o : p.track) EXPECT_GE(o.view, kAdds - kHeld);
  }
  std::cout << "tracker bytes after 20 / " << kAdds << " views: compacted "
            << bytes_20 << " / " << compact.bytes() << ", not compacted "
            << plain_20 << " / " << plain.bytes() << "; compacted peak after "
            << "20 views " << peak << std::endl;
  EXPECT_LT(peak, 1.5 * bytes_20);
  EXPECT_GT(plain.bytes(), 3 * plain_20);  // the leak this test guards
}

// A view whose pose is wrong by more than the epipolar tolerance finds
// (almost) no matches: the known geometry gates the matching.
TEST(SparseTracker, EpipolarGateRejectsWrongPose) {
  const FeatureWorld w = MakeWorld(3, 30, 800, 0.0, 8);
  TrackerOptions opt;
  SparseTracker good(opt), bad(opt);
  good.AddView(0, w.cameras[0], w.features[0]);
  good.AddView(1, w.cameras[1], w.features[1]);
  Camera shifted = w.cameras[1];
  // Move view 1's principal point 4 px down: the ring cameras' epipolar
  // lines are roughly horizontal, so every feature is ~4 px off its line.
  shifted.cy += 4;
  bad.AddView(0, w.cameras[0], w.features[0]);
  bad.AddView(1, shifted, w.features[1]);
  EXPECT_GT(good.Stats().matches, 300);
  EXPECT_LT(bad.Stats().matches, 0.3 * good.Stats().matches);
}

// Matches whose features differ in world size (SIFT scale x pixel
// footprint) by more than a factor 1.8 are rejected.
TEST(SparseTracker, ScaleConsistencyFilter) {
  FeatureWorld w = MakeWorld(2, 20, 400, 0.0, 12);
  auto count = [&w](double factor) {
    Features f1 = w.features[1];
    for (float& s : f1.scale) s *= static_cast<float>(factor);
    SparseTracker t{TrackerOptions()};
    t.AddView(0, w.cameras[0], w.features[0]);
    t.AddView(1, w.cameras[1], f1);
    return t.Points().size();
  };
  const size_t base = count(1.0);
  EXPECT_GT(base, 200u);
  EXPECT_NEAR(static_cast<double>(count(1.3)), base, 0.1 * base);
  EXPECT_EQ(count(2.5), 0u);
}

TEST(SparseTracker, FillSceneChecksViewIndices) {
  const FeatureWorld w = MakeWorld(3, 30, 300, 0.0, 9);
  SparseTracker tracker(TrackerOptions{});
  for (int i = 0; i < 3; ++i) tracker.AddView(i, w.cameras[i], w.features[i]);
  Scene scene;
  scene.views.resize(3);
  for (int i = 0; i < 3; ++i) scene.views[i].camera = w.cameras[i];
  tracker.FillScene(&scene);
  EXPECT_EQ(scene.points.size(), tracker.Points().size());
  EXPECT_GT(scene.points.size(), 100u);
  Scene small;
  small.views.resize(2);
  EXPECT_THROW(tracker.FillScene(&small), Error);
}

TEST(SparseTracker, OptionsCheckNamesTheOption) {
  auto expect_bad = [](TrackerOptions o, const std::string& name) {
    try {
      o.Check();
      ADD_FAILURE() << name << " accepted";
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find(name), std::string::npos)
          << e.what();
    }
  };
  TrackerOptions o;
  EXPECT_NO_THROW(o.Check());
  o.max_neighbors = 0;
  expect_bad(o, "max_neighbors");
  o = TrackerOptions();
  o.max_reprojection_error = 0;
  expect_bad(o, "max_reprojection_error");
  o = TrackerOptions();
  o.min_track_length = 1;
  expect_bad(o, "min_track_length");
  o = TrackerOptions();
  o.features.max_image_size = 10;
  expect_bad(o, "max_image_size");
  o = TrackerOptions();
  o.features.max_features = -3;
  expect_bad(o, "max_features");
  EXPECT_THROW(SparseTracker t(o), Error);
}

TEST(SparseTracker, RejectsBadInput) {
  const FeatureWorld w = MakeWorld(2, 20, 100, 0.0, 10);
  SparseTracker tracker(TrackerOptions{});
  Camera bad = w.cameras[0];
  bad.fx = -1;
  EXPECT_THROW(tracker.AddView(0, bad, w.features[0]), Error);
  Features broken = w.features[0];
  broken.scale.pop_back();
  EXPECT_THROW(tracker.AddView(0, w.cameras[0], broken), Error);
  cv::Mat wrong_size(100, 100, CV_32FC3, cv::Scalar(0.5, 0.5, 0.5));
  EXPECT_THROW(tracker.AddView(0, w.cameras[0], wrong_size), Error);
  EXPECT_FALSE(tracker.HasView(0));
  // Empty feature sets are fine (a blank frame).
  tracker.AddView(0, w.cameras[0], Features());
  tracker.AddView(1, w.cameras[1], w.features[1]);
  EXPECT_TRUE(tracker.Points().empty());
}

}  // namespace
}  // namespace wild_mvs
