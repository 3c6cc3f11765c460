// Copyright wild_mvs authors. The pose at an image stamp from a stream of
// localisation poses: exact samples, slerp + lerp between samples against
// a closed-form motion, refusal beyond the gap and outside the samples,
// waiting for a late pose, bad poses.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <thread>

#include "wild_mvs/core/error.h"
#include "wild_mvs/stream/pose_track.h"

namespace wild_mvs {
namespace {

using R = PoseTrack::Result;
constexpr uint64_t kSecond = 1000000000ull;
// A real-world epoch stamp (2026), so that ns arithmetic is exercised.
constexpr uint64_t kT0 = 1795000000ull * kSecond;

// Body moving at constant velocity and turning at a constant rate about a
// fixed axis: slerp + lerp reproduce it exactly at any t between samples.
Eigen::Isometry3d Motion(double t) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  const Eigen::Vector3d axis = Eigen::Vector3d(0.2, 1.0, -0.3).normalized();
  T.linear() = (Eigen::AngleAxisd(0.1, Eigen::Vector3d::UnitX()) *
                Eigen::AngleAxisd(0.8 * t, axis))
                   .toRotationMatrix();
  T.translation() =
      Eigen::Vector3d(1.0, -2.0, 0.5) + t * Eigen::Vector3d(0.7, 0.1, -0.2);
  return T;
}

double PoseError(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b) {
  return (a.matrix() - b.matrix()).norm();
}

uint64_t At(double t) {
  return kT0 + static_cast<uint64_t>(std::llround(t * 1e9));
}

TEST(PoseTrack, InterpolatesBetweenSamplesExactlyForConstantMotion) {
  PoseTrack track(100);
  // 50 Hz odometry, not at the camera's stamps.
  for (int i = 0; i <= 50; ++i) track.Add(At(0.02 * i), Motion(0.02 * i));
  Eigen::Isometry3d pose;
  for (double t : {0.0033, 0.0101, 0.4567, 0.9999}) {
    ASSERT_EQ(track.At(At(t), 0.0, 0.05, &pose), R::kInterpolated) << t;
    EXPECT_LT(PoseError(pose, Motion(t)), 1e-9) << t;
  }
  // At a sample's stamp: the sample itself.
  ASSERT_EQ(track.At(At(0.2), 0.001, 0.05, &pose), R::kExact);
  EXPECT_LT(PoseError(pose, Motion(0.2)), 1e-12);
  // Close to a sample but between two: interpolated, not snapped.
  ASSERT_EQ(track.At(At(0.2003), 0.01, 0.05, &pose), R::kInterpolated);
  EXPECT_LT(PoseError(pose, Motion(0.2003)), 1e-9);
  // Past the last sample, within the tolerance: the last sample as is.
  ASSERT_EQ(track.At(At(1.0005), 0.001, 0.05, &pose), R::kExact);
  EXPECT_LT(PoseError(pose, Motion(1.0)), 1e-12);
  EXPECT_EQ(track.At(At(1.0005), 0.0001, 0.05, &pose), R::kAfterLast);
  // Nearest-only would be off by the motion of 9 ms; interpolation is not.
  ASSERT_EQ(track.At(At(0.209), 0.0, 0.05, &pose), R::kInterpolated);
  EXPECT_GT(PoseError(Motion(0.2), Motion(0.209)), 1e-3);
  EXPECT_LT(PoseError(pose, Motion(0.209)), 1e-9);
}

TEST(PoseTrack, RefusesAcrossGapsAndOutsideTheSamples) {
  PoseTrack track(100);
  Eigen::Isometry3d pose;
  EXPECT_EQ(track.At(At(0.5), 0.01, 0.1, &pose), R::kNone);
  track.Add(At(0.0), Motion(0.0));
  track.Add(At(0.05), Motion(0.05));
  track.Add(At(0.5), Motion(0.5));  // 450 ms without a pose
  EXPECT_EQ(track.At(At(0.1), 0.01, 0.1, &pose), R::kGapTooLarge);
  EXPECT_EQ(track.At(At(0.1), 0.01, 0.5, &pose), R::kInterpolated);
  EXPECT_EQ(track.At(At(0.6), 0.01, 0.1, &pose), R::kAfterLast);
  EXPECT_EQ(track.At(At(-0.1), 0.01, 0.1, &pose), R::kBeforeFirst);
  EXPECT_FALSE(PoseTrack::Ok(R::kGapTooLarge));
  EXPECT_NE(PoseTrack::Describe(R::kGapTooLarge).find("gap"),
            std::string::npos);
}

TEST(PoseTrack, TakesSamplesOutOfOrderAndKeepsTheNewest) {
  PoseTrack track(3);
  track.Add(At(0.3), Motion(0.3));
  track.Add(At(0.1), Motion(0.1));
  track.Add(At(0.2), Motion(0.2));
  track.Add(At(0.4), Motion(0.4));  // the oldest (0.1) goes
  EXPECT_EQ(track.size(), 3u);
  Eigen::Isometry3d pose;
  EXPECT_EQ(track.At(At(0.15), 0.0, 1.0, &pose), R::kBeforeFirst);
  ASSERT_EQ(track.At(At(0.25), 0.0, 1.0, &pose), R::kInterpolated);
  EXPECT_LT(PoseError(pose, Motion(0.25)), 1e-9);
}

TEST(PoseTrack, SlerpTakesTheShorterArc) {
  Eigen::Isometry3d a = Eigen::Isometry3d::Identity(), b = a;
  b.linear() =
      Eigen::AngleAxisd(0.4, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  // The same rotations given with quaternions of opposite sign.
  const Eigen::Quaterniond qb(b.linear());
  Eigen::Isometry3d b_neg = Eigen::Isometry3d::Identity();
  b_neg.linear() =
      Eigen::Quaterniond(-qb.w(), -qb.x(), -qb.y(), -qb.z()).toRotationMatrix();
  const Eigen::Isometry3d mid = InterpolatePose(a, b_neg, 0.5);
  EXPECT_NEAR(Eigen::AngleAxisd(mid.linear()).angle(), 0.2, 1e-12);
}

TEST(PoseTrack, WaitsForALatePoseAndStops) {
  PoseTrack track(100);
  track.Add(At(0.0), Motion(0.0));
  std::thread late([&] {
    std::this_thread::sleep_for(std::chrono::milliseconds(30));
    track.Add(At(0.02), Motion(0.02));
  });
  Eigen::Isometry3d pose;
  // The pose after the image stamp arrives while we wait (timeout 10 s:
  // the wait ends on the arrival, not on the timeout).
  const auto t0 = std::chrono::steady_clock::now();
  ASSERT_EQ(track.WaitAt(At(0.01), 0.0, 0.05, 10.0, &pose), R::kInterpolated);
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0)
                .count(),
            9.0);
  late.join();
  EXPECT_LT(PoseError(pose, Motion(0.01)), 1e-9);
  // Nothing newer comes: the wait times out with kAfterLast.
  EXPECT_EQ(track.WaitAt(At(0.5), 0.0, 0.05, 0.01, &pose), R::kAfterLast);
  // Stop ends a long wait at once.
  std::thread stopper([&] {
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
    track.Stop();
  });
  EXPECT_EQ(track.WaitAt(At(5.0), 0.0, 0.05, 60.0, &pose), R::kAfterLast);
  stopper.join();
}

TEST(PoseTrack, RejectsPosesThatAreNotRigid) {
  PoseTrack track(10);
  Eigen::Isometry3d bad = Eigen::Isometry3d::Identity();
  bad.linear() *= 1.5;  // an unnormalised quaternion's matrix
  EXPECT_THROW(track.Add(At(0.0), bad), Error);
  bad = Eigen::Isometry3d::Identity();
  bad.translation().x() = std::nan("");
  EXPECT_THROW(track.Add(At(0.0), bad), Error);
  EXPECT_EQ(track.size(), 0u);
}

}  // namespace
}  // namespace wild_mvs
