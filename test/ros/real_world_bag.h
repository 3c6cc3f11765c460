// Copyright wild_mvs authors. Test support (header only): a bag recorded the
// way real robots and public datasets (TUM RGB-D, EuRoC) record, from the
// synthetic scene with exact ground truth the other ROS tests use.
//
// What differs from `wild_mvs to-bag` (scene_bag.h):
//   - epoch stamps with sub-second parts (default 1305031102.175304, the
//     first frame of TUM fr1/xyz); every stamp is exact integer nanoseconds
//     (ros::Time(sec, nsec), never from a double);
//   - leading-slash frame ids ("/world", "/base_link",
//     "/camera_rgb_optical_frame"), as ROS-1-era datasets have them;
//   - a body frame: /tf at tf_rate_hz (100 Hz) world -> base_link, and one
//     latched /tf_static base_link -> camera optical frame with a non-trivial
//     extrinsic (the body -> optical rotation, x forward / z up to z forward /
//     y down, plus a few cm of translation);
//   - a camera_rate_hz (30 Hz) camera that lingers on each view for
//     frames_per_view frames (same image, same pose, distinct stamps), then
//     the body jumps to the next view; the /tf samples take the pose of the
//     nearest frame in time, so tf interpolation at any image stamp gives
//     exactly that view's pose (there are >= 2 samples in each 33 ms gap);
//   - topics /camera/rgb/image_color (rgb8 / bgr8 / mono8) and
//     /camera/rgb/camera_info (plumb_bob, D = 5 zeros, R = I, P = [K 0]), or
//     only /camera/rgb/image_color/compressed (image_transport's compressed
//     plugin: format "rgb8; jpeg compressed bgr8").
#pragma once

#include <geometry_msgs/TransformStamped.h>
#include <ros/ros.h>
#include <rosbag/bag.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/CompressedImage.h>
#include <sensor_msgs/Image.h>
#include <sensor_msgs/image_encodings.h>
#include <tf2_msgs/TFMessage.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cstdint>
#include <cstring>
#include <map>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <stdexcept>
#include <string>
#include <vector>

#include "synthetic_scene.h"
#include "wild_mvs/core/camera.h"
#include "wild_mvs/ros/conversions.h"
#include "wild_mvs/ros/scene_bag.h"

namespace wild_mvs {
namespace testing {

struct RealWorldBagOptions {
  // Stamp of the first image (and origin of every other stamp).
  uint32_t start_sec = 1305031102;
  uint32_t start_nsec = 175304000;
  int camera_rate_hz = 30;
  int frames_per_view = 8;  // frames of the same view (distinct stamps)
  int tf_rate_hz = 100;
  // /tf starts this long before the first image and ends this long after
  // the last one (nanoseconds), so tf can interpolate at every image stamp.
  int64_t tf_margin_ns = 100000000;
  bool leading_slash = true;  // "/world" instead of "world" everywhere
  std::string world_frame = "world";
  std::string body_frame = "base_link";
  std::string camera_frame = "camera_rgb_optical_frame";
  std::string image_topic = "/camera/rgb/image_color";
  std::string info_topic = "/camera/rgb/camera_info";
  std::string encoding = "rgb8";  // rgb8, bgr8 or mono8 (raw images)
  // "" = raw images on image_topic; "jpeg" or "png" = ONLY
  // image_topic + "/compressed" (sensor_msgs/CompressedImage).
  std::string compression;
  int jpeg_quality = 95;
  // body -> optical frame translation (metres, in the body frame).
  Eigen::Vector3d extrinsic_translation{0.08, -0.025, 0.04};

  std::string Frame(const std::string& name) const {
    return leading_slash ? "/" + name : name;
  }
};

// ros::Time of exact integer nanoseconds.
inline ros::Time TimeFromNSec(uint64_t ns) {
  return ros::Time(static_cast<uint32_t>(ns / 1000000000ULL),
                   static_cast<uint32_t>(ns % 1000000000ULL));
}

// What the checker needs to know about the bag written.
struct RealWorldBag {
  std::string path;
  std::vector<ros::Time> image_stamps;         // every image written, in order
  std::vector<int> view_of_image;              // view index of each image
  std::vector<ros::Time> first_stamp_of_view;  // first frame of each view
  std::vector<Camera> view_cameras;            // ground truth per view
  Eigen::Isometry3d body_T_camera = Eigen::Isometry3d::Identity();
  ros::Time first_stamp, last_stamp;  // of the images
  ros::Time bag_begin, bag_end;       // of every message (tf included)

