// Copyright wild_mvs authors.
#include "wild_mvs/ros/scene_bag.h"

#include <geometry_msgs/PoseStamped.h>
#include <geometry_msgs/TransformStamped.h>
#include <rosbag/bag.h>
#include <sensor_msgs/CompressedImage.h>
#include <sensor_msgs/image_encodings.h>
#include <tf2_msgs/TFMessage.h>
#include <wild_mvs/SparsePoints.h>

#include <Eigen/Geometry>
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
  Require(frames_per_view >= 1 && frames_per_view <= 1000, "--frames-per-view ",
          frames_per_view, " must be in [1, 1000]");
  Require(std::isfinite(frame_rate) && frame_rate > 0 && frame_rate <= 1000,
          "--frame-rate ", frame_rate, " must be in (0, 1000] Hz");
  Require((frames_per_view - 1) / frame_rate < 1 / rate, "--frames-per-view ",
          frames_per_view, " at --frame-rate ", frame_rate,
          " Hz do not fit between views at --rate ", rate, " Hz");
  Require(body_frame != world_frame && body_frame != camera_frame,
          "--body-frame '", body_frame,
          "' must differ from the world and "
          "camera frames");
  Require(std::isfinite(tf_rate) && tf_rate > 0 && tf_rate <= 10000,
          "tf_rate = ", tf_rate, " must be in (0, 10000] Hz");
}

Eigen::Matrix3d BodyToOpticalRotation() {
  Eigen::Matrix3d R;
  R << 0, 0, 1,  //
      -1, 0, 0,  //
      0, -1, 0;
  return R;
}

geometry_msgs::Transform TransformMsg(const Eigen::Matrix3d& R,
                                      const Eigen::Vector3d& t) {
  geometry_msgs::Transform m;
  m.translation.x = t.x();
  m.translation.y = t.y();
  m.translation.z = t.z();
  Eigen::Quaterniond q(R);
  q.normalize();
  m.rotation.x = q.x();
  m.rotation.y = q.y();
  m.rotation.z = q.z();
  m.rotation.w = q.w();
  return m;
}

