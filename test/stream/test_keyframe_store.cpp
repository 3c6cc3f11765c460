// Copyright wild_mvs authors. Keyframe selection and the bounded store.
#include <gtest/gtest.h>

#include <cmath>

#include "wild_mvs/core/error.h"
#include "wild_mvs/stream/keyframe_store.h"

namespace wild_mvs {
namespace {

// Camera at centre (x, 0, 0) looking along +z, rotated by yaw_deg about y.
Camera MakeCamera(double x, double yaw_deg = 0) {
  Camera c;
  c.fx = c.fy = 100;
  c.cx = 32;
  c.cy = 24;
  c.width = 64;
  c.height = 48;
  const double a = yaw_deg * M_PI / 180;
  c.R = Eigen::AngleAxisd(a, Eigen::Vector3d::UnitY()).toRotationMatrix();
  c.t = -c.R * Eigen::Vector3d(x, 0, 0);
  return c;
}

KeyframePtr MakeKeyframe(uint32_t id, double x, bool owned = false,
                         int reconstructions = 0) {
  auto k = std::make_shared<Keyframe>();
  k->id = id;
  k->camera = MakeCamera(x);
  k->image = cv::Mat(48, 64, CV_32FC3, cv::Scalar::all(0.5));
  k->owned = owned;
  k->reconstructions = reconstructions;
  return k;
}

TEST(KeyframeStore, SelectionByBaselineAndAngle) {
  KeyframeStore store(KeyframeStoreOptions{});
  KeyframeSelectionOptions sel;
  sel.min_baseline = 0.1;
  sel.min_angle_deg = 5;
  EXPECT_TRUE(store.IsNewKeyframe(MakeCamera(0), sel));  // first frame
  store.Add(MakeKeyframe(0, 0));
  EXPECT_FALSE(store.IsNewKeyframe(MakeCamera(0.05), sel));
  EXPECT_TRUE(store.IsNewKeyframe(MakeCamera(0.15), sel));
  EXPECT_FALSE(store.IsNewKeyframe(MakeCamera(0, 3), sel));
  EXPECT_TRUE(store.IsNewKeyframe(MakeCamera(0, 6), sel));
}

TEST(KeyframeStore, CountBoundEvictsDoneAndFarthestFirst) {
  KeyframeStoreOptions opt;
  opt.max_keyframes = 4;
  KeyframeStore store(opt);
  // 0: owned and waiting, 1..: done (reconstructed or owned elsewhere).
  store.Add(MakeKeyframe(0, 0.0, /*owned=*/true, 0));
  store.Add(MakeKeyframe(1, 0.1));
  store.Add(MakeKeyframe(2, 0.2));
  store.Add(MakeKeyframe(3, 0.3));
  auto evicted = store.Add(MakeKeyframe(4, 0.4));
  ASSERT_EQ(evicted.size(), 1u);
  // Keyframe 0 is farthest but still waits for its depth map: keyframe 1
  // (the farthest done one) goes.
  EXPECT_EQ(evicted[0]->id, 1u);
  EXPECT_EQ(store.size(), 4u);
  EXPECT_NE(store.Get(0), nullptr);
  EXPECT_EQ(store.Get(1), nullptr);
  // Once 0 is reconstructed it is the farthest done keyframe.
  store.Get(0)->reconstructions = 1;
  evicted = store.Add(MakeKeyframe(5, 0.5));
  ASSERT_EQ(evicted.size(), 1u);
  EXPECT_EQ(evicted[0]->id, 0u);
}

TEST(KeyframeStore, ByteBoundHolds) {
  KeyframeStoreOptions opt;
  opt.max_keyframes = 1000;
  const double one_mb = 64 * 48 * 3 * 4 / (1024.0 * 1024.0);
  opt.max_mb = 3.5 * one_mb;  // room for 3 keyframes
  KeyframeStore store(opt);
  for (uint32_t i = 0; i < 20; ++i) {
    store.Add(MakeKeyframe(i, 0.1 * i));
    EXPECT_LE(store.size(), 3u);
    EXPECT_LE(store.bytes(), opt.max_mb * 1024 * 1024);
  }
  EXPECT_NE(store.Get(19), nullptr);  // the newest is always kept
  EXPECT_NE(store.Get(18), nullptr);  // the nearest are kept
}

TEST(KeyframeStore, NeverEvictsTheNewestAndRejectsOldIds) {
  KeyframeStoreOptions opt;
  opt.max_keyframes = 2;
  opt.max_mb = 1e-6;  // smaller than one image
  KeyframeStore store(opt);
  store.Add(MakeKeyframe(0, 0));
  store.Add(MakeKeyframe(1, 1));
  EXPECT_EQ(store.size(), 1u);
  EXPECT_EQ(store.Newest()->id, 1u);
  EXPECT_THROW(store.Add(MakeKeyframe(1, 2)), Error);
}

TEST(KeyframeStore, OptionsAreChecked) {
  KeyframeStoreOptions opt;
  opt.max_keyframes = 1;
  EXPECT_THROW(opt.Check(), Error);
  KeyframeSelectionOptions sel;
  sel.min_angle_deg = NAN;
  EXPECT_THROW(sel.Check(), Error);
}

}  // namespace
}  // namespace wild_mvs