  // View of an image stamp (exact nanoseconds), or -1 when no image of the
  // bag has exactly this stamp.
  int ViewOfStamp(const ros::Time& t) const {
    auto it = view_by_nsec_.find(t.toNSec());
    return it == view_by_nsec_.end() ? -1 : it->second;
  }
  bool IsImageStamp(const ros::Time& t) const { return ViewOfStamp(t) >= 0; }
  // The image stamp nearest to t when within tolerance_ns, else zero: lets a
  // checker still score a depth map whose stamp was rounded (through a
  // double), while it reports the inexact stamp separately.
  ros::Time NearestImageStamp(const ros::Time& t,
                              uint64_t tolerance_ns = 1000000) const {
    const uint64_t ns = t.toNSec();
    uint64_t best = 0, best_d = UINT64_MAX;
    auto it = view_by_nsec_.lower_bound(ns);
    if (it != view_by_nsec_.end()) best = it->first, best_d = it->first - ns;
    if (it != view_by_nsec_.begin()) {
      --it;
      if (ns - it->first < best_d) best = it->first, best_d = ns - it->first;
    }
    return best_d <= tolerance_ns ? TimeFromNSec(best) : ros::Time();
  }
  // Index of the frame within its view (0 = first), or -1.
  int FrameInView(const ros::Time& t) const {
    auto it = frame_by_nsec_.find(t.toNSec());
    return it == frame_by_nsec_.end() ? -1 : it->second;
  }
  int NumViews() const { return static_cast<int>(view_cameras.size()); }