boost::shared_ptr<ros::M_string> LatchedTfStaticHeader() {
  const tf2_msgs::TFMessage m;
  auto h = boost::make_shared<ros::M_string>();
  (*h)["type"] = ros::message_traits::datatype(m);
  (*h)["md5sum"] = ros::message_traits::md5sum(m);
  (*h)["message_definition"] = ros::message_traits::definition(m);
  (*h)["callerid"] = "/static_transform_publisher";
  (*h)["latching"] = "1";
  return h;
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

namespace {
// Frame of view i at stamp t (its tf without a body frame, pose, camera
// info, image; the sparse points with the view's first frame).
void WriteFrame(const Scene& scene, int i, const cv::Mat& img,
                const ros::Time& t, bool first_frame, bool body,
                const SceneBagOptions& options,
                const std::function<ros::Time(int)>& stamp_of,
                rosbag::Bag* bag);
}  // namespace

void WriteSceneBag(const Scene& scene,
                   const std::function<cv::Mat(int)>& image_rgb8,
                   const std::string& path, const SceneBagOptions& options) {
  options.Check();
  Require(!scene.views.empty(), "to-bag: the scene has no views");
  if (!ros::Time::isValid()) ros::Time::init();
  const int n = static_cast<int>(scene.views.size());
  // Stamp of frame j of view i.
  auto frame_stamp = [&](int i, int j) {
    return ros::Time(options.start_time + i / options.rate +
                     j / options.frame_rate);
  };
  auto stamp_of = [&](int i) { return frame_stamp(i, 0); };
  const bool body = !options.body_frame.empty();
  const Eigen::Matrix3d body_R_cam = BodyToOpticalRotation();
  const Eigen::Vector3d body_t_cam(options.extrinsic_translation[0],
                                   options.extrinsic_translation[1],
                                   options.extrinsic_translation[2]);
  ProduceFileAtomically(path, [&](const std::string& tmp) {
    rosbag::Bag bag(tmp, rosbag::bagmode::Write);
    if (body) {
      // rosbag play orders messages by time: /tf_static first (latched, as
      // `rosbag record` keeps it), then /tf from 0.1 s before the first
      // frame to 0.1 s after the last.
      const double t0 = stamp_of(0).toSec() - 0.1;
      const double t1 =
          frame_stamp(n - 1, options.frames_per_view - 1).toSec() + 0.1;
      geometry_msgs::TransformStamped S;
      S.header.stamp = ros::Time(t0 - 0.001);
      S.header.frame_id = options.body_frame;
      S.child_frame_id = options.camera_frame;
      S.transform = TransformMsg(body_R_cam, body_t_cam);
      tf2_msgs::TFMessage st;
      st.transforms.push_back(S);
      bag.write("/tf_static", S.header.stamp, st, LatchedTfStaticHeader());
      const double linger = (options.frames_per_view - 1) / options.frame_rate;
      for (long k = 0;; ++k) {
        const double t = t0 + k / options.tf_rate;
        if (t > t1) break;
        // The view whose frames [start, start + linger] are nearest to t.
        int best = 0;
        double best_d = 1e300;
        for (int i = 0; i < n; ++i) {
          const double a = stamp_of(i).toSec(), b = a + linger;
          const double d = t < a ? a - t : (t > b ? t - b : 0.0);
          if (d < best_d) best_d = d, best = i;
        }
        const Camera& c = scene.views[best].camera;
        // world_T_body = world_T_camera * camera_T_body.
        const Eigen::Matrix3d world_R_cam = c.R.transpose();
        const Eigen::Matrix3d world_R_body =
            world_R_cam * body_R_cam.transpose();
        const Eigen::Vector3d world_t_body =
            c.Center() - world_R_body * body_t_cam;
        geometry_msgs::TransformStamped T;
        T.header.stamp = ros::Time(t);
        T.header.frame_id = options.world_frame;
        T.child_frame_id = options.body_frame;
        T.transform = TransformMsg(world_R_body, world_t_body);
        tf2_msgs::TFMessage tf;
        tf.transforms.push_back(T);
        bag.write("/tf", T.header.stamp, tf);
      }
    }
    for (int i = 0; i < n; ++i) {
      const View& v = scene.views[i];
      const cv::Mat img = image_rgb8(i);
      Require(img.type() == CV_8UC3 && img.cols == v.camera.width &&
                  img.rows == v.camera.height,
              "to-bag: image of view '", v.name, "' is not ", v.camera.width,
              "x", v.camera.height, " 8-bit RGB");
      for (int j = 0; j < options.frames_per_view; ++j) {
        WriteFrame(scene, i, img, frame_stamp(i, j), j == 0, body, options,
                   stamp_of, &bag);
      }
    }
    bag.close();
    return true;
  });
}

namespace {
void WriteFrame(const Scene& scene, int i, const cv::Mat& img,
                const ros::Time& t, bool first_frame, bool body,
                const SceneBagOptions& options,
                const std::function<ros::Time(int)>& stamp_of,
                rosbag::Bag* bag_ptr) {
  rosbag::Bag& bag = *bag_ptr;
  const View& v = scene.views[i];
  {
    {
      const geometry_msgs::Pose p = PoseFromCamera(v.camera);
      if (!body) {
        // tf first, so the pose is there when the image arrives.
        geometry_msgs::TransformStamped T;
        T.header.stamp = t;
        T.header.frame_id = options.world_frame;
        T.child_frame_id = options.camera_frame;
        T.transform.translation.x = p.position.x;
        T.transform.translation.y = p.position.y;
        T.transform.translation.z = p.position.z;
        T.transform.rotation = p.orientation;
        tf2_msgs::TFMessage tf;
        tf.transforms.push_back(T);
        bag.write("/tf", t, tf);
      }
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

      if (options.with_points && first_frame) {
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
  }
}

}  // namespace

}  // namespace ros1
}  // namespace wild_mvs
