// Copyright wild_mvs authors. Conversions between ROS messages and the core's
// types. Every function validates its input and throws wild_mvs::Error
// naming the problem (the caller adds the topic), so a malformed message can
// never crash a node or reach an algorithm.
//
// Pixel convention. The core puts the centre of the top-left pixel at
// (0.5, 0.5) (camera.h); ROS CameraInfo (like OpenCV) puts it at (0, 0). So
// cx_core = K[2] + 0.5, cy_core = K[5] + 0.5, and back with - 0.5. Sparse
// point observations on ROS use the ROS convention too.
//
// Poses. tf / PoseStamped give the camera optical frame in the world frame
// (T_world_camera: x_world = R_wc x_cam + t_wc). The core stores
// world-to-camera: R = R_wc^T, t = -R_wc^T t_wc. The ROS camera optical frame
// (REP 103: x right, y down, z forward) is the core's camera frame.
//
// Depth images follow REP 118: 32FC1, metres along z, NaN where unknown (the
// core uses 0). Confidence 32FC1 in [0, 1]. Normals 32FC3 (camera frame), NaN
// where unknown.
#pragma once

#include <geometry_msgs/Pose.h>
#include <geometry_msgs/Transform.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/CompressedImage.h>
#include <sensor_msgs/Image.h>
#include <sensor_msgs/PointCloud2.h>
#include <visualization_msgs/Marker.h>
#include <wild_mvs/DepthView.h>

#include <Eigen/Geometry>
#include <opencv2/core.hpp>
#include <string>

#include "wild_mvs/core/camera.h"
#include "wild_mvs/core/depth_map.h"
#include "wild_mvs/core/point_cloud.h"
#include "wild_mvs/core/scene.h"

