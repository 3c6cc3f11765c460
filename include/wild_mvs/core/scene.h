// Copyright wild_mvs authors. The scene model every algorithm works on.
//
// A Scene is a set of calibrated views (pinhole camera + image reference) and
// optional sparse structure-from-motion points with their tracks. Readers in
// wild_mvs/io fill it; the streaming ROS node grows one keyframe at a time.
// Conventions: see camera.h (world-to-camera poses, pixel centres at +0.5).
#pragma once

#include <Eigen/Core>
#include <string>
#include <unordered_map>
#include <vector>

#include "wild_mvs/core/camera.h"

namespace wild_mvs {

// Lens distortion of the original image. Images are undistorted at load
// (ImageLoader) so that the algorithms only see `Camera` (pinhole). Track
// observations are undistorted by the readers. Fisheye models are rejected.
struct Distortion {
  enum class Model { kNone, kRadial, kOpenCV };
  Model model = Model::kNone;
  // OpenCV order: k1, k2, p1, p2, k3 (kRadial uses k1, k2 only).
  double k1 = 0, k2 = 0, p1 = 0, p2 = 0, k3 = 0;
  bool IsNone() const {
    return model == Model::kNone ||
           (k1 == 0 && k2 == 0 && p1 == 0 && p2 == 0 && k3 == 0);
  }
};

struct View {
  std::string name;        // unique; the image file name relative to the
                           // image folder (e.g. "0001.png" or "sub/a.jpg")
  std::string image_path;  // absolute or CWD-relative path; may be empty for
                           // in-memory views (tests, ROS keyframes)
  std::string mask_path;   // optional mask, 0 = ignore pixel
  Camera camera;           // pinhole camera of the undistorted image
  Distortion distortion;   // of the file on disk (kNone for most datasets)
  // Size of the image file when it differs from camera.width/height because
  // the camera was downscaled (--max-image-size); 0 = same as the camera.
  int file_width = 0, file_height = 0;

  // File stem used to name outputs ("sub/a.jpg" -> "sub_a").
  std::string Stem() const;
};

struct Observation {
  int view = -1;             // index into Scene::views
  Eigen::Vector2d xy{0, 0};  // undistorted pixel coordinates (camera.h)
  double scale = 0;          // feature scale in pixels (SIFT size); 0 = unknown
};

struct SparsePoint {
  Eigen::Vector3d xyz{0, 0, 0};
  Eigen::Vector3f rgb{0.5f, 0.5f, 0.5f};  // 0..1
  double error = 0;                       // mean reprojection error (px)
  std::vector<Observation> track;
};

struct Scene {
  std::vector<View> views;
  std::vector<SparsePoint> points;
  std::string source;  // where it came from ("COLMAP text model DIR/...")

  // Index of the view with this name, or -1.
  int FindView(const std::string& name) const;
  // For each view, the indices of the points it observes.
  std::vector<std::vector<int>> PointsPerView() const;
  // Throws Error naming the problem when the scene is inconsistent:
  // duplicate view names, invalid cameras, tracks pointing at missing views,
  // non-finite points.
  void Validate() const;
};

}  // namespace wild_mvs
