// Copyright wild_mvs authors. Recent stamped poses of one frame (a camera or
// a robot body) in the world frame, and the pose at an image's stamp
// interpolated between them (ROS-free: the depth node feeds it from
// PoseStamped, PoseWithCovarianceStamped, TransformStamped or Odometry).
//
// Poses are frame-to-world (T_world_frame: x_world = T * x_frame), the way
// localisation sources publish them (REP 105); the camera's world-to-camera
// pose is derived from it by the caller. Stamps are integer nanoseconds.
//
// The pose at stamp t is
//   - a sample's own pose when one has the stamp t;
//   - else the linear interpolation of the translations and the spherical
//     (slerp) interpolation of the rotations of the two samples on either
//     side of t, when they are at most `max_gap` apart;
//   - else the nearer sample when it lies within `tolerance` of t (a pose
//     source that stamps its poses a little off the camera's, or the last
//     pose of a stream that stopped);
//   - else refused (no extrapolation: the reason says which).
#pragma once

#include <Eigen/Geometry>
#include <condition_variable>
#include <cstddef>
#include <cstdint>
#include <map>
#include <mutex>
#include <string>

namespace wild_mvs {

// T_a_b between two poses at fraction s in [0, 1] (translation lerp,
// rotation slerp along the shorter arc).
Eigen::Isometry3d InterpolatePose(const Eigen::Isometry3d& a,
                                  const Eigen::Isometry3d& b, double s);

class PoseTrack {
 public:
  // Keeps the `capacity` newest samples (by stamp).
  explicit PoseTrack(size_t capacity = 1000);

  // Adds a sample; one with a stamp already held replaces it. Samples may
  // arrive out of order. Throws Error when the pose is not finite or its
  // rotation is not a rotation.
  void Add(uint64_t stamp_ns, const Eigen::Isometry3d& world_from_frame);

  enum class Result {
    kExact,         // a sample at the stamp (or within the tolerance)
    kInterpolated,  // between two samples at most max_gap apart
    kNone,          // no sample received yet
    kBeforeFirst,   // t is older than every sample held
    kAfterLast,     // t is newer than every sample (and none came in time)
    kGapTooLarge,   // the samples around t are more than max_gap apart
  };
  static bool Ok(Result r) {
    return r == Result::kExact || r == Result::kInterpolated;
  }
  // A sentence for drop messages ("no pose after the image stamp ...").
  static std::string Describe(Result r);

  // The pose at `stamp_ns` from the samples held now. tolerance, max_gap in
  // seconds (>= 0).
  Result At(uint64_t stamp_ns, double tolerance, double max_gap,
            Eigen::Isometry3d* pose) const;
  // The same, first waiting up to `timeout` s of wall time (steady clock)
  // for a sample at or after the stamp to arrive (a pose source usually
  // lags the camera a little). Stop() ends every wait.
  Result WaitAt(uint64_t stamp_ns, double tolerance, double max_gap,
                double timeout, Eigen::Isometry3d* pose);
  void Stop();
  void Clear();
  size_t size() const;

 private:
  Result AtLocked(uint64_t stamp_ns, double tolerance, double max_gap,
                  Eigen::Isometry3d* pose) const;
  size_t capacity_;
  mutable std::mutex mutex_;
  std::condition_variable cv_;
  bool stop_ = false;
  std::map<uint64_t, Eigen::Isometry3d> samples_;
};

}  // namespace wild_mvs
