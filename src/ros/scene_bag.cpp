// Copyright wild_mvs authors.
#include "wild_mvs/ros/scene_bag.h"

#include <geometry_msgs/PoseStamped.h>
#include <geometry_msgs/TransformStamped.h>
#include <rosbag/bag.h>
#include <sensor_msgs/CompressedImage.h>
#include <sensor_msgs/image_encodings.h>
#include <tf2_msgs/TFMessage.h>
#include <wild_mvs/SparsePoints.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "wild_mvs/core/error.h"
#include "wild_mvs/core/image.h"
#include "wild_mvs/io/atomic_file.h"
#include "wild_mvs/ros/conversions.h"

namespace wild_mvs {
namespace ros1 {

void SceneBagOptions::Check() const {
  Require(std::isfinite(rate) && rate > 0 && rate <= 1000, "--rate ", rate,
          " must be in (0, 1000] Hz");
  Require(std::isfinite(start_time) && start_time > 0,
          "start_time = ", start_time, " must be > 0");
  Require(!world_frame.empty() && !camera_frame.empty() &&
              world_frame != camera_frame,
          "world and camera frames must be non-empty and differ");
}

cv::Mat LinearToSrgb8(const cv::Mat& linear_rgb) {
  Require(linear_rgb.type() == CV_32FC3, "LinearToSrgb8: expected CV_32FC3");
  cv::Mat out(linear_rgb.size(), CV_8UC3);
  for (int r = 0; r < out.rows; ++r) {
    const cv::Vec3f* s = linear_rgb.ptr<cv::Vec3f>(r);
    cv::Vec3b* d = out.ptr<cv::Vec3b>(r);
    for (int c = 0; c < out.cols; ++c)
      for (int k = 0; k < 3; ++k)
        d[c][k] = cv::saturate_cast<uint8_t>(
            LinearToSrgb(std::clamp(s[c][k], 0.0f, 1.0f)) * 255.0f + 0.5f);
  }
  return out;
}

void WriteSceneBag(const Scene& scene,
                   const std::function<cv::Mat(int)>& image_rgb8,
                   const std::string& path, const SceneBagOptions& options) {
  options.Check();
  Require(!scene.views.empty(), "to-bag: the scene has no views");
  if (!ros::Time::isValid()) ros::Time::init();
  const int n = static_cast<int>(scene.views.size());
  auto stamp_of = [&](int i) {
    return ros::Time(options.start_time + i / options.rate);
  };
  ProduceFileAtomically(path, [&](const std::string& tmp) {
    rosbag::Bag bag(tmp, rosbag::bagmode::Write);
    for (int i = 0; i < n; ++i) {
      const View& v = scene.views[i];
      const ros::Time t = stamp_of(i);
      // tf first, so the pose is there when the image arrives.
      geometry_msgs::TransformStamped T;
      T.header.stamp = t;
      T.header.frame_id = options.world_frame;
      T.child_frame_id = options.camera_frame;
      const geometry_msgs::Pose p = PoseFromCamera(v.camera);
      T.transform.translation.x = p.position.x;
      T.transform.translation.y = p.position.y;
      T.transform.translation.z = p.position.z;
      T.transform.rotation = p.orientation;
      tf2_msgs::TFMessage tf;
      tf.transforms.push_back(T);
      bag.write("/tf", t, tf);
      if (options.with_pose) {
        geometry_msgs::PoseStamped ps;
        ps.header.stamp = t;
        ps.header.frame_id = options.world_frame;
        ps.pose = p;
        bag.write(options.pose_topic, t, ps);
      }

      sensor_msgs::CameraInfo info = CameraInfoFromCamera(v.camera);
      info.header.stamp = t;
      info.header.frame_id = options.camera_frame;
      bag.write(options.info_topic, t, info);

      const cv::Mat img = image_rgb8(i);
      Require(img.type() == CV_8UC3 && img.cols == v.camera.width &&
                  img.rows == v.camera.height,
              "to-bag: image of view '", v.name, "' is not ", v.camera.width,
              "x", v.camera.height, " 8-bit RGB");
      if (!options.compression.empty()) {
        sensor_msgs::CompressedImage cm;
        cm.header = info.header;
        cv::Mat bgr;
        cv::cvtColor(img, bgr, cv::COLOR_RGB2BGR);
        std::vector<int> params;
        if (options.compression == "jpeg")
          params = {cv::IMWRITE_JPEG_QUALITY, options.jpeg_quality};
        const std::string ext = options.compression == "png" ? ".png" : ".jpg";
        Require(cv::imencode(ext, bgr, cm.data, params),
                "to-bag: cannot encode view '", v.name, "' as ",
                options.compression);
        // image_transport's "compressed" format string.
        cm.format = "rgb8; " + options.compression + " compressed bgr8";
        bag.write(options.image_topic + "/compressed", t, cm);
      } else {
        sensor_msgs::Image im;
        im.header = info.header;
        im.width = img.cols;
        im.height = img.rows;
        im.encoding = sensor_msgs::image_encodings::RGB8;
        im.step = img.cols * 3;
        im.data.resize(static_cast<size_t>(im.step) * im.height);
        for (int r = 0; r < img.rows; ++r)
          std::memcpy(&im.data[static_cast<size_t>(r) * im.step], img.ptr(r),
                      im.step);
        bag.write(options.image_topic, t, im);
      }

      if (options.with_points) {
        wild_mvs::SparsePoints sp;
        sp.header.stamp = t;
        sp.header.frame_id = options.world_frame;
        for (const SparsePoint& q : scene.points) {
          wild_mvs::TrackedPoint m;
          m.position.x = q.xyz.x();
          m.position.y = q.xyz.y();
          m.position.z = q.xyz.z();
          for (const Observation& o : q.track) {
            if (o.view < 0 || o.view > i) continue;
            m.stamps.push_back(stamp_of(o.view));
            m.x.push_back(static_cast<float>(o.xy.x() - 0.5));  // -> ROS
            m.y.push_back(static_cast<float>(o.xy.y() - 0.5));
          }
          if (m.stamps.size() >= 2) sp.points.push_back(std::move(m));
        }
        bag.write(options.points_topic, t, sp);
      }
    }
    bag.close();
    return true;
  });
}

}  // namespace ros1
}  // namespace wild_mvs
