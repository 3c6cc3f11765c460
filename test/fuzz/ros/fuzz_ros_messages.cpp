// Copyright wild_mvs authors. libFuzzer harness: the ROS nodes' message
// decoding path (src/ros/conversions.cpp over src/io/pixel_buffer.cpp),
// built only when ROS is found.
//
// The message fields are read from the fuzz input in a simple little-endian
// layout (not the ROS wire format, whose deserializer belongs to roscpp):
//   u8 kind (0 DepthView, 1 Image, 2 CameraInfo + pose)
//   Image:      u32 height, u32 width, str encoding, u8 is_bigendian,
//               u32 step, bytes data
//   CameraInfo: u32 height, u32 width, str distortion_model,
//               u8 n + n f64 D, 9 f64 K
//   Pose:       7 f64 (position x y z, orientation x y z w)
//   DepthView:  u32 keyframe_id, u8 n + n u32 neighbor_ids, Image depth,
//               Image confidence, Image normals, CameraInfo, Pose
// with str = u8 length + chars and bytes = u32 length + bytes (both cut to
// what is left). The converters must return a valid result or throw
// wild_mvs::Error; accepted depth maps are checked and turned into a cloud
// the way the fusion node does.
#include <wild_mvs/DepthView.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <string>

#include "wild_mvs/core/error.h"
#include "wild_mvs/ros/conversions.h"

namespace {

class Input {
 public:
  Input(const uint8_t* data, size_t size) : p_(data), end_(data + size) {}
  template <typename T>
  T Get() {
    T v{};
    const size_t n = std::min(sizeof(T), size_t(end_ - p_));
    std::memcpy(&v, p_, n);
    p_ += n;
    return v;
  }
  std::string Str() {
    const size_t n = std::min<size_t>(Get<uint8_t>(), end_ - p_);
    std::string s(reinterpret_cast<const char*>(p_), n);
    p_ += n;
    return s;
  }
  std::vector<uint8_t> Bytes() {
    const size_t n = std::min<size_t>(Get<uint32_t>(), end_ - p_);
    std::vector<uint8_t> b(p_, p_ + n);
    p_ += n;
    return b;
  }

 private:
  const uint8_t* p_;
  const uint8_t* end_;
};

void ReadImage(Input* in, sensor_msgs::Image* m) {
  m->height = in->Get<uint32_t>();
  m->width = in->Get<uint32_t>();
  m->encoding = in->Str();
  m->is_bigendian = in->Get<uint8_t>();
  m->step = in->Get<uint32_t>();
  m->data = in->Bytes();
}

void ReadCameraInfo(Input* in, sensor_msgs::CameraInfo* m) {
  m->height = in->Get<uint32_t>();
  m->width = in->Get<uint32_t>();
  m->distortion_model = in->Str();
  const int n = in->Get<uint8_t>();
  for (int i = 0; i < n; ++i) m->D.push_back(in->Get<double>());
  for (double& k : m->K) k = in->Get<double>();
}

void ReadPose(Input* in, geometry_msgs::Pose* p) {
  p->position.x = in->Get<double>();
  p->position.y = in->Get<double>();
  p->position.z = in->Get<double>();
  p->orientation.x = in->Get<double>();
  p->orientation.y = in->Get<double>();
  p->orientation.z = in->Get<double>();
  p->orientation.w = in->Get<double>();
}

void CheckCamera(const wild_mvs::Camera& c) {
  if (!(c.fx > 0) || !(c.fy > 0) || c.width <= 0 || c.height <= 0 ||
      !std::isfinite(c.cx) || !std::isfinite(c.cy) || !c.R.allFinite() ||
      !c.t.allFinite())
    __builtin_trap();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace wild_mvs;
  Input in(data, size);
  const int kind = in.Get<uint8_t>() % 3;
  try {
    if (kind == 0) {
      wild_mvs::DepthView msg;
      msg.keyframe_id = in.Get<uint32_t>();
      const int n = in.Get<uint8_t>();
      for (int i = 0; i < n; ++i)
        msg.neighbor_ids.push_back(in.Get<uint32_t>());
      ReadImage(&in, &msg.depth);
      ReadImage(&in, &msg.confidence);
      ReadImage(&in, &msg.normals);
      ReadCameraInfo(&in, &msg.camera_info);
      ReadPose(&in, &msg.camera_pose.pose);
      const DepthMap dm = ros1::DepthMapFromDepthView(msg);
      CheckCamera(dm.camera);
      if (dm.depth.type() != CV_32F || dm.confidence.type() != CV_32F ||
          dm.normal.type() != CV_32FC3 || dm.width() != dm.camera.width ||
          dm.height() != dm.camera.height ||
          dm.confidence.size() != dm.depth.size() ||
          dm.normal.size() != dm.depth.size())
        __builtin_trap();
      for (int r = 0; r < dm.height(); ++r)
        for (int c = 0; c < dm.width(); ++c) {
          const float d = dm.depth.at<float>(r, c);
          const float w = dm.confidence.at<float>(r, c);
          if (!std::isfinite(d) || d < 0 || !(w >= 0 && w <= 1))
            __builtin_trap();
        }
      (void)dm.CountValid();
      (void)ros1::DepthMapToCloud(dm, cv::Mat());
    } else if (kind == 1) {
      sensor_msgs::Image msg;
      ReadImage(&in, &msg);
      const bool linearize = in.Get<uint8_t>() & 1;
      const cv::Mat rgb = ros1::ImageToLinearRgb(msg, linearize);
      if (rgb.type() != CV_32FC3 || rgb.cols != int(msg.width) ||
          rgb.rows != int(msg.height))
        __builtin_trap();
    } else {
      sensor_msgs::CameraInfo info;
      ReadCameraInfo(&in, &info);
      Camera camera;
      Distortion distortion;
      ros1::CameraFromCameraInfo(info, &camera, &distortion);
      geometry_msgs::Pose pose;
      ReadPose(&in, &pose);
      ros1::SetCameraPose(pose, &camera);
      CheckCamera(camera);
      camera.Validate("fuzz camera");
    }
  } catch (const Error&) {
  }
  return 0;
}