namespace wild_mvs {
namespace ros1 {

// --- Intrinsics -----------------------------------------------------------
// Intrinsics and image size from a CameraInfo (pose left untouched). Rejects
// zero / non-finite / negative focal lengths, a zero size, a principal point
// far outside the image, a non-zero skew, and distortion models other than
// plumb_bob / rational_polynomial (returned in *distortion with coefficients
// k1 k2 p1 p2 k3; rational_polynomial with k4..k6 != 0 is rejected).
//
// Binning and ROI. info.width/height, K and P describe the full-resolution
// sensor; the image actually delivered is the ROI (x_offset, y_offset,
// width, height; a width or height of 0 = from the offset to the sensor's
// edge, so the all-zero roi = the full sensor) of it, then binned by
// binning_x/binning_y (0 or 1 = none). So the camera returned describes the
// delivered image:
//   width  = (roi.width ? roi.width : info.width - x_offset) / bx  (floor)
//   fx'    = fx / bx
//   cx'    = (cx_core - x_offset) / bx          (core pixel centres)
//          = (K[2] + 0.5 - x_offset) / bx       (from ROS K)
// and the same in y. The formula is exact for pixel centres in the core's
// convention (a binned pixel covers bx full-resolution pixels, its left edge
// at x_offset + bx * j); in ROS terms cx_ros' = (K[2] + 0.5 - x_offset) / bx
// - 0.5, which differs from image_geometry's (K[2] - x_offset) / bx by
// (bx - 1) / (2 bx) pixels. An ROI reaching outside the sensor is rejected.
// Distortion coefficients act on normalised coordinates and are unchanged.
//
// Rectified mode (rectified = true; for image_rect topics): the camera comes
// from P instead (fx = P[0], fy = P[5], cx = P[2], cy = P[6], then the same
// ROI / binning adjustment), D is ignored and *distortion is kNone. A P with
// a non-zero translation P[3] / P[7] (a stereo right camera: -fx * baseline)
// is accepted and the translation ignored (the pose comes from tf). An
// all-zero P (an uncalibrated camera), a non-zero skew P[1], or P[10] != 1
// is rejected.
void CameraFromCameraInfo(const sensor_msgs::CameraInfo& info, Camera* camera,
                          Distortion* distortion, bool rectified = false);
// A CameraInfo for a pinhole camera (no distortion, identity R, P = [K 0]).
sensor_msgs::CameraInfo CameraInfoFromCamera(const Camera& camera);

// --- Poses ----------------------------------------------------------------
// Sets camera->R, t from the camera's pose in the world. Rejects non-finite
// values and quaternions whose norm is far from 1 (|q| not in [0.9, 1.1]);
// nearly unit quaternions are normalised.
void SetCameraPose(const geometry_msgs::Transform& world_T_camera,
                   Camera* camera);
void SetCameraPose(const geometry_msgs::Pose& world_T_camera, Camera* camera);
void SetCameraPose(const Eigen::Isometry3d& world_T_camera, Camera* camera);
// A pose or transform message as a rigid transform, checked like
// SetCameraPose (throws Error naming the problem).
Eigen::Isometry3d IsometryFromMsg(const geometry_msgs::Pose& pose);
Eigen::Isometry3d IsometryFromMsg(const geometry_msgs::Transform& transform);
// The camera's pose in the world (inverse of the core's world-to-camera).
geometry_msgs::Pose PoseFromCamera(const Camera& camera);

// --- Images ---------------------------------------------------------------
// An input image (mono8/16, rgb8/16, bgr8/16, rgba8, bgra8; 32FC1/32FC3 are
// taken as linear; Bayer bayer_rggb8, bayer_bggr8, bayer_gbrg8, bayer_grbg8
// and their 16-bit bayer_*16 variants, demosaiced bilinearly with
// cv::cvtColor) as the core's CV_32FC3 linear RGB. Rejects unknown or
// depth-like encodings (16UC1 "depth") with an Error naming the encoding,
// big-endian multi-byte data, a step shorter than a row, and data shorter
// than step * height.
cv::Mat ImageToLinearRgb(const sensor_msgs::Image& msg, bool linearize);
// A sensor_msgs/CompressedImage (JPEG / PNG) decoded with cv::imdecode
// (both: io/pixel_buffer.h over the message fields).
cv::Mat CompressedToLinearRgb(const sensor_msgs::CompressedImage& msg,
                              bool linearize);
// A view of a 32FC1 / 32FC3 image message's data (validated; copied).
cv::Mat FloatImageFromMsg(const sensor_msgs::Image& msg, int channels,
                          const std::string& what);

// An image message of a continuous or strided cv::Mat, rows packed
// (step = cols * elemSize), with the given encoding; header left empty.
sensor_msgs::Image MatToMsg(const cv::Mat& m, const std::string& encoding);

// REP 118 depth image from a core depth map (0 -> NaN).
sensor_msgs::Image DepthToMsg(const cv::Mat& depth);
// REP 118 16-bit depth image (encoding 16UC1, millimetres rounded to the
// nearest mm, 0 = unknown) from a core depth map (CV_32FC1 metres, 0 =
// unknown). Depths <= 0, non-finite, or rounding above 65535 mm (65.535 m)
// become 0.
sensor_msgs::Image DepthToMsg16(const cv::Mat& depth);
sensor_msgs::Image ConfidenceToMsg(const cv::Mat& confidence);
sensor_msgs::Image NormalsToMsg(const cv::Mat& normals);  // 0 -> NaN

// An rgb8 (sRGB) image of a linear RGB CV_32FC3 image resized to w x h.
sensor_msgs::Image ColorToMsg(const cv::Mat& linear_rgb, int w, int h);

// --- Frames ---------------------------------------------------------------
// frame_id without its leading '/' characters (all of them): tf2 rejects
// frame ids that start with '/', which ROS 1 tf allowed ("/camera").
std::string StripLeadingSlash(const std::string& frame_id);

// --- DepthView ------------------------------------------------------------
// Fills depth, confidence, normals, camera_info and camera_pose (header,
// ids and world frame are left to the caller).
void FillDepthView(const DepthMap& depth_map, const std::string& world_frame,
                   wild_mvs::DepthView* msg);
// The core depth map of a DepthView: checks encodings, equal sizes, the
// camera info against the image size, the pose, and turns NaN into 0 (and
// drops depth <= 0, non-finite normals and confidence outside [0, 1]).
DepthMap DepthMapFromDepthView(const wild_mvs::DepthView& msg);

// --- Clouds and meshes ----------------------------------------------------
// PointCloud2 with x y z (float32), rgb (packed float32, when the cloud has
// colour), normal_x/y/z (when it has normals), confidence (when it has it).
// At most max_points points, a uniform subsample (0 = all).
sensor_msgs::PointCloud2 CloudToMsg(const PointCloud& cloud,
                                    size_t max_points = 0);
// The points of one depth map in the world frame (every valid pixel).
PointCloud DepthMapToCloud(const DepthMap& depth_map, const cv::Mat& rgb);
// A TRIANGLE_LIST marker of a mesh (vertex colours when present).
visualization_msgs::Marker MeshToMarker(const Mesh& mesh);

}  // namespace ros1
}  // namespace wild_mvs
