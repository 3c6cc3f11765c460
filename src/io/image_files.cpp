// Copyright wild_mvs authors.
#include "wild_mvs/io/image_files.h"

#include <filesystem>
#include <fstream>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "wild_mvs/core/error.h"

namespace wild_mvs {

namespace fs = std::filesystem;

int JpegReductionFactor(int file_width, int file_height, int width,
                        int height) {
  // The decoded image keeps at least twice the camera's size, so that an
  // area-averaging step of 2x or more follows libjpeg's DCT scaling: a pure
  // 1/2 DCT decode to the working size (strecha_fountain-P11, 3072 px at
  // 1536) lost 1 point of completeness against the ground truth.
  for (int f : {8, 4, 2}) {
    if (file_width >= 2 * f * width && file_height >= 2 * f * height) return f;
  }
  return 1;
}

namespace {

// True when the file starts with a JPEG SOI marker (FF D8 FF).
bool IsJpegFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  unsigned char b[3] = {0, 0, 0};
  in.read(reinterpret_cast<char*>(b), 3);
  return in && b[0] == 0xFF && b[1] == 0xD8 && b[2] == 0xFF;
}

int ReducedColorFlag(int factor) {
  switch (factor) {
    case 2:
      return cv::IMREAD_REDUCED_COLOR_2;
    case 4:
      return cv::IMREAD_REDUCED_COLOR_4;
    default:
      return cv::IMREAD_REDUCED_COLOR_8;
  }
}

}  // namespace

cv::Mat ReadViewImageFile(const View& view, int* factor) {
  Require(!view.image_path.empty(), "image '", view.name,
          "': no image file is known for this view");
  const Camera& cam = view.camera;
  const int fw = view.file_width > 0 ? view.file_width : cam.width;
  const int fh = view.file_height > 0 ? view.file_height : cam.height;
  int f = JpegReductionFactor(fw, fh, cam.width, cam.height);
  cv::Mat raw;
  if (f > 1 && IsJpegFile(view.image_path)) {
    // libjpeg decodes at 1/f directly (the DCT scaled: a fraction of the
    // time and memory); its output is ceil(size / f).
    raw = cv::imread(view.image_path,
                     ReducedColorFlag(f) | cv::IMREAD_IGNORE_ORIENTATION);
    if (!raw.empty() &&
        (raw.cols != (fw + f - 1) / f || raw.rows != (fh + f - 1) / f)) {
      raw.release();  // another size (not the file the camera says): full
    }
  }
  if (raw.empty()) {
    f = 1;
    raw = cv::imread(view.image_path,
                     cv::IMREAD_UNCHANGED | cv::IMREAD_IGNORE_ORIENTATION);
    Require(!raw.empty(), view.image_path,
            ": cannot read image (missing, truncated or not an image)");
    Require(raw.cols == fw && raw.rows == fh, view.image_path, ": image is ",
            raw.cols, "x", raw.rows, " but its camera says ", fw, "x", fh);
  }
  if (factor) *factor = f;
  return raw;
}

cv::Mat LoadViewImage(const View& view, const ImageOptions& options) {
  int f = 1;
  cv::Mat raw = ReadViewImageFile(view, &f);
  const Camera& cam = view.camera;
  const int fw = view.file_width > 0 ? view.file_width : cam.width;
  const int fh = view.file_height > 0 ? view.file_height : cam.height;
  if (!view.distortion.IsNone()) {
    // Distortion parameters refer to the file's resolution; a reduced
    // decode is the file scaled by 1/f about the image corner.
    const Camera fc = cam.Resized(fw, fh);
    const double s = 1.0 / f;
    // OpenCV puts the top-left pixel centre at (0, 0): shift by 0.5.
    cv::Mat K = (cv::Mat_<double>(3, 3) << fc.fx * s, 0, fc.cx * s - 0.5, 0,
                 fc.fy * s, fc.cy * s - 0.5, 0, 0, 1);
    const Distortion& d = view.distortion;
    cv::Mat dist = (cv::Mat_<double>(1, 5) << d.k1, d.k2, d.p1, d.p2, d.k3);
    cv::Mat und;
    cv::undistort(raw, und, K, dist, K);
    raw = und;
  }
  if (f > 1) {
    // The camera is the file's scaled by cam.width / fw (about the corner,
    // pixel-centre convention): from the reduced image that is f times as
    // much. Its size ceil(fw / f) may exceed fw / f, so resize by the exact
    // factors and crop the (partial) last column / row away.
    const double sx = static_cast<double>(cam.width) * f / fw;
    const double sy = static_cast<double>(cam.height) * f / fh;
    cv::Mat scaled;
    cv::resize(raw, scaled, cv::Size(), sx, sy, cv::INTER_AREA);
    Require(scaled.cols >= cam.width && scaled.rows >= cam.height,
            view.image_path, ": reduced decode gave ", scaled.cols, "x",
            scaled.rows, " < ", cam.width, "x", cam.height);
    raw = scaled(cv::Rect(0, 0, cam.width, cam.height)).clone();
  } else if (raw.cols != cam.width || raw.rows != cam.height) {
    cv::Mat small;
    cv::resize(raw, small, cv::Size(cam.width, cam.height), 0, 0,
               cv::INTER_AREA);
    raw = small;
  }
  return ToLinearRgb(raw, options.linearize);
}

ImageCache::Loader MakeSceneLoader(const Scene& scene,
                                   const ImageOptions& options) {
  const Scene* s = &scene;
  return [s, options](int view) {
    Require(view >= 0 && view < static_cast<int>(s->views.size()),
            "image cache: no view ", view);
    return LoadViewImage(s->views[view], options);
  };
}

int AssignMasks(Scene* scene, const std::string& dir) {
  std::error_code ec;
  Require(fs::is_directory(dir, ec), dir, ": mask folder does not exist");
  int found = 0;
  for (View& v : scene->views) {
    const std::string candidates[] = {dir + "/" + v.name + ".png",
                                      dir + "/" + v.Stem() + ".png",
                                      dir + "/" + v.name};
    for (const std::string& c : candidates) {
      if (fs::is_regular_file(c, ec)) {
        v.mask_path = c;
        ++found;
        break;
      }
    }
  }
  Require(
      found > 0, dir,
      ": no mask found for any view (expected "
      "<image name>.png or <image stem>.png, e.g. ",
      scene->views.empty() ? std::string("?") : scene->views[0].Stem() + ".png",
      ")");
  return found;
}

cv::Mat LoadViewMask(const View& v) {
  if (v.mask_path.empty()) return cv::Mat();
  cv::Mat m = cv::imread(v.mask_path, cv::IMREAD_GRAYSCALE);
  Require(!m.empty(), v.mask_path, ": cannot read mask image");
  const int fw = v.file_width > 0 ? v.file_width : v.camera.width;
  const int fh = v.file_height > 0 ? v.file_height : v.camera.height;
  const bool camera_size =
      m.cols == v.camera.width && m.rows == v.camera.height;
  Require(camera_size || (m.cols == fw && m.rows == fh), v.mask_path,
          ": mask is ", m.cols, "x", m.rows, " but image '", v.name, "' is ",
          fw, "x", fh);
  if (!camera_size) {
    cv::Mat small;
    cv::resize(m, small, cv::Size(v.camera.width, v.camera.height), 0, 0,
               cv::INTER_NEAREST);
    m = small;
  }
  return m;
}

}  // namespace wild_mvs
