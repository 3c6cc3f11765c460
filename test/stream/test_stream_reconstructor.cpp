// Copyright wild_mvs authors. The ROS-free stream reconstructor behind the
// depth node, on a synthetic stream with exact ground truth.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <mutex>
#include <numeric>
#include <set>
#include <thread>

#include "pooled_depth_metrics.h"
#include "ros_test_scene.h"
#include "wild_mvs/core/error.h"
#include "wild_mvs/core/geometric_consistency.h"
#include "wild_mvs/core/metrics.h"
#include "wild_mvs/core/reconstruct_view.h"
#include "wild_mvs/core/thread_pool.h"
#include "wild_mvs/stream/stream_reconstructor.h"

namespace wild_mvs {
namespace {

using testing::SyntheticScene;

const SyntheticScene& Scene6() {
  static const SyntheticScene s = testing::Render(testing::RosTestSpec(6));
  return s;
}

StreamOptions FastOptions() {
  StreamOptions o;
  o.keyframes.min_baseline = 0.05;
  o.keyframes.min_angle_deg = 3;
  o.use_tracker = false;
  o.min_neighbors = 2;
  o.lookahead = 1;
  o.idle_flush = 0.5;
  o.num_threads = 2;
  o.mvs.global.num_neighbors = 4;
  return o;
}

// The scene's exact sparse points, observed by stamp i (frame i).
std::vector<StreamReconstructor::StampedPoint> StampedPoints(
    const SyntheticScene& s) {
  std::vector<StreamReconstructor::StampedPoint> out;
  for (const SparsePoint& p : s.scene.points) {
    StreamReconstructor::StampedPoint q;
    q.xyz = p.xyz;
    for (const Observation& o : p.track)
      q.observations.push_back({double(o.view), o.xy});
    out.push_back(q);
  }
  return out;
}

struct Collector {
  std::mutex mutex;
  std::vector<StreamResult> results;
  std::vector<std::string> errors;
  StreamReconstructor::ResultCallback OnResult() {
    return [this](const StreamResult& r) {
      std::lock_guard<std::mutex> lock(mutex);
      results.push_back(r);
    };
  }
  StreamReconstructor::ErrorCallback OnError() {
    return [this](const std::string& e) {
      std::lock_guard<std::mutex> lock(mutex);
      errors.push_back(e);
    };
  }
};

// Feeds every frame and flushes.
void Play(StreamReconstructor& stream, const SyntheticScene& s,
          const std::vector<StreamReconstructor::StampedPoint>& points) {
  stream.SetSparsePoints(points);
  for (size_t i = 0; i < s.scene.views.size(); ++i)
    stream.AddFrame(double(i), "camera", s.scene.views[i].camera, s.images[i]);
  for (int k = 0; k < 50; ++k) {
    stream.WaitIdle();
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
    stream.Tick();
    const StreamStats st = stream.Stats();
    if (st.pending == 0 && k > 8) break;
  }
  stream.WaitIdle();
}
void Play(StreamReconstructor& stream, const SyntheticScene& s) {
  Play(stream, s, StampedPoints(s));
}

TEST(StreamReconstructor, DepthMapsMatchGroundTruth) {
  const SyntheticScene& s = Scene6();
  Collector c;
  StreamReconstructor stream(FastOptions(), c.OnResult(), c.OnError());
  Play(stream, s);
  EXPECT_TRUE(c.errors.empty()) << c.errors.front();
  const StreamStats st = stream.Stats();
  EXPECT_EQ(st.keyframes_total, 6u);
  // Every keyframe is matched once and revised twice (revision 1, then the
  // final one).
  ASSERT_EQ(c.results.size(), 18u);
  EXPECT_EQ(st.reconstructed, 6u);
  EXPECT_EQ(st.early_revised, 6u);
  EXPECT_EQ(st.revised, 6u);
  EXPECT_EQ(st.unrevised, 0);
  std::set<uint32_t> ids;
  for (const StreamResult& r : c.results) {
    if (r.revision != 0) continue;
    ids.insert(r.keyframe_id);
    EXPECT_GE(r.neighbor_ids.size(), 2u);
    for (uint32_t n : r.neighbor_ids) EXPECT_NE(n, r.keyframe_id);
    const int v = static_cast<int>(r.keyframe_id);
    EXPECT_DOUBLE_EQ(r.stamp, double(v));
    EXPECT_DOUBLE_EQ(r.session, 0.0);  // stamp of the stream's first frame
    const DepthMetrics m = EvaluateDepth(r.depth.depth, r.depth.camera,
                                         s.depth[v], s.scene.views[v].camera);
    EXPECT_GT(m.completeness, 0.5) << "keyframe " << v << ": " << m.ToString();
    EXPECT_LT(m.median_rel_error, 0.01) << "keyframe " << v;
    EXPECT_GT(m.relative_accuracy[1], 0.8) << "keyframe " << v;  // 2 %
  }
  EXPECT_EQ(ids.size(), 6u);
}

// A keyframe that shares no sparse feature with any other (the tracker
// found nothing on its texture) waits for shared features while keyframes
// arrive; once the stream is idle it is matched with the neighbours that
// frustum overlap gives, as the offline tool matches such a view at once.
// Every keyframe gets a depth map, and this one is as accurate.
TEST(StreamReconstructor, KeyframeWithoutSharedFeaturesIsMatchedWhenIdle) {
  const SyntheticScene& s = Scene6();
  std::vector<StreamReconstructor::StampedPoint> points = StampedPoints(s);
  for (StreamReconstructor::StampedPoint& p : points) {
    auto& obs = p.observations;
    obs.erase(std::remove_if(obs.begin(), obs.end(),
                             [](const auto& o) { return o.stamp == 0.0; }),
              obs.end());
  }
  Collector c;
  StreamReconstructor stream(FastOptions(), c.OnResult(), c.OnError());
  Play(stream, s, points);
  EXPECT_TRUE(c.errors.empty()) << c.errors.front();
  std::set<uint32_t> ids;
  bool first = false;
  for (const StreamResult& r : c.results) {
    if (r.revision != 0) continue;
    ids.insert(r.keyframe_id);
    if (r.keyframe_id != 0) continue;
    first = true;
    const DepthMetrics m = EvaluateDepth(r.depth.depth, r.depth.camera,
                                         s.depth[0], s.scene.views[0].camera);
    std::printf("keyframe 0 without shared features: %s\n",
                m.ToString().c_str());
    EXPECT_GT(m.completeness, 0.5) << m.ToString();
    EXPECT_LT(m.median_rel_error, 0.01);
  }
  EXPECT_TRUE(first) << "keyframe 0 got no depth map";
  EXPECT_EQ(ids.size(), 6u);
  // ... and its final revision, as every other keyframe.
  EXPECT_EQ(stream.Stats().revised, 6u);
  EXPECT_EQ(stream.Stats().unrevised, 0);
}

// The live path runs the offline pipeline's steps: a keyframe is delivered
// as matched, mostly against earlier keyframes (revision 0, not final),
// then matched again once later keyframes exist, with neighbours on both
// sides, and checked against the maps its neighbours have then (revision
// 1, not final), then checked against its neighbours' maps matched again
// (revision 2, final). Revision 1 is more accurate than revision 0; the
// final maps are as good as the offline pipeline's on the same images.
TEST(StreamReconstructor, FinalRevisionsAreTheOfflinePipelines) {
  const SyntheticScene& s = Scene6();
  Collector c;
  const StreamOptions options = FastOptions();
  StreamReconstructor stream(options, c.OnResult(), c.OnError());
  Play(stream, s);
  EXPECT_TRUE(c.errors.empty()) << c.errors.front();
  std::map<uint32_t, StreamResult> first, early, last;
  for (const StreamResult& r : c.results) {
    if (r.revision == 0) {
      EXPECT_FALSE(r.final_revision);
      EXPECT_FALSE(first.count(r.keyframe_id));
      first[r.keyframe_id] = r;
    } else if (r.revision == 1) {
      EXPECT_FALSE(r.final_revision);
      EXPECT_TRUE(first.count(r.keyframe_id)) << "revision 1 before 0";
      EXPECT_FALSE(early.count(r.keyframe_id));
      EXPECT_EQ(r.stamp_ns, first[r.keyframe_id].stamp_ns);
      early[r.keyframe_id] = r;
    } else {
      EXPECT_EQ(r.revision, 2);
      EXPECT_TRUE(r.final_revision);
      EXPECT_TRUE(early.count(r.keyframe_id)) << "revision 2 before 1";
      EXPECT_FALSE(last.count(r.keyframe_id));
      EXPECT_EQ(r.stamp_ns, first[r.keyframe_id].stamp_ns);
      last[r.keyframe_id] = r;
    }
  }
  ASSERT_EQ(first.size(), 6u);
  ASSERT_EQ(early.size(), 6u);
  ASSERT_EQ(last.size(), 6u);
  // Inner keyframes are revised with neighbours on both sides.
  for (uint32_t id = 1; id + 1 < 6; ++id) {
    const std::vector<uint32_t>& n = last.at(id).neighbor_ids;
    EXPECT_TRUE(
        std::any_of(n.begin(), n.end(), [&](uint32_t k) { return k < id; }))
        << "keyframe " << id;
    EXPECT_TRUE(
        std::any_of(n.begin(), n.end(), [&](uint32_t k) { return k > id; }))
        << "keyframe " << id;
  }
  // Offline: every view matched over the whole scene, then filtered.
  const int n = static_cast<int>(s.scene.views.size());
  ImageCache images([&s](int v) { return s.images[v]; }, 256);
  ThreadPool pool(2);
  std::vector<DepthMap> raw(n);
  for (int v = 0; v < n; ++v)
    raw[v] = ReconstructView(s.scene, v, images, options.mvs, &pool, nullptr,
                             cv::Mat());
  testing::PooledDepthMetrics offline, live_first, live_early, live_final;
  for (int v = 0; v < n; ++v) {
    DepthMap m = raw[v];
    m.depth = raw[v].depth.clone();
    std::vector<const DepthMap*> neighbors;
    for (int k : raw[v].neighbors) neighbors.push_back(&raw[k]);
    ConsistencyStats stats;
    FilterByConsistency(&m, neighbors, options.mvs.consistency, &stats);
    const Camera& gt_camera = s.scene.views[v].camera;
    offline.Add(EvaluateDepth(m.depth, m.camera, s.depth[v], gt_camera));
    const DepthMap& d0 = first.at(v).depth;
    const DepthMap& d1 = early.at(v).depth;
    const DepthMap& d2 = last.at(v).depth;
    live_first.Add(EvaluateDepth(d0.depth, d0.camera, s.depth[v], gt_camera));
    live_early.Add(EvaluateDepth(d1.depth, d1.camera, s.depth[v], gt_camera));
    live_final.Add(EvaluateDepth(d2.depth, d2.camera, s.depth[v], gt_camera));
  }
  std::printf(
      "coverage / within 1 %% / off > 5 %%: first %.3f %.3f %.2f %%, "
      "revision 1 %.3f %.3f %.2f %%, final %.3f %.3f %.2f %%, offline %.3f "
      "%.3f %.2f %%\n",
      live_first.coverage(), live_first.within1(), 100 * live_first.off5pc(),
      live_early.coverage(), live_early.within1(), 100 * live_early.off5pc(),
      live_final.coverage(), live_final.within1(), 100 * live_final.off5pc(),
      offline.coverage(), offline.within1(), 100 * offline.off5pc());
  EXPECT_GT(live_early.within1(), live_first.within1());
  EXPECT_LT(live_early.off5pc(), live_first.off5pc());
  EXPECT_GT(live_final.within1(), live_first.within1());
  EXPECT_LT(live_final.off5pc(), live_first.off5pc());
  EXPECT_GT(live_final.within1(), offline.within1() - 0.005);
  EXPECT_LT(live_final.off5pc(), offline.off5pc() + 0.002);
  EXPECT_GT(live_final.coverage(), offline.coverage() - 0.02);
}

// Revision 1 comes within `lookahead` keyframes: keyframes fed one at a
// time, each after the work it made possible is done (a stream slower than
// the machine), keyframe k is revised once keyframe k + lookahead arrives
// and it has mvs.mpgc.min_active_views neighbours, not before; its final
// revision (2) follows, once.
TEST(StreamReconstructor, RevisionOneComesWithinLookaheadKeyframes) {
  const SyntheticScene& s = Scene6();
  StreamOptions o = FastOptions();
  o.lookahead = 2;
  o.idle_flush = 1e3;  // no idle flush while frames arrive
  Collector c;
  StreamReconstructor stream(o, c.OnResult(), c.OnError());
  stream.SetSparsePoints(StampedPoints(s));
  const int n = static_cast<int>(s.scene.views.size());
  for (int i = 0; i < n; ++i) {
    stream.AddFrame(double(i), "camera", s.scene.views[i].camera, s.images[i]);
    stream.WaitIdle();
    std::set<uint32_t> revised;
    {
      std::lock_guard<std::mutex> lock(c.mutex);
      for (const StreamResult& r : c.results)
        if (r.revision == 1) revised.insert(r.keyframe_id);
    }
    // Keyframe k has i other keyframes (every view of the scene sees every
    // other's points): its revision 1 needs MPGC's active views too.
    for (int k = 0; k < n; ++k)
      EXPECT_EQ(revised.count(k) > 0,
                k + o.lookahead <= i && i >= o.mvs.mpgc.min_active_views)
          << "keyframe " << k << " after keyframe " << i;
  }
  EXPECT_TRUE(c.errors.empty()) << c.errors.front();
  // Each revision at most once, in order (the finals of the last keyframes
  // come at the idle flush: FinalRevisionsAreTheOfflinePipelines).
  std::map<uint32_t, std::vector<int>> revisions;
  for (const StreamResult& r : c.results)
    revisions[r.keyframe_id].push_back(r.revision);
  for (const auto& [id, seen] : revisions) {
    std::vector<int> expected(seen.size());
    std::iota(expected.begin(), expected.end(), 0);
    EXPECT_EQ(seen, expected) << "keyframe " << id;
  }
}

// A stream's first keyframe has one neighbour when the second arrives. By
// default (min_neighbors 1, a revision to follow) both are previewed from
// those two views at once, instead of waiting for a fourth keyframe; with
// the consistency step off there is no revision, and a first map is final:
// it waits for mvs.mpgc.min_active_views neighbours.
TEST(StreamReconstructor, FirstKeyframesArePreviewedFromTwoViews) {
  const SyntheticScene& s = Scene6();
  for (const bool consistency : {true, false}) {
    StreamOptions o = FastOptions();
    o.min_neighbors = StreamOptions().min_neighbors;  // the default
    o.idle_flush = 1e3;                               // no idle flush
    o.mvs.ablation.consistency = consistency;
    Collector c;
    StreamReconstructor stream(o, c.OnResult(), c.OnError());
    stream.SetSparsePoints(StampedPoints(s));
    for (size_t i = 0; i < 2; ++i)
      stream.AddFrame(double(i), "camera", s.scene.views[i].camera,
                      s.images[i]);
    stream.WaitIdle();
    EXPECT_TRUE(c.errors.empty()) << c.errors.front();
    if (!consistency) {
      EXPECT_TRUE(c.results.empty()) << "a final map from two views";
      continue;
    }
    // The two previews (and keyframe 0's revision 1: lookahead 1).
    std::vector<StreamResult> previews;
    for (const StreamResult& r : c.results)
      if (r.revision == 0) previews.push_back(r);
    ASSERT_EQ(previews.size(), 2u);
    for (const StreamResult& r : previews) {
      EXPECT_FALSE(r.final_revision);
      const uint32_t other = 1 - r.keyframe_id;
      EXPECT_EQ(r.neighbor_ids, std::vector<uint32_t>{other});
      const int v = static_cast<int>(r.keyframe_id);
      const DepthMetrics m = EvaluateDepth(r.depth.depth, r.depth.camera,
                                           s.depth[v], s.scene.views[v].camera);
      std::printf("two-view preview of keyframe %d: %s\n", v,
                  m.ToString().c_str());
      EXPECT_GT(m.completeness, 0.3) << "keyframe " << v;
      EXPECT_LT(m.median_rel_error, 0.01) << "keyframe " << v;
      EXPECT_GT(m.relative_accuracy[1], 0.8) << "keyframe " << v;  // 2 %
    }
  }
}

// A session that a pose jump started may be a glitch that ends a frame
// later (its frames consistent with each other, not with the world): there
// two keyframes make no preview; a keyframe waits for
// mvs.mpgc.min_active_views neighbours, as without a revision to follow.
TEST(StreamReconstructor, NoTwoViewPreviewsAfterAPoseJump) {
  const SyntheticScene& s = Scene6();
  StreamOptions o = FastOptions();
  o.min_neighbors = StreamOptions().min_neighbors;
  o.idle_flush = 1e3;
  o.max_pose_jump = 1.0;
  const Eigen::Vector3d jump(3.0, 0.0, 0.0);
  // Frames 0 and 1 (stamps 0, 0.25), then frames 2 and 3 moved by 3 m
  // (stamps 0.5, 0.75) with their sparse points moved alike: the second
  // pair is as consistent as the first; only its session began at a jump.
  std::vector<StreamReconstructor::StampedPoint> points;
  for (const StreamReconstructor::StampedPoint& p : StampedPoints(s)) {
    StreamReconstructor::StampedPoint before, after;
    before.xyz = p.xyz;
    after.xyz = p.xyz + jump;
    for (const auto& obs : p.observations) {
      if (obs.stamp < 2)
        before.observations.push_back({obs.stamp * 0.25, obs.xy});
      else if (obs.stamp < 4)
        after.observations.push_back({obs.stamp * 0.25, obs.xy});
    }
    if (before.observations.size() >= 2) points.push_back(before);
    if (after.observations.size() >= 2) points.push_back(after);
  }
  Collector c;
  StreamReconstructor stream(o, c.OnResult(), c.OnError());
  stream.SetSparsePoints(points);
  for (int i = 0; i < 4; ++i) {
    Camera camera = s.scene.views[i].camera;
    if (i >= 2) camera.t -= camera.R * jump;  // centre moved by `jump`
    const StreamReconstructor::FrameStatus status =
        stream.AddFrame(0.25 * i, "camera", camera, s.images[i]);
    EXPECT_EQ(status, i == 2 ? StreamReconstructor::FrameStatus::kReset
                             : StreamReconstructor::FrameStatus::kKeyframe)
        << "frame " << i;
    if (i == 1) stream.WaitIdle();  // the first pair's previews
  }
  stream.WaitIdle();
  EXPECT_TRUE(c.errors.empty()) << c.errors.front();
  int previews = 0;
  for (const StreamResult& r : c.results) {
    EXPECT_LT(r.stamp, 0.3) << "keyframe of the jumped session";
    previews += r.revision == 0;
  }
  EXPECT_EQ(previews, 2);
}

// Real-world stamps (epoch seconds with microseconds, 30 Hz) come back bit
// for bit: a double cannot hold 1305031102.175304 exactly, so stamps must
// never pass through one on their way to the outputs.
TEST(StreamReconstructor, EpochStampsPassThroughExactly) {
  const SyntheticScene& s = Scene6();
  Collector c;
  StreamReconstructor stream(FastOptions(), c.OnResult(), c.OnError());
  const uint64_t t0 = 1305031102175304000ull;  // TUM RGB-D fr1/xyz
  std::set<uint64_t> stamps;
  std::vector<StreamReconstructor::StampedPoint> points = StampedPoints(s);
  auto stamp_of = [&](size_t i) -> uint64_t {
    return t0 + i * 33333000ull + i * 17;
  };
  for (auto& p : points)
    for (auto& o : p.observations)
      o.stamp =
          static_cast<double>(stamp_of(static_cast<size_t>(o.stamp))) * 1e-9;
  stream.SetSparsePoints(points);
  for (size_t i = 0; i < s.scene.views.size(); ++i) {
    stamps.insert(stamp_of(i));
    stream.AddFrame(stamp_of(i), "camera", s.scene.views[i].camera,
                    s.images[i]);
  }
  for (int k = 0; k < 50; ++k) {
    stream.WaitIdle();
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
    stream.Tick();
    if (stream.Stats().pending == 0 && k > 8) break;
  }
  stream.WaitIdle();
  ASSERT_EQ(c.results.size(), 18u);  // each keyframe and its revisions
  for (const StreamResult& r : c.results) {
    EXPECT_EQ(r.stamp_ns, stamp_of(r.keyframe_id));
    EXPECT_EQ(r.session_ns, t0);
    ASSERT_EQ(r.neighbor_stamps_ns.size(), r.neighbor_ids.size());
    for (size_t n = 0; n < r.neighbor_ids.size(); ++n)
      EXPECT_EQ(r.neighbor_stamps_ns[n], stamp_of(r.neighbor_ids[n]));
  }
}

TEST(StreamReconstructor, KeyframeOwnerIsAnEvenHashOfTheStamp) {
  // Deterministic, in range, and even over the stamps of a 30 Hz stream.
  int counts[3] = {0, 0, 0};
  const uint64_t t0 = 1700000000123456789ull;
  for (int i = 0; i < 3000; ++i) {
    const uint64_t stamp = t0 + uint64_t(i) * 33333333ull;
    const int w = KeyframeOwner(stamp, 3);
    ASSERT_GE(w, 0);
    ASSERT_LT(w, 3);
    EXPECT_EQ(w, KeyframeOwner(stamp, 3));
    ++counts[w];
  }
  for (int c : counts) {
    EXPECT_GT(c, 900);
    EXPECT_LT(c, 1100);
  }
  EXPECT_EQ(KeyframeOwner(t0, 1), 0);
  EXPECT_THROW(KeyframeOwner(t0, 0), Error);
}

// Three workers fed the same frames split the keyframes by the stamp hash:
// every keyframe matched exactly once (and revised by the same worker).
TEST(StreamReconstructor, WorkersSplitKeyframesByStampHash) {
  const SyntheticScene& s = Scene6();
  std::map<uint64_t, int> owner_of;
  for (int w = 0; w < 3; ++w) {
    StreamOptions o = FastOptions();
    o.worker_count = 3;
    o.worker_index = w;
    Collector c;
    StreamReconstructor stream(o, c.OnResult(), c.OnError());
    Play(stream, s);
    for (const StreamResult& r : c.results) {
      EXPECT_EQ(KeyframeOwner(r.stamp_ns, 3), w);
      if (r.revision != 0) continue;
      EXPECT_TRUE(owner_of.emplace(r.stamp_ns, w).second)
          << "stamp " << r.stamp_ns << " done twice";
    }
  }
  EXPECT_EQ(owner_of.size(), 6u);  // none missing
}

// A worker fed by a selector (select_keyframes = false) keeps every frame
// as a keyframe and owns the same keyframes whatever others it missed; a
// selector (reconstruct = false) reconstructs nothing and hands out its
// tracks by stamp.
TEST(StreamReconstructor, SelectorAndWorkerRoles) {
  const SyntheticScene& s = Scene6();
  StreamOptions so = FastOptions();
  so.use_tracker = true;
  so.reconstruct = false;
  Collector sc;
  StreamReconstructor selector(so, sc.OnResult(), sc.OnError());
  std::vector<uint64_t> keyframe_stamps;
  for (size_t i = 0; i < s.scene.views.size(); ++i) {
    const auto st = selector.AddFrame(double(i), "camera",
                                      s.scene.views[i].camera, s.images[i]);
    if (st != StreamReconstructor::FrameStatus::kKeyframe) continue;
    StreamReconstructor::KeyframeInfo info;
    ASSERT_TRUE(selector.Newest(&info));
    EXPECT_EQ(info.id, keyframe_stamps.size());
    EXPECT_EQ(info.session_ns, 0u);
    keyframe_stamps.push_back(info.stamp_ns);
  }
  selector.Tick();
  selector.WaitIdle();
  ASSERT_EQ(keyframe_stamps.size(), 6u);
  EXPECT_TRUE(sc.results.empty());
  EXPECT_EQ(selector.Stats().reconstructed, 0u);
  const std::vector<StreamReconstructor::StampedPoint> tracked =
      selector.TrackedPoints();
  ASSERT_GT(tracked.size(), 100u);
  for (const auto& p : tracked) {
    ASSERT_GE(p.observations.size(), 2u);
    for (const auto& o : p.observations) {
      const int v = static_cast<int>(std::lround(o.stamp));
      ASSERT_GE(v, 0);
      ASSERT_LT(v, 6);
      // The observation is where the point projects in that frame.
      Eigen::Vector2d xy;
      ASSERT_TRUE(s.scene.views[v].camera.Project(p.xyz, &xy));
      EXPECT_LT((xy - o.xy).norm(), 3.0);
    }
  }

  // Points given by stamp (a SLAM system's, sparse_source topic) are handed
  // on the same way, restricted to the keyframes held.
  StreamOptions to = so;
  to.use_tracker = false;
  StreamReconstructor topic_selector(to, sc.OnResult(), sc.OnError());
  topic_selector.SetSparsePoints(StampedPoints(s));
  for (size_t i = 0; i < s.scene.views.size(); ++i)
    topic_selector.AddFrame(double(i), "camera", s.scene.views[i].camera,
                            s.images[i]);
  size_t with_two = 0;
  for (const auto& p : StampedPoints(s)) with_two += p.observations.size() >= 2;
  EXPECT_EQ(topic_selector.TrackedPoints().size(), with_two);

  // Worker 0 of 2 misses the keyframes it does not own but one (as a
  // worker that dropped messages would): it still owns, and reconstructs,
  // exactly its share.
  StreamOptions wo = FastOptions();
  wo.select_keyframes = false;
  wo.worker_count = 2;
  wo.worker_index = 0;
  Collector wc;
  StreamReconstructor worker(wo, wc.OnResult(), wc.OnError());
  EXPECT_TRUE(worker.FollowSession(0));
  EXPECT_FALSE(worker.FollowSession(0));
  worker.SetSparsePoints(StampedPoints(s));
  std::set<uint64_t> mine;
  bool skipped_one = false;
  for (size_t i = 0; i < s.scene.views.size(); ++i) {
    const uint64_t stamp = uint64_t(i) * 1000000000ull;
    const bool owned = KeyframeOwner(stamp, 2) == 0;
    if (owned) mine.insert(stamp);
    if (!owned && !skipped_one) {
      skipped_one = true;
      continue;
    }
    // Every frame given is a keyframe (no selection thresholds).
    EXPECT_EQ(
        worker.AddFrame(stamp, "camera", s.scene.views[i].camera, s.images[i]),
        StreamReconstructor::FrameStatus::kKeyframe);
  }
  ASSERT_TRUE(skipped_one);
  for (int k = 0; k < 50 && worker.Stats().reconstructed < mine.size(); ++k) {
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
    worker.Tick();
    worker.WaitIdle();
  }
  std::set<uint64_t> done;
  for (const StreamResult& r : wc.results) {
    done.insert(r.stamp_ns);
    EXPECT_EQ(r.session_ns, 0u);
  }
  EXPECT_EQ(done, mine);
  // A new session of the selector restarts the worker.
  EXPECT_TRUE(worker.FollowSession(7000000000ull));
  EXPECT_EQ(worker.Stats().keyframes, 0u);
}

TEST(StreamReconstructor, KeyframeSelectionOrderAndResets) {
  const SyntheticScene& s = Scene6();
  StreamOptions o = FastOptions();
  o.min_neighbors = 100;  // never reconstruct: only selection is tested
  o.idle_flush = 1e6;
  o.lookahead = 1000;
  o.max_pose_jump = 5.0;
  Collector c;
  StreamReconstructor stream(o, c.OnResult(), c.OnError());
  using S = StreamReconstructor::FrameStatus;
  const Camera& c0 = s.scene.views[0].camera;
  EXPECT_EQ(stream.Stats().session, -1.0);  // no frame yet
  EXPECT_EQ(stream.AddFrame(10.0, "cam", c0, s.images[0]), S::kKeyframe);
  EXPECT_EQ(stream.Stats().session, 10.0);  // the first frame starts it
  // Same pose again: not a keyframe.
  EXPECT_EQ(stream.AddFrame(10.1, "cam", c0, s.images[0]), S::kNotKeyframe);
  // Older stamp (small step back): out of order, dropped; IsOutOfOrder
  // tells before (the node skips converting such frames).
  EXPECT_TRUE(stream.IsOutOfOrder(10050000000ull));
  EXPECT_TRUE(stream.IsOutOfOrder(10100000000ull));   // the same stamp
  EXPECT_FALSE(stream.IsOutOfOrder(10100000001ull));  // later
  EXPECT_FALSE(stream.IsOutOfOrder(1000000000ull));   // far back: a reset
  EXPECT_EQ(stream.AddFrame(10.05, "cam", s.scene.views[1].camera, s.images[1]),
            S::kOutOfOrder);
  EXPECT_EQ(stream.AddFrame(10.2, "cam", s.scene.views[1].camera, s.images[1]),
            S::kKeyframe);
  EXPECT_EQ(stream.Stats().keyframes, 2u);
  // Big jump back in time (bag loop): reset, then this frame starts over.
  EXPECT_EQ(stream.AddFrame(1.0, "cam", s.scene.views[2].camera, s.images[2]),
            S::kReset);
  EXPECT_EQ(stream.Stats().keyframes, 1u);
  EXPECT_EQ(stream.Stats().session, 1.0);  // a new session at the reset
  EXPECT_EQ(stream.Stats().keyframes_total, 3u);
  // Pose jump of 50 m within 1 s: reset.
  Camera far = s.scene.views[3].camera;
  far.t += Eigen::Vector3d(50, 0, 0);
  EXPECT_EQ(stream.AddFrame(1.1, "cam", far, s.images[3]), S::kReset);
  EXPECT_EQ(stream.Stats().resets, 2u);
  EXPECT_EQ(stream.Stats().session, 1.1);
  // Invalid camera / image: Error, state untouched.
  Camera bad = c0;
  bad.fx = 0;
  EXPECT_THROW(stream.AddFrame(2.0, "cam", bad, s.images[0]), Error);
  EXPECT_THROW(stream.AddFrame(2.0, "cam", c0, cv::Mat(10, 10, CV_32FC3)),
               Error);
  EXPECT_TRUE(c.results.empty());
}

// The keyframe test runs on the pose alone: the image of a frame that is not
// kept is never made (the node decodes and undistorts only keyframes), and
// a frame whose image cannot be made is dropped without becoming one.
TEST(StreamReconstructor, OnlyKeyframeImagesAreMade) {
  const SyntheticScene& s = Scene6();
  StreamOptions o = FastOptions();
  o.min_neighbors = 100;  // selection only
  o.idle_flush = 1e6;
  Collector c;
  StreamReconstructor stream(o, c.OnResult(), c.OnError());
  using S = StreamReconstructor::FrameStatus;
  int made = 0;
  auto image_of = [&](int i) {
    return [&, i](Camera*, cv::Mat* image) {
      ++made;
      *image = s.images[i];
      return true;
    };
  };
  const uint64_t t0 = 1795000000000000000ull;  // epoch stamps (ns)
  const uint64_t dt = 33333333ull;             // 30 Hz
  // Frame 0, then 9 frames at the same pose (a robot standing still),
  // then frame 1's pose.
  EXPECT_EQ(stream.AddFrame(t0, "cam", s.scene.views[0].camera, image_of(0)),
            S::kKeyframe);
  for (int k = 1; k < 10; ++k)
    EXPECT_EQ(stream.AddFrame(t0 + k * dt, "cam", s.scene.views[0].camera,
                              image_of(0)),
              S::kNotKeyframe);
  EXPECT_EQ(made, 1);
  // A keyframe whose image fails: dropped, not kept.
  EXPECT_EQ(stream.AddFrame(t0 + 10 * dt, "cam", s.scene.views[1].camera,
                            [&](Camera*, cv::Mat*) { return false; }),
            S::kDropped);
  EXPECT_EQ(stream.Stats().keyframes, 1u);
  // The image function may change the intrinsics (undistortion): the
  // keyframe keeps the camera it returns.
  Camera undistorted;
  EXPECT_EQ(stream.AddFrame(t0 + 11 * dt, "cam", s.scene.views[1].camera,
                            [&](Camera* cam, cv::Mat* image) {
                              cam->fx *= 1.01;
                              undistorted = *cam;
                              *image = s.images[1];
                              return true;
                            }),
            S::kKeyframe);
  EXPECT_EQ(stream.Stats().keyframes, 2u);
  EXPECT_EQ(stream.Stats().frames, 12u);
  EXPECT_DOUBLE_EQ(undistorted.fx, s.scene.views[1].camera.fx * 1.01);
}

// Tick() is cheap when nothing changed: no scheduling pass (store snapshot
// and view selection) until a keyframe, points or a finished map arrive,
// and one idle flush per quiet spell.
TEST(StreamReconstructor, TickSchedulesOnlyWhenSomethingChanged) {
  const SyntheticScene& s = Scene6();
  StreamOptions o = FastOptions();
  o.min_neighbors = 100;  // keyframes never ready: they stay schedulable
  o.idle_flush = 0.05;
  Collector c;
  StreamReconstructor stream(o, c.OnResult(), c.OnError());
  for (int i = 0; i < 3; ++i)
    stream.AddFrame(double(i), "cam", s.scene.views[i].camera, s.images[i]);
  const uint64_t after_frames = stream.Stats().scheduling_passes;
  EXPECT_GE(after_frames, 2u);  // the 2nd and 3rd keyframe scheduled
  // Wait for the quiet spell: the first Tick then flushes once.
  const auto t0 = std::chrono::steady_clock::now();
  while (std::chrono::steady_clock::now() - t0 < std::chrono::milliseconds(60))
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  for (int k = 0; k < 100; ++k) stream.Tick();
  EXPECT_EQ(stream.Stats().scheduling_passes, after_frames + 1);
  // New points: scheduled at once (not by a Tick).
  stream.SetSparsePoints(StampedPoints(s));
  EXPECT_EQ(stream.Stats().scheduling_passes, after_frames + 2);
  for (int k = 0; k < 100; ++k) stream.Tick();
  EXPECT_EQ(stream.Stats().scheduling_passes, after_frames + 2);
}

// Live tuning: new keyframe thresholds change the selection from the next
// frame on; invalid options are refused and the old ones kept.
TEST(StreamReconstructor, SetOptionsRetunesKeyframeSelectionLive) {
  const SyntheticScene& s = Scene6();
  StreamOptions o = FastOptions();
  o.min_neighbors = 100;  // selection only
  o.idle_flush = 1e6;
  Collector c;
  StreamReconstructor stream(o, c.OnResult(), c.OnError());
  using S = StreamReconstructor::FrameStatus;
  EXPECT_EQ(stream.AddFrame(0.0, "cam", s.scene.views[0].camera, s.images[0]),
            S::kKeyframe);
  // Views are 10 degrees (0.45 m) apart: with 100 m and 90 degrees no frame
  // is a keyframe any more.
  StreamOptions strict = stream.Options();
  strict.keyframes.min_baseline = 100;
  strict.keyframes.min_angle_deg = 90;
  stream.SetOptions(strict);
  EXPECT_EQ(stream.AddFrame(1.0, "cam", s.scene.views[1].camera, s.images[1]),
            S::kNotKeyframe);
  // Invalid: refused, the strict thresholds stay.
  StreamOptions bad = strict;
  bad.mvs.mpgc.window = 4;  // must be odd
  EXPECT_THROW(stream.SetOptions(bad), Error);
  EXPECT_EQ(stream.Options().mvs.mpgc.window, strict.mvs.mpgc.window);
  EXPECT_EQ(stream.AddFrame(2.0, "cam", s.scene.views[2].camera, s.images[2]),
            S::kNotKeyframe);
  // Back to the defaults: the next view is a keyframe again.
  stream.SetOptions(o);
  EXPECT_EQ(stream.AddFrame(3.0, "cam", s.scene.views[3].camera, s.images[3]),
            S::kKeyframe);
}

// Shutdown cancels a running depth map (a node must end within roslaunch's
// SIGINT-to-SIGKILL escalation, whatever the image size): the map in
// progress is stopped and counted, nothing is delivered.
TEST(StreamReconstructor, ShutdownCancelsARunningDepthMap) {
  testing::SyntheticSpec spec = testing::RosTestSpec(4);
  spec.width = 640;  // a depth map of several CPU-seconds
  spec.height = 480;
  spec.focal = 600;
  const SyntheticScene s = testing::Render(spec);
  StreamOptions o = FastOptions();
  o.num_threads = 1;
  o.lookahead = 0;
  Collector c;
  StreamReconstructor stream(o, c.OnResult(), c.OnError());
  stream.SetSparsePoints(StampedPoints(s));
  for (size_t i = 0; i < s.scene.views.size(); ++i)
    stream.AddFrame(double(i), "camera", s.scene.views[i].camera, s.images[i]);
  // Wait (on the condition) until a depth map is being computed.
  for (int k = 0; k < 60000 && stream.Stats().running == 0; ++k)
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  ASSERT_EQ(stream.Stats().running, 1);
  stream.Shutdown();
  const StreamStats st = stream.Stats();
  EXPECT_EQ(st.cancelled, 1u);
  EXPECT_EQ(st.running, 0);
  EXPECT_EQ(st.reconstructed, 0u);
  std::lock_guard<std::mutex> lock(c.mutex);
  EXPECT_TRUE(c.results.empty());
  EXPECT_TRUE(c.errors.empty());
}

TEST(StreamReconstructor, StoreStaysBoundedOnALongStream) {
  const SyntheticScene& s = Scene6();
  StreamOptions o = FastOptions();
  o.store.max_keyframes = 4;
  o.min_neighbors = 100;  // selection and eviction only
  Collector c;
  StreamReconstructor stream(o, c.OnResult(), c.OnError());
  for (int loop = 0; loop < 3; ++loop)
    for (size_t i = 0; i < s.scene.views.size(); ++i) {
      stream.AddFrame(loop * 100.0 + i * 0.1, "cam", s.scene.views[i].camera,
                      s.images[i]);
      EXPECT_LE(stream.Stats().keyframes, 4u);
    }
  EXPECT_GT(stream.Stats().evicted_waiting, 0u);  // counted, not silent
}

TEST(StreamReconstructor, OptionsAreChecked) {
  StreamOptions o;
  o.worker_index = 2;
  o.worker_count = 2;
  EXPECT_THROW(o.Check(), Error);
  o = StreamOptions();
  o.max_pending = 0;
  EXPECT_THROW(StreamReconstructor(o, nullptr), Error);
}

}  // namespace
}  // namespace wild_mvs
