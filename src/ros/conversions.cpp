// Copyright wild_mvs authors.
#include "wild_mvs/ros/conversions.h"

#include <sensor_msgs/image_encodings.h>
#include <sensor_msgs/point_cloud2_iterator.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <opencv2/imgproc.hpp>

#include "wild_mvs/core/error.h"
#include "wild_mvs/core/image.h"
#include "wild_mvs/io/pixel_buffer.h"

namespace wild_mvs {
namespace ros1 {
namespace enc = sensor_msgs::image_encodings;

namespace {

constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();

bool Finite(double v) { return std::isfinite(v); }

// The pixels of an image message (not copied).
PixelBuffer BufferOf(const sensor_msgs::Image& msg) {
  PixelBuffer b;
  b.width = msg.width;
  b.height = msg.height;
  b.encoding = msg.encoding;
  b.big_endian = msg.is_bigendian != 0;
  b.step = msg.step;
  b.data = msg.data.data();
  b.size = msg.data.size();
  return b;
}

}  // namespace

sensor_msgs::Image MatToMsg(const cv::Mat& m, const std::string& encoding) {
  sensor_msgs::Image msg;
  msg.height = m.rows;
  msg.width = m.cols;
  msg.encoding = encoding;
  msg.is_bigendian = 0;
  msg.step = static_cast<uint32_t>(m.cols * m.elemSize());
  msg.data.resize(static_cast<size_t>(msg.step) * m.rows);
  for (int r = 0; r < m.rows; ++r)
    std::memcpy(&msg.data[static_cast<size_t>(r) * msg.step], m.ptr(r),
                msg.step);
  return msg;
}

void CameraFromCameraInfo(const sensor_msgs::CameraInfo& info, Camera* camera,
                          Distortion* distortion, bool rectified) {
  const auto& K = info.K;
  const auto& P = info.P;
  Require(info.width > 0 && info.height > 0, "camera_info: image size is ",
          info.width, "x", info.height);
  // Larger sizes would also overflow Camera's int width/height.
  Require(
      info.width <= kMaxBufferImageSide && info.height <= kMaxBufferImageSide,
      "camera_info: image size ", info.width, "x", info.height,
      " is too large (at most ", kMaxBufferImageSide, " per side)");
  double fx, fy, cx_ros, cy_ros;
  if (rectified) {
    for (double v : P)
      Require(Finite(v), "camera_info: P has a non-finite value");
    Require(std::any_of(P.begin(), P.end(), [](double v) { return v != 0; }),
            "camera_info: P is all zero (uncalibrated camera) in rectified "
            "mode");
    Require(P[0] > 0 && P[5] > 0,
            "camera_info: zero or negative focal length in P (fx=", P[0],
            " fy=", P[5], ")");
    Require(P[1] == 0, "camera_info: skew P[1] = ", P[1], " is not supported");
    Require(P[10] == 1, "camera_info: P[10] = ", P[10], " (expected 1)");
    // P[3], P[7] (stereo baseline) are ignored: the pose comes from tf.
    fx = P[0];
    fy = P[5];
    cx_ros = P[2];
    cy_ros = P[6];
  } else {
    for (double v : K)
      Require(Finite(v), "camera_info: K has a non-finite value");
    Require(K[0] > 0 && K[4] > 0,
            "camera_info: zero or negative focal length (fx=", K[0],
            " fy=", K[4], ")");
    Require(K[1] == 0, "camera_info: skew K[1] = ", K[1], " is not supported");
    fx = K[0];
    fy = K[4];
    cx_ros = K[2];
    cy_ros = K[5];
  }
  // ROI then binning (header). 0 means none / full sensor.
  const auto& roi = info.roi;
  const uint32_t bx = info.binning_x > 1 ? info.binning_x : 1;
  const uint32_t by = info.binning_y > 1 ? info.binning_y : 1;
  const uint64_t roi_w =
      roi.width ? roi.width : info.width - std::min(info.width, roi.x_offset);
  const uint64_t roi_h =
      roi.height ? roi.height
                 : info.height - std::min(info.height, roi.y_offset);
  Require(uint64_t(roi.x_offset) + roi_w <= info.width &&
              uint64_t(roi.y_offset) + roi_h <= info.height && roi_w > 0 &&
              roi_h > 0,
          "camera_info: roi (x_offset ", roi.x_offset, ", y_offset ",
          roi.y_offset, ", width ", roi.width, ", height ", roi.height,
          ") is not inside the ", info.width, "x", info.height, " sensor");
  Require(bx <= roi_w && by <= roi_h, "camera_info: binning ", info.binning_x,
          "x", info.binning_y, " is larger than the ", roi_w, "x", roi_h,
          " roi");
  const int width = static_cast<int>(roi_w / bx);
  const int height = static_cast<int>(roi_h / by);
  // ROS -> core pixel centres (+0.5), then ROI and binning.
  const double cx = (cx_ros + 0.5 - roi.x_offset) / bx;
  const double cy = (cy_ros + 0.5 - roi.y_offset) / by;
  Require(cx > -double(width) && cx < 2.0 * width && cy > -double(height) &&
              cy < 2.0 * height,
          "camera_info: principal point (", cx_ros, ", ", cy_ros,
          ") is far outside the ", width, "x", height, " image");
  camera->fx = fx / bx;
  camera->fy = fy / by;
  camera->cx = cx;
  camera->cy = cy;
  camera->width = width;
  camera->height = height;
  Distortion d;
  if (!rectified) {
    const auto& D = info.D;
    for (double v : D)
      Require(Finite(v), "camera_info: D has a non-finite value");
    bool any = std::any_of(D.begin(), D.end(), [](double v) { return v != 0; });
    if (any) {
      Require(info.distortion_model == "plumb_bob" ||
                  info.distortion_model == "rational_polynomial",
              "camera_info: distortion model '", info.distortion_model,
              "' is not supported (plumb_bob, rational_polynomial)");
      for (size_t i = 5; i < D.size(); ++i)
        Require(D[i] == 0, "camera_info: rational_polynomial coefficient D[", i,
                "] = ", D[i], " is not supported");
      d.model = Distortion::Model::kOpenCV;
      d.k1 = D.size() > 0 ? D[0] : 0;
      d.k2 = D.size() > 1 ? D[1] : 0;
      d.p1 = D.size() > 2 ? D[2] : 0;
      d.p2 = D.size() > 3 ? D[3] : 0;
      d.k3 = D.size() > 4 ? D[4] : 0;
    }
  }
  if (distortion) *distortion = d;
}

sensor_msgs::CameraInfo CameraInfoFromCamera(const Camera& camera) {
  sensor_msgs::CameraInfo info;
  info.width = camera.width;
  info.height = camera.height;
  info.distortion_model = "plumb_bob";
  info.D.assign(5, 0.0);
  const double cx = camera.cx - 0.5, cy = camera.cy - 0.5;  // core -> ROS
  info.K = {camera.fx, 0, cx, 0, camera.fy, cy, 0, 0, 1};
  info.R = {1, 0, 0, 0, 1, 0, 0, 0, 1};
  info.P = {camera.fx, 0, cx, 0, 0, camera.fy, cy, 0, 0, 0, 1, 0};
  return info;
}

namespace {
Eigen::Isometry3d MakeIsometry(double qx, double qy, double qz, double qw,
                               double x, double y, double z) {
  for (double v : {qx, qy, qz, qw, x, y, z})
    Require(Finite(v), "pose has a non-finite value (NaN or Inf)");
  Eigen::Quaterniond q(qw, qx, qy, qz);
  const double n = q.norm();
  Require(n > 0.9 && n < 1.1, "pose quaternion has norm ", n,
          " (not a rotation)");
  q.normalize();
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = q.toRotationMatrix();
  T.translation() = Eigen::Vector3d(x, y, z);
  return T;
}
}  // namespace

Eigen::Isometry3d IsometryFromMsg(const geometry_msgs::Transform& T) {
  return MakeIsometry(T.rotation.x, T.rotation.y, T.rotation.z, T.rotation.w,
                      T.translation.x, T.translation.y, T.translation.z);
}

Eigen::Isometry3d IsometryFromMsg(const geometry_msgs::Pose& P) {
  return MakeIsometry(P.orientation.x, P.orientation.y, P.orientation.z,
                      P.orientation.w, P.position.x, P.position.y,
                      P.position.z);
}

void SetCameraPose(const Eigen::Isometry3d& world_T_camera, Camera* camera) {
  const Eigen::Matrix3d R_wc = world_T_camera.linear();
  camera->R = R_wc.transpose();
  camera->t = -R_wc.transpose() * world_T_camera.translation();
}

void SetCameraPose(const geometry_msgs::Transform& T, Camera* camera) {
  SetCameraPose(IsometryFromMsg(T), camera);
}

void SetCameraPose(const geometry_msgs::Pose& P, Camera* camera) {
  SetCameraPose(IsometryFromMsg(P), camera);
}

geometry_msgs::Pose PoseFromCamera(const Camera& camera) {
  const Eigen::Matrix3d R_wc = camera.R.transpose();
  const Eigen::Vector3d c = camera.Center();
  Eigen::Quaterniond q(R_wc);
  q.normalize();
  geometry_msgs::Pose p;
  p.position.x = c.x();
  p.position.y = c.y();
  p.position.z = c.z();
  p.orientation.x = q.x();
  p.orientation.y = q.y();
  p.orientation.z = q.z();
  p.orientation.w = q.w();
  return p;
}

cv::Mat ImageToLinearRgb(const sensor_msgs::Image& msg, bool linearize) {
  return PixelsToLinearRgb(BufferOf(msg), linearize);
}

cv::Mat CompressedToLinearRgb(const sensor_msgs::CompressedImage& msg,
                              bool linearize) {
  return DecodeToLinearRgb(msg.data.data(), msg.data.size(), msg.format,
                           linearize);
}

cv::Mat FloatImageFromMsg(const sensor_msgs::Image& msg, int channels,
                          const std::string& what) {
  const std::string want = channels == 1 ? enc::TYPE_32FC1 : enc::TYPE_32FC3;
  Require(msg.encoding == want, what, ": encoding '", msg.encoding,
          "', expected '", want, "'");
  return WrapPixels(BufferOf(msg), CV_MAKETYPE(CV_32F, channels), what).clone();
}

sensor_msgs::Image DepthToMsg(const cv::Mat& depth) {
  Require(depth.type() == CV_32FC1, "DepthToMsg: depth must be CV_32FC1");
  cv::Mat d = depth.clone();
  d.forEach<float>([](float& v, const int*) {
    if (!(v > 0) || !std::isfinite(v)) v = kNaN;
  });
  return MatToMsg(d, enc::TYPE_32FC1);
}

sensor_msgs::Image DepthToMsg16(const cv::Mat& depth) {
  Require(depth.type() == CV_32FC1, "DepthToMsg16: depth must be CV_32FC1");
  cv::Mat mm(depth.size(), CV_16UC1);
  for (int r = 0; r < depth.rows; ++r) {
    const float* src = depth.ptr<float>(r);
    uint16_t* dst = mm.ptr<uint16_t>(r);
    for (int c = 0; c < depth.cols; ++c) {
      const float v = src[c];
      const double m =
          std::isfinite(v) && v > 0 ? std::round(double(v) * 1000) : 0.0;
      dst[c] = m > 0 && m <= 65535 ? static_cast<uint16_t>(m) : 0;
    }
  }
  return MatToMsg(mm, enc::TYPE_16UC1);
}

std::string StripLeadingSlash(const std::string& frame_id) {
  const size_t i = frame_id.find_first_not_of('/');
  return i == std::string::npos ? std::string() : frame_id.substr(i);
}

sensor_msgs::Image ConfidenceToMsg(const cv::Mat& confidence) {
  Require(confidence.type() == CV_32FC1,
          "ConfidenceToMsg: confidence must be CV_32FC1");
  return MatToMsg(confidence, enc::TYPE_32FC1);
}

sensor_msgs::Image NormalsToMsg(const cv::Mat& normals) {
  Require(normals.type() == CV_32FC3, "NormalsToMsg: normals must be CV_32FC3");
  cv::Mat n = normals.clone();
  n.forEach<cv::Vec3f>([](cv::Vec3f& v, const int*) {
    if (v[0] == 0 && v[1] == 0 && v[2] == 0) v = cv::Vec3f(kNaN, kNaN, kNaN);
  });
  return MatToMsg(n, enc::TYPE_32FC3);
}

sensor_msgs::Image ColorToMsg(const cv::Mat& linear_rgb, int w, int h) {
  Require(linear_rgb.type() == CV_32FC3, "ColorToMsg: image must be CV_32FC3");
  cv::Mat small;
  if (linear_rgb.cols == w && linear_rgb.rows == h) {
    small = linear_rgb;
  } else {
    cv::resize(linear_rgb, small, cv::Size(w, h), 0, 0, cv::INTER_AREA);
  }
  cv::Mat out(h, w, CV_8UC3);
  for (int r = 0; r < h; ++r) {
    const cv::Vec3f* s = small.ptr<cv::Vec3f>(r);
    cv::Vec3b* d = out.ptr<cv::Vec3b>(r);
    for (int c = 0; c < w; ++c)
      for (int k = 0; k < 3; ++k)
        d[c][k] = cv::saturate_cast<uint8_t>(
            LinearToSrgb(std::clamp(s[c][k], 0.0f, 1.0f)) * 255.0f + 0.5f);
  }
  return MatToMsg(out, enc::RGB8);
}

void FillDepthView(const DepthMap& dm, const std::string& world_frame,
                   wild_mvs::DepthView* msg) {
  Require(!dm.empty(), "FillDepthView: empty depth map");
  msg->depth = DepthToMsg(dm.depth);
  msg->confidence =
      dm.confidence.empty()
          ? ConfidenceToMsg(cv::Mat(dm.depth.size(), CV_32FC1, cv::Scalar(0)))
          : ConfidenceToMsg(dm.confidence);
  msg->normals =
      dm.normal.empty()
          ? NormalsToMsg(cv::Mat(dm.depth.size(), CV_32FC3, cv::Scalar::all(0)))
          : NormalsToMsg(dm.normal);
  msg->camera_info = CameraInfoFromCamera(dm.camera);
  msg->camera_info.header = msg->header;
  msg->depth.header = msg->confidence.header = msg->normals.header =
      msg->header;
  msg->camera_pose.header.stamp = msg->header.stamp;
  msg->camera_pose.header.frame_id = world_frame;
  msg->camera_pose.pose = PoseFromCamera(dm.camera);
}

DepthMap DepthMapFromDepthView(const wild_mvs::DepthView& msg) {
  DepthMap dm;
  dm.view = static_cast<int>(msg.keyframe_id);
  CameraFromCameraInfo(msg.camera_info, &dm.camera, nullptr);
  SetCameraPose(msg.camera_pose.pose, &dm.camera);
  dm.depth = FloatImageFromMsg(msg.depth, 1, "depth_view.depth");
  Require(dm.depth.cols == dm.camera.width && dm.depth.rows == dm.camera.height,
          "depth_view: depth is ", dm.depth.cols, "x", dm.depth.rows,
          " but camera_info is ", dm.camera.width, "x", dm.camera.height);
  dm.confidence = FloatImageFromMsg(msg.confidence, 1, "depth_view.confidence");
  dm.normal = FloatImageFromMsg(msg.normals, 3, "depth_view.normals");
  Require(dm.confidence.size() == dm.depth.size() &&
              dm.normal.size() == dm.depth.size(),
          "depth_view: depth, confidence and normals differ in size");
  for (int r = 0; r < dm.depth.rows; ++r) {
    float* d = dm.depth.ptr<float>(r);
    float* c = dm.confidence.ptr<float>(r);
    cv::Vec3f* n = dm.normal.ptr<cv::Vec3f>(r);
    for (int x = 0; x < dm.depth.cols; ++x) {
      const bool normal_ok = std::isfinite(n[x][0]) && std::isfinite(n[x][1]) &&
                             std::isfinite(n[x][2]);
      if (!(d[x] > 0) || !std::isfinite(d[x]) || !std::isfinite(c[x]) ||
          c[x] < 0 || c[x] > 1 || !normal_ok) {
        d[x] = 0;
        c[x] = 0;
        n[x] = cv::Vec3f(0, 0, 0);
      }
    }
  }
  for (uint32_t id : msg.neighbor_ids) dm.neighbors.push_back(int(id));
  return dm;
}

sensor_msgs::PointCloud2 CloudToMsg(const PointCloud& cloud,
                                    size_t max_points) {
  const size_t n = cloud.size();
  const size_t stride = (max_points > 0 && n > max_points)
                            ? (n + max_points - 1) / max_points
                            : 1;
  const size_t m = (n + stride - 1) / stride;
  sensor_msgs::PointCloud2 msg;
  sensor_msgs::PointCloud2Modifier mod(msg);
  using PF = sensor_msgs::PointField;
  std::vector<std::pair<std::string, int>> fields = {
      {"x", PF::FLOAT32}, {"y", PF::FLOAT32}, {"z", PF::FLOAT32}};
  // Always an "rgb" field (grey when the cloud has no colour): rviz picks
  // its colour transformer from the first cloud it sees and keeps a
  // fallback (flat white) when that one had no rgb, e.g. an empty cloud.
  fields.push_back({"rgb", PF::FLOAT32});
  if (cloud.has_normal()) {
    fields.push_back({"normal_x", PF::FLOAT32});
    fields.push_back({"normal_y", PF::FLOAT32});
    fields.push_back({"normal_z", PF::FLOAT32});
  }
  if (cloud.has_confidence()) fields.push_back({"confidence", PF::FLOAT32});
  msg.fields.clear();
  uint32_t offset = 0;
  for (const auto& [name, type] : fields) {
    PF f;
    f.name = name;
    f.offset = offset;
    f.datatype = type;
    f.count = 1;
    msg.fields.push_back(f);
    offset += 4;
  }
  msg.point_step = offset;
  msg.height = 1;
  msg.width = static_cast<uint32_t>(m);
  msg.row_step = msg.point_step * msg.width;
  msg.is_bigendian = false;
  msg.is_dense = true;
  msg.data.resize(static_cast<size_t>(msg.row_step));
  uint8_t* out = msg.data.data();
  for (size_t i = 0; i < n; i += stride) {
    float* f = reinterpret_cast<float*>(out);
    int k = 0;
    f[k++] = cloud.xyz[i].x();
    f[k++] = cloud.xyz[i].y();
    f[k++] = cloud.xyz[i].z();
    {
      auto c8 = [](float v) {
        return static_cast<uint32_t>(std::clamp(v, 0.0f, 1.0f) * 255.0f + 0.5f);
      };
      const Eigen::Vector3f c =
          cloud.has_rgb() ? cloud.rgb[i] : Eigen::Vector3f::Constant(0.5f);
      const uint32_t rgb = (c8(c.x()) << 16) | (c8(c.y()) << 8) | c8(c.z());
      std::memcpy(&f[k++], &rgb, 4);
    }
    if (cloud.has_normal()) {
      f[k++] = cloud.normal[i].x();
      f[k++] = cloud.normal[i].y();
      f[k++] = cloud.normal[i].z();
    }
    if (cloud.has_confidence()) f[k++] = cloud.confidence[i];
    out += msg.point_step;
  }
  return msg;
}

PointCloud DepthMapToCloud(const DepthMap& dm, const cv::Mat& rgb) {
  PointCloud cloud;
  const bool colour = !rgb.empty() && rgb.type() == CV_32FC3;
  for (int r = 0; r < dm.depth.rows; ++r) {
    for (int c = 0; c < dm.depth.cols; ++c) {
      const float z = dm.depth.at<float>(r, c);
      if (!(z > 0) || !std::isfinite(z)) continue;
      const Eigen::Vector2d px(c + 0.5, r + 0.5);
      cloud.xyz.push_back(dm.camera.Backproject(px, z).cast<float>());
      if (!dm.normal.empty()) {
        const cv::Vec3f n = dm.normal.at<cv::Vec3f>(r, c);
        cloud.normal.push_back(
            (dm.camera.R.transpose() * Eigen::Vector3d(n[0], n[1], n[2]))
                .cast<float>());
      }
      if (!dm.confidence.empty())
        cloud.confidence.push_back(dm.confidence.at<float>(r, c));
      if (colour) {
        // Depth maps may be smaller than the image: sample proportionally.
        const int ir = std::min(rgb.rows - 1, r * rgb.rows / dm.depth.rows);
        const int ic = std::min(rgb.cols - 1, c * rgb.cols / dm.depth.cols);
        const cv::Vec3f p = rgb.at<cv::Vec3f>(ir, ic);
        cloud.rgb.emplace_back(LinearToSrgb(std::clamp(p[0], 0.f, 1.f)),
                               LinearToSrgb(std::clamp(p[1], 0.f, 1.f)),
                               LinearToSrgb(std::clamp(p[2], 0.f, 1.f)));
      }
    }
  }
  return cloud;
}

visualization_msgs::Marker MeshToMarker(const Mesh& mesh) {
  visualization_msgs::Marker m;
  m.type = visualization_msgs::Marker::TRIANGLE_LIST;
  m.action = visualization_msgs::Marker::ADD;
  m.pose.orientation.w = 1.0;
  m.scale.x = m.scale.y = m.scale.z = 1.0;
  m.color.r = m.color.g = m.color.b = 0.8f;
  m.color.a = 1.0f;
  const auto& V = mesh.vertices;
  const bool colour = V.has_rgb();
  m.points.reserve(mesh.faces.size() * 3);
  if (colour) m.colors.reserve(mesh.faces.size() * 3);
  for (const Eigen::Vector3i& f : mesh.faces) {
    bool ok = true;
    for (int k = 0; k < 3; ++k)
      ok = ok && f[k] >= 0 && static_cast<size_t>(f[k]) < V.size();
    if (!ok) continue;
    for (int k = 0; k < 3; ++k) {
      geometry_msgs::Point p;
      p.x = V.xyz[f[k]].x();
      p.y = V.xyz[f[k]].y();
      p.z = V.xyz[f[k]].z();
      m.points.push_back(p);
      if (colour) {
        std_msgs::ColorRGBA c;
        c.r = V.rgb[f[k]].x();
        c.g = V.rgb[f[k]].y();
        c.b = V.rgb[f[k]].z();
        c.a = 1.0f;
        m.colors.push_back(c);
      }
    }
  }
  return m;
}

}  // namespace ros1
}  // namespace wild_mvs
