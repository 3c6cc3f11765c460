// Copyright wild_mvs authors.
#include "wild_mvs/ros/depth_inputs.h"

#include <image_transport/camera_common.h>
#include <ros/console.h>

#include <algorithm>
#include <chrono>
#include <thread>

#include "wild_mvs/core/error.h"
#include "wild_mvs/ros/conversions.h"
#include "wild_mvs/ros/depth_messages.h"

namespace wild_mvs {
namespace ros1 {

namespace {
bool EndsWith(const std::string& s, const std::string& tail) {
  return s.size() >= tail.size() &&
         s.compare(s.size() - tail.size(), tail.size(), tail) == 0;
}
}  // namespace

DepthInputs::DepthInputs(const ros::NodeHandle& nh,
                         const ros::NodeHandle& private_nh,
                         const DepthNodeOptions& options, DropFn drop)
    : nh_(nh), pnh_(private_nh), options_(options), drop_(std::move(drop)) {
  // camera_info sits beside the image (image_transport's CameraSubscriber
  // convention) unless `camera_info` is remapped itself.
  image_topic_ = nh_.resolveName("image");
  info_topic_ = nh_.resolveName("camera_info");
  if (info_topic_ == nh_.resolveName("camera_info", false))
    info_topic_ = image_transport::getCameraInfoTopic(image_topic_);
  rectified_ = options_.rectified || EndsWith(image_topic_, "/image_rect") ||
               EndsWith(image_topic_, "/image_rect_color");
  undistorter_ = std::make_unique<Undistorter>();
}

void DepthInputs::Subscribe(FrameFn on_frame, PointsFn on_points) {
  on_frame_ = std::move(on_frame);
  on_points_ = std::move(on_points);
  const DepthNodeOptions& o = options_;
  if (!o.camera_extrinsic.empty()) {
    body_T_camera_ = ParseCameraExtrinsic(o.camera_extrinsic);
    have_extrinsic_ = true;
  }
  pose_frame_ = NoSlash(o.pose_frame);
  // tf: the pose itself, or a body's camera extrinsic from /tf_static.
  if (o.pose_source == "tf" || !have_extrinsic_) {
    tf_buffer_ = std::make_unique<tf2_ros::Buffer>(ros::Duration(30.0));
    tf_listener_ =
        std::make_unique<tf2_ros::TransformListener>(*tf_buffer_, nh_, true);
  }
  const int q = kPoseQueueSize;
  if (o.pose_source == "pose" || o.pose_source == "topic") {
    pose_sub_ = nh_.subscribe("pose", q, &DepthInputs::OnPoseStamped, this);
  } else if (o.pose_source == "pose_with_covariance") {
    pose_sub_ =
        nh_.subscribe("pose", q, &DepthInputs::OnPoseWithCovariance, this);
  } else if (o.pose_source == "transform") {
    pose_sub_ = nh_.subscribe("pose", q, &DepthInputs::OnTransform, this);
  } else if (o.pose_source == "odometry") {
    pose_sub_ = nh_.subscribe("pose", q, &DepthInputs::OnOdometry, this);
  }
  if (o.sparse_source == "topic")
    points_sub_ =
        nh_.subscribe("sparse_points", 2, &DepthInputs::OnSparsePoints, this);
  info_sub_ = nh_.subscribe(info_topic_, kCameraInfoQueueSize,
                            &DepthInputs::OnInfo, this);
  it_ = std::make_unique<image_transport::ImageTransport>(nh_);
  const std::vector<std::string> plugins = it_->getLoadableTransports();
  const bool have_plugin = std::find(plugins.begin(), plugins.end(),
                                     o.image_transport) != plugins.end();
  if (o.image_transport == "raw" || have_plugin) {
    image_sub_ =
        it_->subscribe(image_topic_, kImageQueueSize, &DepthInputs::OnRaw, this,
                       image_transport::TransportHints(
                           o.image_transport, ros::TransportHints(), pnh_,
                           "image_transport_hints"));
  } else if (o.image_transport == "compressed") {
    // No compressed plugin installed (Debian 12 ships none): take
    // <image>/compressed and decode it here. "image" is remapped as a
    // whole name, so it is resolved before appending.
    compressed_sub_ =
        nh_.subscribe(image_topic_ + "/compressed", kImageQueueSize,
                      &DepthInputs::OnCompressed, this);
  } else {
    std::string names;
    for (const std::string& p : plugins) names += " " + p;
    throw Error(Msg("image_transport = '", o.image_transport,
                    "': no such image_transport plugin is installed "
                    "(loadable:",
                    names, ")"));
  }
}

void DepthInputs::OnRaw(const sensor_msgs::ImageConstPtr& msg) {
  DepthFrame f;
  f.raw = msg;
  f.rectified = rectified_;
  f.stamp = msg->header.stamp;
  f.frame_id = msg->header.frame_id;
  on_frame_(std::move(f));
}

void DepthInputs::OnCompressed(
    const sensor_msgs::CompressedImageConstPtr& msg) {
  DepthFrame f;
  f.compressed = msg;
  f.rectified = rectified_;
  f.stamp = msg->header.stamp;
  f.frame_id = msg->header.frame_id;
  on_frame_(std::move(f));
}

void DepthInputs::OnInfo(const sensor_msgs::CameraInfoConstPtr& msg) {
  infos_.Add(msg->header.stamp.toNSec(), msg);
}

void DepthInputs::OnPoseStamped(const geometry_msgs::PoseStampedConstPtr& msg) {
  AddPose(msg->header, "", msg->pose);
}

void DepthInputs::OnPoseWithCovariance(
    const geometry_msgs::PoseWithCovarianceStampedConstPtr& msg) {
  AddPose(msg->header, "", msg->pose.pose);
}

void DepthInputs::OnTransform(
    const geometry_msgs::TransformStampedConstPtr& msg) {
  geometry_msgs::Pose p;
  p.position.x = msg->transform.translation.x;
  p.position.y = msg->transform.translation.y;
  p.position.z = msg->transform.translation.z;
  p.orientation = msg->transform.rotation;
  AddPose(msg->header, msg->child_frame_id, p);
}

void DepthInputs::OnOdometry(const nav_msgs::OdometryConstPtr& msg) {
  AddPose(msg->header, msg->child_frame_id, msg->pose.pose);
}

void DepthInputs::AddPose(const std_msgs::Header& header,
                          const std::string& child,
                          const geometry_msgs::Pose& pose) {
  const std::string topic = Topic("pose");
  if (NoSlash(header.frame_id) != options_.world_frame) {
    drop_(topic, "pose frame_id is not the world frame",
          "'" + header.frame_id + "' vs '" + options_.world_frame + "'");
    return;
  }
  // The frame the poses are of: the messages' child_frame_id (transform,
  // odometry) unless ~pose_frame says otherwise; one frame per stream.
  if (!child.empty() && options_.pose_frame.empty()) {
    const std::string frame = NoSlash(child);
    std::lock_guard<std::mutex> lock(pose_frame_mutex_);
    if (pose_frame_.empty()) {
      pose_frame_ = frame;
    } else if (frame != pose_frame_) {
      drop_(topic, "pose child_frame_id changed (poses of one frame expected)",
            "'" + frame + "' after '" + pose_frame_ + "'");
      return;
    }
  }
  try {
    poses_.Add(header.stamp.toNSec(), IsometryFromMsg(pose));
  } catch (const Error& e) {
    drop_(topic, "invalid pose", e.what());
  }
}

void DepthInputs::Stop() {
  stopping_ = true;
  infos_.Stop();
  poses_.Stop();
  image_sub_.shutdown();
  compressed_sub_.shutdown();
  points_sub_.shutdown();
}

std::map<std::string, std::string> DepthInputs::QueueParams() const {
  std::map<std::string, std::string> out;
  if (image_sub_)
    out[image_sub_.getTopic()] = "the node falls behind the images";
  if (compressed_sub_)
    out[compressed_sub_.getTopic()] = "the node falls behind the images";
  if (info_sub_)
    out[info_sub_.getTopic()] = "the node falls behind camera_info";
  if (pose_sub_) out[pose_sub_.getTopic()] = "the node falls behind the poses";
  return out;
}

std::string DepthInputs::Topic(const std::string& name) const {
  return nh_.resolveName(name);
}

std::string DepthInputs::ImageTopic(const DepthFrame& f) const {
  return image_topic_ + (f.raw ? "" : "/" + options_.image_transport);
}

std::string DepthInputs::Describe() const {
  const DepthNodeOptions& o = options_;
  return Msg("images ", image_topic_, " (", o.image_transport,
             rectified_ ? ", rectified" : "", "), camera_info ", info_topic_,
             " (", o.camera_info_latest ? "latest" : "paired by stamp",
             "), pose from ", o.pose_source, ", sparse points from ",
             o.sparse_source, ", world frame '", o.world_frame, "'");
}

std::string DepthInputs::NoSlash(const std::string& frame_id) {
  const std::string stripped = StripLeadingSlash(frame_id);
  if (stripped == frame_id) return frame_id;
  bool first = false;
  {
    std::lock_guard<std::mutex> lock(slash_mutex_);
    first = slash_warned_.insert(frame_id).second;
  }
  if (first)
    ROS_WARN(
        "%s: frame id '%s' starts with '/', which tf2 does not accept: "
        "using '%s' (warned once per frame id)",
        pnh_.getNamespace().c_str(), frame_id.c_str(), stripped.c_str());
  return stripped;
}

void DepthInputs::OnSparsePoints(const wild_mvs::SparsePointsConstPtr& msg) {
  if (NoSlash(msg->header.frame_id) != options_.world_frame) {
    drop_(Topic("sparse_points"), "frame_id is not the world frame",
          "'" + msg->header.frame_id + "' vs '" + options_.world_frame + "'");
    return;
  }
  on_points_(StampedPointsFromMsg(*msg));
}

bool DepthInputs::PairCameraInfo(DepthFrame* f) {
  // The camera's optical frame: ~camera_frame, else the image's.
  f->frame_id = NoSlash(options_.camera_frame.empty() ? f->frame_id
                                                      : options_.camera_frame);
  // The camera_info with the frame's exact stamp (waiting up to tf_timeout
  // of wall time for it), or with camera_info_latest the latest one.
  if (options_.camera_info_latest) {
    if (infos_.WaitLatest(options_.tf_timeout, &f->info)) return true;
    drop_(info_topic_, "no camera_info received yet", "");
    return false;
  }
  using Found = ExactStampBuffer<sensor_msgs::CameraInfoConstPtr>::Found;
  const Found found =
      infos_.WaitExact(f->stamp.toNSec(), options_.tf_timeout, &f->info);
  if (found == Found::kYes) return true;
  drop_(info_topic_,
        found == Found::kOther
            ? "no camera_info with the image's stamp (images and "
              "camera_info are paired by exact stamp; set "
              "camera_info_latest:=true for a driver that publishes it "
              "once or at another rate)"
            : "no camera_info received yet",
        "");
  return false;
}

bool DepthInputs::CameraFromInfo(const DepthFrame& f, Camera* cam) {
  Distortion dist;
  try {
    CameraFromCameraInfo(*f.info, cam, &dist, f.rectified);
  } catch (const Error& e) {
    drop_(info_topic_, "invalid camera_info", e.what());
    return false;
  }
  return true;
}

bool DepthInputs::ConvertImage(const DepthFrame& f, Camera* cam,
                               cv::Mat* image) {
  const std::string image_topic = ImageTopic(f);
  try {
    *image = f.raw ? ImageToLinearRgb(*f.raw, true)
                   : CompressedToLinearRgb(*f.compressed, true);
  } catch (const Error& e) {
    drop_(image_topic, "invalid image", e.what());
    return false;
  }
  if (image->cols != cam->width || image->rows != cam->height) {
    drop_(image_topic, "image size differs from camera_info",
          Msg(image->cols, "x", image->rows, " vs ", cam->width, "x",
              cam->height));
    return false;
  }
  // Undistorted with maps built once per camera_info (a rectified
  // input passes through: the camera is P's, without distortion).
  try {
    Distortion d;
    CameraFromCameraInfo(*f.info, cam, &d, f.rectified);
    *image = undistorter_->Apply(*cam, d, *image);
  } catch (const Error& e) {
    drop_(info_topic_, "invalid camera_info", e.what());
    return false;
  }
  return true;
}

bool DepthInputs::BodyToCamera(const std::string& body,
                               const std::string& camera,
                               Eigen::Isometry3d* T) {
  if (have_extrinsic_) {
    *T = body_T_camera_;
    return true;
  }
  // A static extrinsic: the latest transform (/tf_static), waiting up to
  // tf_timeout of wall time for it to arrive.
  const auto deadline = std::chrono::steady_clock::now() +
                        std::chrono::duration<double>(options_.tf_timeout);
  while (!tf_buffer_->canTransform(body, camera, ros::Time(0)) &&
         std::chrono::steady_clock::now() < deadline && !stopping_) {
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
  try {
    *T = IsometryFromMsg(
        tf_buffer_->lookupTransform(body, camera, ros::Time(0)).transform);
  } catch (const tf2::TransformException& e) {
    drop_("tf",
          "no camera extrinsic body <- camera (publish it on /tf_static or "
          "set ~camera_extrinsic)",
          body + " <- " + camera + ": " + e.what());
    return false;
  } catch (const Error& e) {
    drop_("tf", "invalid camera extrinsic",
          body + " <- " + camera + ": " + e.what());
    return false;
  }
  return true;
}

// Pose of the frame from tf or the pose topic; false (and counted) when
// there is none within the timeout.
bool DepthInputs::LookupPose(const DepthFrame& f, Camera* cam) {
  const DepthNodeOptions& o = options_;
  if (o.pose_source == "tf") {
    if (f.frame_id.empty()) {
      drop_(Topic("image"), "image has an empty frame_id (needed for tf)", "");
      return false;
    }
    geometry_msgs::TransformStamped T;
    try {
      // Wait in wall time (tf2's own timeout runs on ROS time, which
      // stands still when /clock pauses), polling the buffer.
      const auto deadline = std::chrono::steady_clock::now() +
                            std::chrono::duration<double>(o.tf_timeout);
      while (!tf_buffer_->canTransform(o.world_frame, f.frame_id, f.stamp) &&
             std::chrono::steady_clock::now() < deadline) {
        if (stopping_) break;
        std::this_thread::sleep_for(std::chrono::milliseconds(2));
      }
      T = tf_buffer_->lookupTransform(o.world_frame, f.frame_id, f.stamp);
    } catch (const tf2::TransformException& e) {
      drop_("tf",
            "no transform " + o.world_frame + " <- " + f.frame_id +
                " at the image stamp within tf_timeout",
            e.what());
      return false;
    }
    try {
      SetCameraPose(T.transform, cam);
    } catch (const Error& e) {
      drop_("tf", "invalid pose", e.what());
      return false;
    }
    return true;
  }
  // Pose topic: interpolated at the image stamp (slerp + lerp between the
  // poses around it, at most kPoseMaxGap apart), never extrapolated.
  Eigen::Isometry3d world_T_frame;
  const PoseTrack::Result r =
      poses_.WaitAt(f.stamp.toNSec(), kPoseSyncTolerance, kPoseMaxGap,
                    o.tf_timeout, &world_T_frame);
  if (!PoseTrack::Ok(r)) {
    drop_(Topic("pose"), PoseTrack::Describe(r), "");
    return false;
  }
  // Poses of a body frame: T_world_camera = T_world_body * T_body_camera.
  std::string body;
  {
    std::lock_guard<std::mutex> lock(pose_frame_mutex_);
    body = pose_frame_;
  }
  Eigen::Isometry3d world_T_camera = world_T_frame;
  if (!body.empty() && body != f.frame_id) {
    Eigen::Isometry3d body_T_camera;
    if (!BodyToCamera(body, f.frame_id, &body_T_camera)) return false;
    world_T_camera = world_T_frame * body_T_camera;
  }
  SetCameraPose(world_T_camera, cam);
  return true;
}

}  // namespace ros1
}  // namespace wild_mvs
