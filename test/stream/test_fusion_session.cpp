// Copyright wild_mvs authors. The fusion node's ROS-free core: the reorder
// buffer (keyframe order across workers, timeout), revisions, sessions
// ("keep" / "reset" with the session save), Reset, the final flush.
#include <gtest/gtest.h>

#include <filesystem>
#include <string>
#include <thread>
#include <vector>

#include "../unit/test_fusion_scene.h"
#include "test_paths.h"
#include "wild_mvs/core/error.h"
#include "wild_mvs/stream/fusion_session.h"

namespace wild_mvs {
namespace {

namespace fs = std::filesystem;
using Clock = ReorderBuffer::Clock;
constexpr int kViews = 8;

FusionView MakeView(uint64_t session, uint32_t id, uint64_t stamp,
                    Clock::time_point arrived = Clock::now()) {
  FusionView v;
  v.keyframe_id = id;
  v.session_ns = session;
  v.stamp_ns = stamp;
  v.arrived = arrived;
  return v;
}

// View i of the analytic ring scene as keyframe `id` of `session`, stamped
// 1000 * (session + 1) + i; its neighbours are the ring neighbours' stamps.
FusionView SceneView(int i, uint64_t session, uint32_t id) {
  static const fusion_test::AnalyticScene scene = [] {
    fusion_test::AnalyticScene s;
    s.width = 80;
    s.height = 60;
    s.focal = 70;
    return s;
  }();
  const uint64_t base = 1000 * (session + 1);
  FusionView v = MakeView(session, id, base + i);
  v.map = scene.Render(i, kViews);
  for (int n : v.map.neighbors) v.neighbor_stamps_ns.push_back(base + n);
  v.image = cv::Mat(scene.height, scene.width, CV_32FC3, cv::Scalar(0.5));
  return v;
}

constexpr size_t kNoBudget = size_t(1) << 40;

TEST(ReorderBuffer, ReleasesViewsInKeyframeOrder) {
  ReorderBuffer b(2.0, 30.0, kNoBudget);
  const Clock::time_point t0 = Clock::now();
  const uint64_t S = 77;
  FusionView out;
  b.Insert(MakeView(S, 1, 101, t0));  // keyframe 1 before 0
  EXPECT_TRUE(b.Contains(101));
  EXPECT_FALSE(b.PopReady(t0, &out));  // a new session starts with id 0
  b.Insert(MakeView(S, 0, 100, t0));
  ASSERT_TRUE(b.PopReady(t0, &out));
  EXPECT_EQ(out.keyframe_id, 0u);
  b.StartSession(S);
  b.Fused(S, 0);
  ASSERT_TRUE(b.PopReady(t0, &out));
  EXPECT_EQ(out.keyframe_id, 1u);
  b.Fused(S, 1);
  EXPECT_FALSE(b.PopReady(t0, &out));  // empty
  // A gap (keyframe 2 missing): 3 waits for the timeout.
  b.Insert(MakeView(S, 3, 103, t0));
  EXPECT_FALSE(b.PopReady(t0 + std::chrono::milliseconds(1999), &out));
  ASSERT_TRUE(b.PopReady(t0 + std::chrono::milliseconds(2000), &out));
  EXPECT_EQ(out.keyframe_id, 3u);
  b.Fused(S, 3);
  // A new session's first view goes at once; then a late view of the
  // earlier session (seen before) goes at once too.
  b.Insert(MakeView(S + 1, 0, 200, t0));
  ASSERT_TRUE(b.PopReady(t0, &out));
  b.StartSession(S + 1);
  b.Fused(S + 1, 0);
  EXPECT_TRUE(b.IsCurrent(S + 1));
  EXPECT_TRUE(b.Seen(S));
  b.Insert(MakeView(S, 2, 102, t0));
  ASSERT_TRUE(b.PopReady(t0, &out));
  EXPECT_EQ(out.session_ns, S);
  b.Fused(S, 2);  // not the current session: order state unchanged
  b.Insert(MakeView(S + 1, 1, 201, t0));
  EXPECT_TRUE(b.PopReady(t0, &out));
  b.Fused(S + 1, 1);
  // After RestartOrder (cloud cleared) the current session expects id 0.
  b.RestartOrder();
  b.Insert(MakeView(S + 1, 2, 202, t0));
  EXPECT_FALSE(b.PopReady(t0, &out));
  // Oldest stamp first, whatever the arrival order; PopAll takes all.
  b.Insert(MakeView(S + 1, 9, 150, t0));
  const std::vector<FusionView> all = b.PopAll();
  ASSERT_EQ(all.size(), 2u);
  EXPECT_EQ(all[0].stamp_ns, 150u);
  EXPECT_EQ(all[1].stamp_ns, 202u);
  EXPECT_EQ(b.size(), 0u);
}

// A first revision that is not final waits for its final revision, which
// replaces it, or until its session sent nothing for revision_timeout; an
// earlier revision never replaces a later one.
TEST(ReorderBuffer, WaitsForTheFinalRevisionAndTakesIt) {
  ReorderBuffer b(2.0, 30.0, kNoBudget);
  const Clock::time_point t0 = Clock::now();
  const uint64_t S = 5;
  FusionView out;
  FusionView first = MakeView(S, 0, 100, t0);
  first.final_revision = false;
  b.Insert(first);
  EXPECT_FALSE(b.PopReady(t0 + std::chrono::seconds(29), &out));
  FusionView revised = MakeView(S, 0, 100, t0 + std::chrono::seconds(10));
  revised.revision = 1;
  revised.map.view = 42;  // marks it
  EXPECT_TRUE(b.Replace(revised));
  EXPECT_FALSE(b.Replace(first));  // revision 0 after 1: not taken
  EXPECT_EQ(b.size(), 1u);
  ASSERT_TRUE(b.PopReady(t0 + std::chrono::seconds(10), &out));
  EXPECT_EQ(out.revision, 1);
  EXPECT_EQ(out.map.view, 42);
  EXPECT_EQ(out.arrived, t0);  // the first one's arrival is kept
  b.StartSession(S);
  b.Fused(S, 0);
  // Keyframe 1's revision never comes: it goes once the session sent
  // nothing for revision_timeout (its last view came at t0 + 10 s).
  FusionView lone = MakeView(S, 1, 101, t0);
  lone.final_revision = false;
  b.Insert(lone);
  EXPECT_FALSE(b.PopReady(t0 + std::chrono::milliseconds(39999), &out));
  ASSERT_TRUE(b.PopReady(t0 + std::chrono::seconds(40), &out));
  EXPECT_EQ(out.revision, 0);
  b.Fused(S, 1);
  // ... nor once a view of another session waits (the depth node reset).
  FusionView old = MakeView(S, 2, 102, t0);
  old.final_revision = false;
  b.Insert(old);
  EXPECT_FALSE(b.PopReady(t0, &out));
  b.Insert(MakeView(S + 1, 0, 200, t0));
  ASSERT_TRUE(b.PopReady(t0, &out));
  EXPECT_EQ(out.stamp_ns, 102u);
}

// A slow stream: a keyframe's final revision comes some keyframes later,
// long after revision_timeout, and the view waits for it as long as its
// depth node keeps sending (the views behind it wait in stamp order).
TEST(ReorderBuffer, WaitsForTheFinalRevisionWhileTheSessionSends) {
  ReorderBuffer b(2.0, 30.0, kNoBudget);
  const Clock::time_point t0 = Clock::now();
  const uint64_t S = 9;
  auto at = [&](int s) { return t0 + std::chrono::seconds(s); };
  FusionView out;
  FusionView first = MakeView(S, 0, 100, at(0));
  first.final_revision = false;
  b.Insert(first);
  for (uint32_t k = 1; k <= 15; ++k) {  // a keyframe every 4 s
    FusionView next = MakeView(S, k, 100 + k, at(4 * k));
    next.final_revision = false;
    b.Insert(next);
    EXPECT_FALSE(b.PopReady(at(4 * k), &out)) << "keyframe " << k;
  }
  EXPECT_EQ(b.size(), 16u);
  FusionView final0 = MakeView(S, 0, 100, at(61));
  final0.revision = 2;
  final0.final_revision = true;
  ASSERT_TRUE(b.Replace(final0));
  ASSERT_TRUE(b.PopReady(at(61), &out));
  EXPECT_EQ(out.stamp_ns, 100u);
  EXPECT_EQ(out.revision, 2);
  b.StartSession(S);
  b.Fused(S, 0);
  // Keyframe 1 still waits; once the stream is silent for revision_timeout
  // the rest go as they are.
  EXPECT_FALSE(b.PopReady(at(61 + 29), &out));
  ASSERT_TRUE(b.PopReady(at(61 + 30), &out));
  EXPECT_EQ(out.stamp_ns, 101u);
  EXPECT_EQ(out.revision, 0);
}

// The waiting views are bounded in memory: beyond the budget the oldest
// goes as it is, whatever it waits for.
TEST(ReorderBuffer, WaitingViewsStayWithinTheirBudget) {
  auto sized = [](uint64_t stamp, uint32_t id, Clock::time_point t) {
    FusionView v = MakeView(3, id, stamp, t);
    v.map.depth = cv::Mat(10, 10, CV_32F, cv::Scalar(1));  // 2,000 bytes
    v.final_revision = false;
    return v;
  };
  ReorderBuffer b(2.0, 30.0, 5000);
  const Clock::time_point t0 = Clock::now();
  FusionView out;
  b.Insert(sized(100, 0, t0));
  b.Insert(sized(101, 1, t0));
  EXPECT_EQ(b.bytes(), 4000u);
  EXPECT_FALSE(b.PopReady(t0, &out));  // within the budget: they wait
  b.Insert(sized(102, 2, t0));
  ASSERT_TRUE(b.PopReady(t0, &out));
  EXPECT_EQ(out.stamp_ns, 100u);
  EXPECT_EQ(b.bytes(), 4000u);
  EXPECT_FALSE(b.PopReady(t0, &out));
  EXPECT_EQ(b.PopAll().size(), 2u);
  EXPECT_EQ(b.bytes(), 0u);
}

struct Recorder {
  std::vector<std::string> drops, logs;
  FusionSession::DropCallback Drop() {
    return [this](const std::string& p, const std::string& d) {
      drops.push_back(p + (d.empty() ? "" : ": " + d));
    };
  }
  FusionSession::LogCallback Log() {
    return [this](bool error, const std::string& m) {
      logs.push_back((error ? "error: " : "") + m);
    };
  }
};

FusionSessionOptions SessionOptions() {
  FusionSessionOptions o;
  o.fusion.min_support = 2;
  o.reorder_timeout = 100;  // no timeouts unless a test wants them
  return o;
}

TEST(FusionSession, FusesInOrderTakesWaitingRevisionsAndReportsTheCloud) {
  Recorder r;
  FusionSession f(SessionOptions(), r.Drop(), r.Log());
  uint64_t version = 0, stamp = 0;
  PointCloud cloud;
  EXPECT_FALSE(f.CloudIfChanged(&version, false, &cloud, &stamp));
  // Keyframes 1 and 2 of two workers arrive before keyframe 0.
  EXPECT_TRUE(f.Add(SceneView(1, 0, 1)));
  EXPECT_TRUE(f.Add(SceneView(2, 0, 2)));
  EXPECT_EQ(f.Stats().fused, 0u);
  EXPECT_EQ(f.Stats().waiting, 2u);
  EXPECT_TRUE(f.Add(SceneView(0, 0, 0)));
  EXPECT_EQ(f.Stats().fused, 3u);
  EXPECT_EQ(f.Stats().waiting, 0u);
  // Keyframe 3 announces a revision: it and every later keyframe wait.
  FusionView first3 = SceneView(3, 0, 3);
  first3.final_revision = false;
  EXPECT_TRUE(f.Add(first3));
  for (int i = 4; i < kViews; ++i) EXPECT_TRUE(f.Add(SceneView(i, 0, i)));
  EXPECT_EQ(f.Stats().fused, 3u);
  EXPECT_EQ(f.Stats().waiting, size_t(kViews - 3));
  // Its final revision replaces it; then all of them are fused.
  FusionView final3 = SceneView(3, 0, 3);
  final3.revision = 1;
  EXPECT_TRUE(f.Add(final3));
  EXPECT_EQ(f.Stats().fused, uint64_t(kViews));
  // A revision of a view fused already is ignored.
  FusionView late = SceneView(4, 0, 4);
  late.revision = 1;
  EXPECT_FALSE(f.Add(late));
  const FusionSessionStats s = f.Stats();
  EXPECT_EQ(s.fused, uint64_t(kViews));
  EXPECT_EQ(s.revisions_replaced, 1u);
  EXPECT_EQ(s.revisions_ignored, 1u);
  EXPECT_EQ(s.sessions, 1u);
  EXPECT_EQ(s.resets, 0u);
  EXPECT_GT(s.fusion.points, 100u);
  ASSERT_TRUE(f.CloudIfChanged(&version, false, &cloud, &stamp));
  EXPECT_GT(cloud.size(), 100u);
  EXPECT_TRUE(cloud.has_rgb());
  EXPECT_EQ(stamp, 1000u + kViews - 1);  // the newest view's stamp
  EXPECT_FALSE(f.CloudIfChanged(&version, false, &cloud, &stamp));
  EXPECT_TRUE(f.CloudIfChanged(&version, true, &cloud, &stamp));  // force
  EXPECT_TRUE(r.drops.empty());
}

TEST(FusionSession, SpilledMapsStillSupportNewViews) {
  // A store bound far below one map: every earlier map is spilled and read
  // back for the checks; the cloud equals the one fused in memory.
  FusionSessionOptions small = SessionOptions();
  small.map_store_mb = 0.01;
  Recorder r1, r2;
  FusionSession spilled(small, r1.Drop());
  FusionSession memory(SessionOptions(), r2.Drop());
  for (int i = 0; i < kViews; ++i) {
    spilled.Add(SceneView(i, 0, i));
    memory.Add(SceneView(i, 0, i));
  }
  EXPECT_EQ(spilled.Stats().spilled, uint64_t(kViews - 1));
  EXPECT_EQ(memory.Stats().spilled, 0u);
  // Spilled views lose their images: colours may differ, geometry not.
  const PointCloud a = spilled.FlushAndCloud(), b = memory.FlushAndCloud();
  ASSERT_EQ(a.size(), b.size());
  for (size_t k = 0; k < a.size(); k += 97)
    EXPECT_LT((a.xyz[k] - b.xyz[k]).norm(), 1e-6f);
  EXPECT_TRUE(r1.drops.empty());
}

TEST(FusionSession, NewSessionKeepFusesIntoTheSameCloud) {
  Recorder r;
  FusionSession f(SessionOptions(), r.Drop(), r.Log());
  for (int i = 0; i < 4; ++i) f.Add(SceneView(i, 0, i));
  const size_t before = f.Stats().fusion.points;
  for (int i = 4; i < kViews; ++i) f.Add(SceneView(i, 5, i - 4));
  const FusionSessionStats s = f.Stats();
  EXPECT_EQ(s.sessions, 2u);
  EXPECT_EQ(s.resets, 0u);
  EXPECT_EQ(s.fused, uint64_t(kViews));
  EXPECT_GE(s.fusion.points, before);
  // A late view of the first session is fused too.
  EXPECT_TRUE(f.Add(SceneView(5, 0, 7)));
  EXPECT_EQ(f.Stats().fused, uint64_t(kViews + 1));
  EXPECT_TRUE(r.drops.empty());
  EXPECT_TRUE(r.logs.empty());
}

TEST(FusionSession, NewSessionResetSavesAndStartsANewCloud) {
  const std::string dir = testing::MakeTempDir("wild_mvs_session");
  FusionSessionOptions o = SessionOptions();
  o.on_new_session = "reset";
  o.output_path = dir + "/cloud.ply";
  Recorder r;
  FusionSession f(o, r.Drop(), r.Log());
  for (int i = 0; i < kViews; ++i) f.Add(SceneView(i, 0, i));
  const size_t first = f.Stats().fusion.points;
  ASSERT_GT(first, 100u);
  EXPECT_FALSE(fs::exists(dir + "/cloud_session0.ply"));
  // Session 2 starts: the first cloud is saved, the new one starts empty.
  EXPECT_TRUE(f.Add(SceneView(0, 2, 0)));
  EXPECT_TRUE(fs::exists(dir + "/cloud_session0.ply"));
  ASSERT_EQ(r.logs.size(), 1u);
  EXPECT_EQ(r.logs[0], "new depth session: saved the previous cloud to " + dir +
                           "/cloud_session0.ply");
  FusionSessionStats s = f.Stats();
  EXPECT_EQ(s.sessions, 2u);
  EXPECT_EQ(s.resets, 1u);
  EXPECT_EQ(s.session_saves, 1u);
  EXPECT_LT(s.fusion.points, first);  // one view: little support
  // A late view of session 0 is dropped (its world frame is gone).
  EXPECT_TRUE(f.Add(SceneView(5, 0, 9)));
  ASSERT_EQ(r.drops.size(), 1u);
  EXPECT_EQ(r.drops[0], "view of an earlier depth session after a cloud reset");
  EXPECT_EQ(f.Stats().fused, uint64_t(kViews + 1));
  // Session 3: the cloud of session 2 goes to _session1.
  f.Add(SceneView(1, 2, 1));
  f.Add(SceneView(0, 3, 0));
  EXPECT_TRUE(fs::exists(dir + "/cloud_session1.ply"));
  EXPECT_EQ(f.Stats().session_saves, 2u);
  fs::remove_all(dir);
}

TEST(FusionSession, ResetClearsAndTimeoutFusesAfterAGap) {
  FusionSessionOptions o = SessionOptions();
  o.reorder_timeout = 0.05;
  Recorder r;
  FusionSession f(o, r.Drop(), r.Log());
  for (int i = 0; i < 4; ++i) f.Add(SceneView(i, 0, i));
  f.Add(SceneView(5, 0, 5));  // keyframe 4 missing: 5 waits
  EXPECT_EQ(f.Stats().waiting, 1u);
  f.Reset();
  FusionSessionStats s = f.Stats();
  EXPECT_EQ(s.waiting, 0u);
  EXPECT_EQ(s.fusion.points, 0u);
  EXPECT_EQ(s.resets, 1u);
  EXPECT_EQ(f.FlushAndCloud().size(), 0u);
  // After the reset the session's next view waits for keyframe 0 until the
  // timeout, then FuseReady fuses it.
  EXPECT_TRUE(f.Add(SceneView(6, 0, 6)));
  EXPECT_EQ(f.Stats().waiting, 1u);
  std::this_thread::sleep_for(std::chrono::milliseconds(80));
  f.FuseReady();
  EXPECT_EQ(f.Stats().waiting, 0u);
  EXPECT_EQ(f.Stats().fused, 5u);
  // The views before the reset are forgotten: their stamps are new again.
  EXPECT_TRUE(f.Add(SceneView(0, 0, 0)));
}

TEST(FusionSession, FlushFusesWaitingViewsAndOptionsAreChecked) {
  Recorder r;
  FusionSession f(SessionOptions(), r.Drop(), r.Log());
  f.Add(SceneView(0, 0, 0));
  f.Add(SceneView(2, 0, 2));
  f.Add(SceneView(3, 0, 3));
  EXPECT_EQ(f.Stats().waiting, 2u);
  const PointCloud cloud = f.FlushAndCloud();
  EXPECT_EQ(f.Stats().waiting, 0u);
  EXPECT_EQ(f.Stats().fused, 3u);
  EXPECT_EQ(cloud.size(), f.Stats().fusion.points);
  auto bad = [&](auto change) {
    FusionSessionOptions o = SessionOptions();
    change(o);
    EXPECT_THROW(FusionSession(o, r.Drop()), Error);
  };
  bad([](FusionSessionOptions& o) { o.on_new_session = "forget"; });
  bad([](FusionSessionOptions& o) { o.reorder_timeout = -1; });
  bad([](FusionSessionOptions& o) { o.revision_timeout = -1; });
  bad([](FusionSessionOptions& o) { o.map_store_mb = 0; });
  bad([](FusionSessionOptions& o) { o.fusion.min_support = 0; });
}

}  // namespace
}  // namespace wild_mvs
