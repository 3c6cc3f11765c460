// Copyright wild_mvs authors. A small ray-casting renderer for tests.
//
// Builds scenes with exact ground truth: textured planes, slanted planes,
// boxes, spheres, cylinders and relief (displaced) rectangles, cameras
// around them, per-view exposure, white balance, gamma, sun, ambient and
// overcast changes, and occluders that appear in one view only. Every
// algorithm test builds on it.
#pragma once

#include <Eigen/Core>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "wild_mvs/core/image.h"
#include "wild_mvs/core/point_cloud.h"
#include "wild_mvs/core/scene.h"

namespace wild_mvs {
namespace testing {

struct SyntheticObject {
  enum class Type { kPlane, kBox, kSphere, kCylinder, kRelief };
  Type type = Type::kPlane;
  // kPlane: a rectangle centred at `center` spanned by the unit vectors
  //   axis_u, axis_v with half extents size.x(), size.y().
  // kBox: axis-aligned box centred at `center` (rotated by `rotation`),
  //   half extents size.
  // kSphere: centre `center`, radius size.x().
  // kCylinder: vertical axis (world z) through `center`, radius size.x(),
  //   half height size.z(); closed by two discs when `capped`.
  // kRelief: the rectangle of kPlane displaced along its normal
  //   n = axis_u x axis_v by a smooth height field h(u, v) (u, v the
  //   coordinates along axis_u, axis_v from `center`): a sum of six plane
  //   waves with wavelengths 0.6 .. 1.7 relief_scale, directions and phases
  //   from relief_seed, |h| <= relief_amplitude. Rays are intersected by
  //   Lipschitz-bounded marching and bisection to 1e-12 relative depth, the
  //   normal is that of the analytic gradient, so ground-truth depth and
  //   normals are those of the rendered surface.
  Eigen::Vector3d center{0, 0, 0};
  Eigen::Vector3d size{1, 1, 1};
  Eigen::Vector3d axis_u{1, 0, 0}, axis_v{0, 1, 0};
  Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();
  // Procedural texture (multi-scale value noise, colour) with this seed and
  // feature size in world units; texture is fixed to the surface.
  int texture_seed = 1;
  double texture_scale = 0.05;
  // -1: visible in every view. Otherwise the object exists only when
  // rendering view `only_in_view` (a transient occluder: a person, a car);
  // the ground-truth depth of that view includes it, of other views not.
  int only_in_view = -1;
  bool capped = true;             // kCylinder
  double relief_amplitude = 0.0;  // kRelief: max |h| in world units
  double relief_scale = 0.5;      // kRelief: feature size in world units
  int relief_seed = 1;            // kRelief
  // Albedo variation amplitude: 1 = the full texture; k scales the
  // luminance and tint deviations from their mid values by k (0 = a
  // uniform colour).
  double texture_contrast = 1.0;
};

// Photometric change applied to one view's rendered linear radiance L
// (L = mean over the supersample^2 sub-pixel rays; radiance is view
// independent and lies in about [0.02, 0.4]; background = 0). Per channel c:
//   v = clamp(exposure * white_balance[c] * L, 0, 1) ^ (1 / gamma)
//   v = clamp(v + N(0, noise_sigma), 0, 1)
//   if quantize: v = SrgbToLinear(round(LinearToSrgb(v) * 255) / 255)
// i.e. 8-bit quantisation happens in the sRGB encoding, as a camera's PNG or
// JPEG stores it, so `images` equal exactly what LoadViewImage returns for
// the 8-bit sRGB PNGs WriteDataset writes. gamma = 1 keeps it linear.
//
// Two more changes, off by default:
//  - vignetting k: L *= 1 - k * (r / r_corner)^2 before the response, r the
//    distance of the sub-sample from the image centre;
//  - sun (world direction towards a directional light; zero = none): the
//    radiance of a point becomes 0.4 * albedo * (0.35 + 0.65 * max(0, n . l)
//    * lit) with lit = 0 where another object casts a shadow (the shading
//    and the shadows then differ between views lit from different sides,
//    like photos taken at other times of day). `ambient` is the 0.35 of
//    that formula: radiance 0.4 * albedo * (ambient + (1 - ambient) * max(0,
//    n . l) * lit);
//  - overcast (no direct sun, only sky light; `sun` is ignored): radiance
//    0.4 * albedo * (ambient + (1 - ambient) * (1 + n_z) / 2) with n the
//    normal facing the camera and n_z its world up component (light from
//    the upper hemisphere, no shadows), and a grey sky.
// `ambient` matters only with a sun or overcast.
struct ViewLighting {
  double exposure = 1.0;
  Eigen::Vector3d white_balance{1, 1, 1};
  double gamma = 1.0;
  double vignetting = 0.0;
  Eigen::Vector3d sun{0, 0, 0};
  double ambient = 0.35;  // in [0, 1]
  bool overcast = false;
};

struct SyntheticSpec {
  std::vector<SyntheticObject> objects;
  int width = 320, height = 240;
  double focal = 300;  // pixels; principal point at the image centre
  // Per-view focal lengths (empty = `focal` for all).
  std::vector<double> focals;
  // A sky: rays that hit nothing see radiance 0.25 + 0.1 * elevation in a
  // blue tint, passed through each view's lighting (ground-truth depth 0
  // there). false = black background.
  bool sky = false;
  // Camera centres; every camera looks at `look_at`, its image x axis
  // horizontal (world z is up). See MakeRingCameras.
  std::vector<Eigen::Vector3d> camera_centers;
  Eigen::Vector3d look_at{0, 0, 0};
  // Per-view targets (empty = `look_at` for all).
  std::vector<Eigen::Vector3d> look_ats;
  std::vector<ViewLighting> lighting;  // per view; empty = all defaults
  double noise_sigma = 0.0;            // Gaussian image noise (linear units)
  bool quantize = true;                // 8-bit quantisation like a camera
  int supersample = 2;                 // anti-aliasing samples per axis
  // Sparse points: sample this many surface points visible in >= 2 views,
  // with exact projections as observations (feature scale = 2 px) and this
  // much pixel noise on the observations.
  int num_sparse_points = 300;
  double sparse_pixel_noise = 0.0;
  unsigned seed = 7;
};

struct SyntheticScene {
  Scene scene;                   // cameras, view names "view_000.png"...,
                                 // no image paths; sparse points + tracks
  std::vector<cv::Mat> images;   // CV_32FC3 linear RGB (as ImageCache gives)
  std::vector<cv::Mat> depth;    // CV_32F exact z; 0 where nothing is hit
  std::vector<cv::Mat> normals;  // CV_32FC3 camera frame, facing the camera
  double scene_size = 1.0;       // diagonal of the bounding box of the
                                 // objects (excluding one-view occluders)
  // Additions to the fixed API: the spec the scene was rendered from, and
  // per view the index (into spec.objects) of the object seen at each pixel
  // centre (CV_32S, -1 = background).
  SyntheticSpec spec;
  std::vector<cv::Mat> object_id;

