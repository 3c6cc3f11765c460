// Copyright wild_mvs authors.
#include "wild_mvs/stream/pose_track.h"

#include <chrono>
#include <cmath>

#include "wild_mvs/core/error.h"

namespace wild_mvs {
namespace {

uint64_t Nanoseconds(double seconds) {
  return static_cast<uint64_t>(std::llround(seconds * 1e9));
}

}  // namespace

Eigen::Isometry3d InterpolatePose(const Eigen::Isometry3d& a,
                                  const Eigen::Isometry3d& b, double s) {
  const Eigen::Quaterniond qa(a.linear()), qb(b.linear());
  // Eigen's slerp takes the shorter arc (q and -q are the same rotation).
  Eigen::Isometry3d out = Eigen::Isometry3d::Identity();
  out.linear() = qa.slerp(s, qb).normalized().toRotationMatrix();
  out.translation() = (1.0 - s) * a.translation() + s * b.translation();
  return out;
}

PoseTrack::PoseTrack(size_t capacity) : capacity_(capacity) {
  Require(capacity >= 2, "PoseTrack: capacity ", capacity, " must be >= 2");
}

void PoseTrack::Add(uint64_t stamp_ns, const Eigen::Isometry3d& pose) {
  Require(pose.matrix().allFinite(), "pose at stamp ", stamp_ns * 1e-9,
          " s is not finite");
  const Eigen::Matrix3d R = pose.linear();
  Require((R * R.transpose() - Eigen::Matrix3d::Identity()).norm() < 1e-6 &&
              R.determinant() > 0,
          "pose at stamp ", stamp_ns * 1e-9,
          " s: its rotation is not a rotation (orientation quaternion not "
          "normalised?)");
  {
    std::lock_guard<std::mutex> lock(mutex_);
    samples_[stamp_ns] = pose;
    while (samples_.size() > capacity_) samples_.erase(samples_.begin());
  }
  cv_.notify_all();
}

std::string PoseTrack::Describe(Result r) {
  switch (r) {
    case Result::kExact:
      return "pose at the image stamp";
    case Result::kInterpolated:
      return "pose interpolated at the image stamp";
    case Result::kNone:
      return "no pose received yet";
    case Result::kBeforeFirst:
      return "the image is older than every pose held (raise the pose "
             "buffer or lower the image latency)";
    case Result::kAfterLast:
      return "no pose at or after the image stamp arrived within "
             "tf_timeout (poses are interpolated, never extrapolated)";
    case Result::kGapTooLarge:
      return "the poses before and after the image stamp are too far apart "
             "(not interpolated across the gap)";
  }
  return "?";
}

PoseTrack::Result PoseTrack::AtLocked(uint64_t t, double tolerance,
                                      double max_gap,
                                      Eigen::Isometry3d* pose) const {
  if (samples_.empty()) return Result::kNone;
  const uint64_t tol = Nanoseconds(tolerance), gap = Nanoseconds(max_gap);
  // after: first sample >= t; before: the last one < t.
  auto after = samples_.lower_bound(t);
  auto before = after == samples_.begin() ? samples_.end() : std::prev(after);
  const bool have_after = after != samples_.end();
  const bool have_before = before != samples_.end();
  // A sample at the stamp itself.
  if (have_after && after->first == t) {
    *pose = after->second;
    return Result::kExact;
  }
  // Between two samples at most max_gap apart: interpolated.
  if (have_before && have_after && after->first - before->first <= gap) {
    const double s =
        double(t - before->first) / double(after->first - before->first);
    *pose = InterpolatePose(before->second, after->second, s);
    return Result::kInterpolated;
  }
  // Else the nearer sample within the tolerance, as is.
  const uint64_t d_after = have_after ? after->first - t : UINT64_MAX;
  const uint64_t d_before = have_before ? t - before->first : UINT64_MAX;
  if (std::min(d_after, d_before) <= tol) {
    *pose = d_after <= d_before ? after->second : before->second;
    return Result::kExact;
  }
  if (!have_before) return Result::kBeforeFirst;
  if (!have_after) return Result::kAfterLast;
  return Result::kGapTooLarge;
}

PoseTrack::Result PoseTrack::At(uint64_t stamp_ns, double tolerance,
                                double max_gap, Eigen::Isometry3d* pose) const {
  std::lock_guard<std::mutex> lock(mutex_);
  return AtLocked(stamp_ns, tolerance, max_gap, pose);
}

PoseTrack::Result PoseTrack::WaitAt(uint64_t stamp_ns, double tolerance,
                                    double max_gap, double timeout,
                                    Eigen::Isometry3d* pose) {
  std::unique_lock<std::mutex> lock(mutex_);
  cv_.wait_until(
      lock,
      std::chrono::steady_clock::now() +
          std::chrono::duration_cast<std::chrono::steady_clock::duration>(
              std::chrono::duration<double>(timeout)),
      [&] {
        return stop_ ||
               (!samples_.empty() && samples_.rbegin()->first >= stamp_ns);
      });
  return AtLocked(stamp_ns, tolerance, max_gap, pose);
}

void PoseTrack::Stop() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stop_ = true;
  }
  cv_.notify_all();
}

void PoseTrack::Clear() {
  std::lock_guard<std::mutex> lock(mutex_);
  samples_.clear();
}

size_t PoseTrack::size() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return samples_.size();
}

}  // namespace wild_mvs
