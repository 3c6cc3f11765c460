// Copyright wild_mvs authors. The depth node's inputs: the subscriptions
// (image through image_transport or the compressed fallback, camera_info,
// pose, sparse_points) and the conversion of a received image into what
// the StreamReconstructor takes: camera_info paired by stamp, pixels decoded
// to linear RGB and undistorted, pose from tf2 or the pose topic (waits in
// wall time). Every failure drops the frame through the node's drop
// callback (counted, throttled) naming the topic and the problem.
#pragma once

#include <geometry_msgs/PoseStamped.h>
#include <geometry_msgs/PoseWithCovarianceStamped.h>
#include <geometry_msgs/TransformStamped.h>
#include <image_transport/image_transport.h>
#include <nav_msgs/Odometry.h>
#include <ros/node_handle.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/CompressedImage.h>
#include <sensor_msgs/Image.h>
#include <tf2_ros/buffer.h>
#include <tf2_ros/transform_listener.h>
#include <wild_mvs/KeyframeIndex.h>
#include <wild_mvs/SelectedKeyframe.h>
#include <wild_mvs/SparsePoints.h>

#include <Eigen/Geometry>
#include <atomic>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <opencv2/core.hpp>
#include <set>
#include <string>
#include <vector>

#include "wild_mvs/core/camera.h"
#include "wild_mvs/ros/params.h"
#include "wild_mvs/stream/pose_track.h"
#include "wild_mvs/stream/stamp_buffer.h"
#include "wild_mvs/stream/stream_reconstructor.h"
#include "wild_mvs/stream/undistorter.h"

namespace wild_mvs {
namespace ros1 {

// A received image (raw or compressed), before conversion; for a depth
// worker a keyframe message or a keyframe index instead.
struct DepthFrame {
  sensor_msgs::ImageConstPtr raw;
  sensor_msgs::CompressedImageConstPtr compressed;
  sensor_msgs::CameraInfoConstPtr info;  // set by PairCameraInfo
  // The image is rectified: the camera is P's, D is ignored (~rectified or
  // an image_rect topic; a worker: the selector's SelectedKeyframe).
  bool rectified = false;
  ros::Time stamp;
  std::string frame_id;
  wild_mvs::SelectedKeyframeConstPtr keyframe;
  wild_mvs::KeyframeIndexConstPtr index;
};

class DepthInputs {
 public:
  // topic, problem, detail
  using DropFn = std::function<void(const std::string&, const std::string&,
                                    const std::string&)>;
  using FrameFn = std::function<void(DepthFrame)>;
  using PointsFn =
      std::function<void(std::vector<StreamReconstructor::StampedPoint>)>;

  // `options` (the node's, outliving this) are read when used, so that the
  // node may strip the frames' '/' with NoSlash after construction.
  DepthInputs(const ros::NodeHandle& nh, const ros::NodeHandle& private_nh,
              const DepthNodeOptions& options, DropFn drop);
  // Subscribes: images go to on_frame, sparse points (sparse_source
  // "topic") to on_points, both on the callback threads. Throws Error when
  // the image_transport plugin is not installed.
  void Subscribe(FrameFn on_frame, PointsFn on_points);
  // Ends the waits (for good) and unsubscribes the images and points.
  void Stop();

  // The camera's optical frame (~camera_frame, else the image's) and the
  // camera_info of the frame's stamp (or the latest): false when none came
  // within tf_timeout.
  bool PairCameraInfo(DepthFrame* f);
  // The three steps of a paired frame, each false when the frame is
  // dropped (counted): the camera's intrinsics from its camera_info; its
  // pose (tf, or the pose topic interpolated at the stamp, with the body
  // extrinsic); and, only for a frame kept as a keyframe, the image
  // decoded to linear RGB and undistorted (which may change the camera's
  // intrinsics).
  bool CameraFromInfo(const DepthFrame& f, Camera* cam);
  bool LookupPose(const DepthFrame& f, Camera* cam);
  bool ConvertImage(const DepthFrame& f, Camera* cam, cv::Mat* image);

  // The topic a frame came on (for messages) and the resolved inputs.
  std::string ImageTopic(const DepthFrame& f) const;
  std::string Topic(const std::string& name) const;
  // The subscribed topics (resolved) and what a full roscpp queue of each
  // means (RoscppDropWatch's hint).
  std::map<std::string, std::string> QueueParams() const;
  // "images <topic> (<transport>[, rectified]), camera_info <topic> (...),
  // pose from ..., sparse points from ..., world frame '...'" for the
  // node's start message.
  std::string Describe() const;
  // A frame id as tf2 wants it: without leading '/' (tf2 rejects them, and
  // many recorded bags have them); warns once per frame id.
  std::string NoSlash(const std::string& frame_id);

 private:
  // The pose topic's messages, by type (pose_source).
  void OnPoseStamped(const geometry_msgs::PoseStampedConstPtr& msg);
  void OnPoseWithCovariance(
      const geometry_msgs::PoseWithCovarianceStampedConstPtr& msg);
  void OnTransform(const geometry_msgs::TransformStampedConstPtr& msg);
  void OnOdometry(const nav_msgs::OdometryConstPtr& msg);
  // One pose message: world frame checked, the pose kept by its stamp.
  // `child` is the frame it is the pose of ("" = the camera).
  void AddPose(const std_msgs::Header& header, const std::string& child,
               const geometry_msgs::Pose& pose);
  // T_body_camera: ~camera_extrinsic, else tf (latest) body <- camera.
  bool BodyToCamera(const std::string& body, const std::string& camera,
                    Eigen::Isometry3d* T);
  void OnRaw(const sensor_msgs::ImageConstPtr& msg);
  void OnCompressed(const sensor_msgs::CompressedImageConstPtr& msg);
  void OnInfo(const sensor_msgs::CameraInfoConstPtr& msg);
  void OnSparsePoints(const wild_mvs::SparsePointsConstPtr& msg);

  ros::NodeHandle nh_, pnh_;
  const DepthNodeOptions& options_;
  DropFn drop_;
  FrameFn on_frame_;
  PointsFn on_points_;
  std::string image_topic_, info_topic_;  // resolved input names
  bool rectified_ = false;                // the images' DepthFrame::rectified
  std::unique_ptr<Undistorter> undistorter_;  // front end only
  std::unique_ptr<tf2_ros::Buffer> tf_buffer_;
  std::unique_ptr<tf2_ros::TransformListener> tf_listener_;
  std::unique_ptr<image_transport::ImageTransport> it_;
  image_transport::Subscriber image_sub_;
  ros::Subscriber compressed_sub_, info_sub_, pose_sub_, points_sub_;
  // camera_infos by exact stamp (ns) and poses of the pose topic.
  ExactStampBuffer<sensor_msgs::CameraInfoConstPtr> infos_{100};
  // Poses of the pose topic (frame-to-world) and the frame they are of
  // (the messages' child_frame_id or ~pose_frame; "" = the camera).
  PoseTrack poses_{2000};
  std::mutex pose_frame_mutex_;
  std::string pose_frame_;
  // ~camera_extrinsic, parsed (when set).
  bool have_extrinsic_ = false;
  Eigen::Isometry3d body_T_camera_ = Eigen::Isometry3d::Identity();
  std::atomic<bool> stopping_{false};
  std::mutex slash_mutex_;
  std::set<std::string> slash_warned_;  // frame ids warned about once
};

}  // namespace ros1
}  // namespace wild_mvs