  // A loader for ImageCache serving `images`.
  ImageCache::Loader Loader() const;
  // Points sampled on the visible surfaces (union over views of the
  // ground-truth depth maps, one point per `stride` pixels) with world-frame
  // normals and sRGB colours; one-view occluders are excluded.
  PointCloud GroundTruthCloud(int stride = 2) const;
};

SyntheticScene Render(const SyntheticSpec& spec);

// The height field h(u, v) of a kRelief object (see SyntheticObject) and,
// when `grad` is set, its gradient (dh/du, dh/dv): the analytic surface the
// renderer intersects.
double ReliefHeight(const SyntheticObject& relief, double u, double v,
                    Eigen::Vector2d* grad = nullptr);

// `n` cameras on a circle of `radius` at `height` around the origin, looking
// at the origin (an object ring like Middlebury's).
std::vector<Eigen::Vector3d> MakeRingCameras(int n, double radius,
                                             double height,
                                             double arc_deg = 360);
// Presets used by many tests.
// A textured plane at depth ~2 slanted by `slant_deg` about the vertical
// axis, seen by `n` cameras on a short arc in front of it.
SyntheticSpec SlantedPlaneSpec(double slant_deg = 30, int n = 5);
// Boxes and a sphere on a ground plane (4.4 x 4.4), 8 ring cameras at radius
// 2.6, height 1.5 looking at (0, 0, 0.15), with per-view exposure (0.4 ..
// 2.5) / white-balance (+-30 %) / gamma (1 .. 2.2) changes when
// `vary_lighting`, and a textured box occluder present in view 0 only when
// `occluder`. With the default full ring (arc_deg = 360) neighbouring views
// are 45 degrees apart: wide baselines (unwarped 5x5 windows do not match on
// the slanted ground). arc_deg < 360 puts the 8 cameras on an arc of that
// many degrees instead (e.g. 105: 15 degrees apart) for stereo tests.
SyntheticSpec ClutteredSceneSpec(bool vary_lighting, bool occluder,
                                 double arc_deg = 360);

// Writes the scene as a dataset folder that the CLI reads: COLMAP text model
// in DIR/sparse/ (cameras.txt, images.txt, points3D.txt), 8-bit sRGB PNG
// images in DIR/images/, ground-truth depth as PFM in DIR/gt_depth/<stem>.pfm.
void WriteDataset(const SyntheticScene& s, const std::string& dir);

}  // namespace testing
}  // namespace wild_mvs