  std::map<uint64_t, int> view_by_nsec_, frame_by_nsec_;
};

using ros1::BodyToOpticalRotation;

inline geometry_msgs::Transform TransformMsg(const Eigen::Isometry3d& T) {
  return ros1::TransformMsg(T.rotation(), T.translation());
}

// world_T_camera of a core camera (R, t are world-to-camera).
inline Eigen::Isometry3d WorldFromCamera(const Camera& c) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = c.R.transpose();
  T.translation() = c.Center();
  return T;
}

// The image of view i as the bag stores it: 8-bit sRGB in `encoding`
// (CV_8UC3 in rgb or bgr channel order, or CV_8UC1 for mono8).
inline cv::Mat RealBagImage(const SyntheticScene& scene, int i,
                            const std::string& encoding) {
  cv::Mat rgb = ros1::LinearToSrgb8(scene.images[i]);
  if (encoding == "rgb8") return rgb;
  cv::Mat out;
  if (encoding == "bgr8")
    cv::cvtColor(rgb, out, cv::COLOR_RGB2BGR);
  else if (encoding == "mono8")
    cv::cvtColor(rgb, out, cv::COLOR_RGB2GRAY);
  else
    throw std::invalid_argument("RealBagImage: encoding '" + encoding +
                                "' is not rgb8, bgr8 or mono8");
  return out;
}

// Writes the bag of `scene` (every view, in order) to `path`.
inline RealWorldBag WriteRealWorldBag(const SyntheticScene& scene,
                                      const std::string& path,
                                      const RealWorldBagOptions& o) {
  if (o.camera_rate_hz <= 0 || o.tf_rate_hz <= 0 || o.frames_per_view <= 0)
    throw std::invalid_argument("WriteRealWorldBag: rates and frames > 0");
  if (o.compression.empty() && o.encoding != "rgb8" && o.encoding != "bgr8" &&
      o.encoding != "mono8")
    throw std::invalid_argument("WriteRealWorldBag: bad encoding " +
                                o.encoding);
  if (!o.compression.empty() && o.compression != "jpeg" &&
      o.compression != "png")
    throw std::invalid_argument("WriteRealWorldBag: bad compression " +
                                o.compression);
  if (!ros::Time::isValid()) ros::Time::init();
  const int num_views = static_cast<int>(scene.scene.views.size());
  if (num_views == 0) throw std::invalid_argument("WriteRealWorldBag: empty");

  RealWorldBag out;
  out.path = path;
  out.body_T_camera.linear() = BodyToOpticalRotation();
  out.body_T_camera.translation() = o.extrinsic_translation;
  const Eigen::Isometry3d camera_T_body = out.body_T_camera.inverse();

  const uint64_t start_ns =
      static_cast<uint64_t>(o.start_sec) * 1000000000ULL + o.start_nsec;
  const int num_frames = num_views * o.frames_per_view;
  auto frame_ns = [&](int k) {  // offset of frame k from start, exact
    return static_cast<uint64_t>(k) * 1000000000ULL /
           static_cast<uint64_t>(o.camera_rate_hz);
  };
  for (int v = 0; v < num_views; ++v)
    out.view_cameras.push_back(scene.scene.views[v].camera);
  for (int k = 0; k < num_frames; ++k) {
    const uint64_t ns = start_ns + frame_ns(k);
    out.image_stamps.push_back(TimeFromNSec(ns));
    out.view_of_image.push_back(k / o.frames_per_view);
    out.view_by_nsec_[ns] = k / o.frames_per_view;
    out.frame_by_nsec_[ns] = k % o.frames_per_view;
    if (k % o.frames_per_view == 0)
      out.first_stamp_of_view.push_back(TimeFromNSec(ns));
  }
  out.first_stamp = out.image_stamps.front();
  out.last_stamp = out.image_stamps.back();

  // Body pose of view v: world_T_body = world_T_camera * camera_T_body.
  auto body_pose = [&](int v) {
    return WorldFromCamera(out.view_cameras[v]) * camera_T_body;
  };
  // The view whose frame is nearest in time to `offset_ns` (may be < 0).
  auto nearest_view = [&](int64_t offset_ns) {
    const double k = static_cast<double>(offset_ns) * o.camera_rate_hz / 1e9;
    const int f =
        std::clamp(static_cast<int>(std::lround(k)), 0, num_frames - 1);
    return f / o.frames_per_view;
  };

  rosbag::Bag bag(path, rosbag::bagmode::Write);
  const uint64_t tf_step = 1000000000ULL / o.tf_rate_hz;
  const uint64_t tf_begin = start_ns - static_cast<uint64_t>(o.tf_margin_ns);
  const uint64_t tf_end = start_ns + frame_ns(num_frames - 1) +
                          static_cast<uint64_t>(o.tf_margin_ns);
  // /tf_static once, at the start (latched), 1 ms before the first /tf so
  // that it plays first.
  const uint64_t static_ns = tf_begin - 1000000ULL;
  out.bag_begin = TimeFromNSec(static_ns);
  {
    geometry_msgs::TransformStamped T;
    T.header.stamp = TimeFromNSec(static_ns);
    T.header.frame_id = o.Frame(o.body_frame);
    T.child_frame_id = o.Frame(o.camera_frame);
    T.transform = TransformMsg(out.body_T_camera);
    tf2_msgs::TFMessage m;
    m.transforms.push_back(T);
    bag.write("/tf_static", TimeFromNSec(static_ns), m,
              ros1::LatchedTfStaticHeader());
  }

  // Merge /tf samples and camera frames in time order (tf first on ties).
  uint64_t tf_ns = tf_begin;
  int k = 0;
  while (tf_ns <= tf_end || k < num_frames) {
    const uint64_t img_ns =
        k < num_frames ? start_ns + frame_ns(k) : UINT64_MAX;
    if (tf_ns <= tf_end && tf_ns <= img_ns) {
      const ros::Time t = TimeFromNSec(tf_ns);
      geometry_msgs::TransformStamped T;
      T.header.stamp = t;
      T.header.frame_id = o.Frame(o.world_frame);
      T.child_frame_id = o.Frame(o.body_frame);
      T.transform = TransformMsg(body_pose(nearest_view(
          static_cast<int64_t>(tf_ns) - static_cast<int64_t>(start_ns))));
      tf2_msgs::TFMessage m;
      m.transforms.push_back(T);
      bag.write("/tf", t, m);
      out.bag_end = t;
      tf_ns += tf_step;
      continue;
    }
    const ros::Time t = TimeFromNSec(img_ns);
    const int v = k / o.frames_per_view;
    const Camera& cam = out.view_cameras[v];
    sensor_msgs::CameraInfo info = ros1::CameraInfoFromCamera(cam);
    info.header.stamp = t;
    info.header.frame_id = o.Frame(o.camera_frame);
    info.distortion_model = "plumb_bob";
    info.D.assign(5, 0.0);
    bag.write(o.info_topic, t, info);

    const std::string enc = o.compression.empty() ? o.encoding : "rgb8";
    const cv::Mat img = RealBagImage(scene, v, enc);
    if (!o.compression.empty()) {
      sensor_msgs::CompressedImage cm;
      cm.header = info.header;
      cv::Mat bgr;
      cv::cvtColor(img, bgr, cv::COLOR_RGB2BGR);
      std::vector<int> params;
      if (o.compression == "jpeg")
        params = {cv::IMWRITE_JPEG_QUALITY, o.jpeg_quality};
      const std::string ext = o.compression == "png" ? ".png" : ".jpg";
      if (!cv::imencode(ext, bgr, cm.data, params))
        throw std::runtime_error("WriteRealWorldBag: cannot encode");
      cm.format = "rgb8; " + o.compression + " compressed bgr8";
      bag.write(o.image_topic + "/compressed", t, cm);
    } else {
      sensor_msgs::Image im = ros1::MatToMsg(img, o.encoding);
      im.header = info.header;
      bag.write(o.image_topic, t, im);
    }
    out.bag_end = std::max(out.bag_end, t);
    ++k;
  }
  bag.close();
  return out;
}

}  // namespace testing
}  // namespace wild_mvs
