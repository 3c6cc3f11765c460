// Copyright wild_mvs authors. A calibrated scene as a rosbag, as a camera
// driver with localisation would record it (`wild_mvs to-bag`).
//
// View i (scene order) becomes, at stamp start_time + i / rate:
//   /tf                  tf2_msgs/TFMessage world_frame -> camera_frame
//                        (the camera optical frame, REP 103/105; the pose
//                        is the camera's pose in the world)
//   /camera/camera_info  sensor_msgs/CameraInfo (ROS pixel convention, no
//                        distortion: images are undistorted)
//   /camera/image_raw    sensor_msgs/Image rgb8 (sRGB, as the camera gives)
//   /camera/image_raw/compressed  sensor_msgs/CompressedImage instead of
//                        the raw image when compression is "png" / "jpeg"
//                        (the image_transport "compressed" topic)
//   /camera/pose         geometry_msgs/PoseStamped (with_pose): the same
//                        pose as /tf (camera optical frame in the world)
//   /sparse_points       wild_mvs/SparsePoints (with_points): the scene's
//                        points seen by >= 2 of the views so far, with their
//                        observations by stamp (ROS pixel convention)
//
// As a robot records (frames_per_view > 1, body_frame set): the camera
// lingers on each view for frames_per_view frames frame_rate apart (same
// image and pose, distinct stamps, all before the next view), and /tf
// carries world_frame -> body_frame at tf_rate, with one latched /tf_static
// body_frame -> camera_frame (x forward, z up body to z forward, y down
// optical, plus extrinsic_translation); the /tf samples take the pose of
// the view whose frames are nearest in time, so tf interpolation at an
// image stamp gives that view's pose exactly.
#pragma once

#include <geometry_msgs/Transform.h>
#include <ros/datatypes.h>

#include <Eigen/Core>
#include <functional>
#include <opencv2/core.hpp>
#include <string>

#include "wild_mvs/core/scene.h"

namespace wild_mvs {
namespace ros1 {

struct SceneBagOptions {
  double rate = 5.0;           // frames per second (Hz)
  bool with_points = false;    // also write /sparse_points
  double start_time = 1000.0;  // stamp of the first frame, seconds
  std::string world_frame = "world";
  std::string camera_frame = "camera_optical_frame";
  std::string image_topic = "/camera/image_raw";
  std::string info_topic = "/camera/camera_info";
  std::string points_topic = "/sparse_points";
  std::string compression;  // "" = raw rgb8, "png" or "jpeg" (compressed)
  int jpeg_quality = 95;
  bool with_pose = false;  // also write pose_topic (PoseStamped)
  std::string pose_topic = "/camera/pose";
  int frames_per_view = 1;   // frames of each view, >= 1
  double frame_rate = 30.0;  // Hz between the frames of one view
  // "" = /tf world_frame -> camera_frame with each frame; else the body
  // frame of /tf (at tf_rate Hz) and /tf_static (body -> camera).
  std::string body_frame;
  double tf_rate = 100.0;  // Hz, with body_frame
  double extrinsic_translation[3] = {0.08, -0.025, 0.04};  // m, body frame
  void Check() const;
};

// Writes the bag atomically (temporary file + rename). image(i) returns view
// i's image as 8-bit sRGB RGB (CV_8UC3) of the camera's size. Throws Error.
void WriteSceneBag(const Scene& scene,
                   const std::function<cv::Mat(int)>& image_rgb8,
                   const std::string& path, const SceneBagOptions& options);

// Linear RGB float (the core's image type) -> 8-bit sRGB RGB.
cv::Mat LinearToSrgb8(const cv::Mat& linear_rgb);

// The usual body -> camera optical frame rotation (REP 103: body x forward,
// y left, z up; optical z forward, x right, y down): columns are the
// optical axes in the body frame.
Eigen::Matrix3d BodyToOpticalRotation();
// The transform of rotation R and translation t (parent <- child).
geometry_msgs::Transform TransformMsg(const Eigen::Matrix3d& R,
                                      const Eigen::Vector3d& t);
// A connection header for /tf_static (tf2_msgs/TFMessage) with latching=1:
// rosbag play re-publishes it latched, as `rosbag record` stores it.
boost::shared_ptr<ros::M_string> LatchedTfStaticHeader();

}  // namespace ros1
}  // namespace wild_mvs
