// Copyright wild_mvs authors.
#include "wild_mvs/io/image_files.h"

#include <filesystem>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "wild_mvs/core/error.h"

namespace wild_mvs {

namespace fs = std::filesystem;

cv::Mat LoadViewImage(const View& view, const ImageOptions& options) {
  Require(!view.image_path.empty(), "image '", view.name,
          "': no image file is known for this view");
  cv::Mat raw = cv::imread(
      view.image_path, cv::IMREAD_UNCHANGED | cv::IMREAD_IGNORE_ORIENTATION);
  Require(!raw.empty(), view.image_path,
          ": cannot read image (missing, truncated or not an image)");
  const Camera& cam = view.camera;
  const int fw = view.file_width > 0 ? view.file_width : cam.width;
  const int fh = view.file_height > 0 ? view.file_height : cam.height;
  Require(raw.cols == fw && raw.rows == fh, view.image_path, ": image is ",
          raw.cols, "x", raw.rows, " but its camera says ", fw, "x", fh);
  if (!view.distortion.IsNone()) {
    // Distortion parameters refer to the file's resolution.
    const Camera fc = cam.Resized(fw, fh);
    // OpenCV puts the top-left pixel centre at (0, 0): shift by 0.5.
    cv::Mat K = (cv::Mat_<double>(3, 3) << fc.fx, 0, fc.cx - 0.5, 0, fc.fy,
                 fc.cy - 0.5, 0, 0, 1);
    const Distortion& d = view.distortion;
    cv::Mat dist = (cv::Mat_<double>(1, 5) << d.k1, d.k2, d.p1, d.p2, d.k3);
    cv::Mat und;
    cv::undistort(raw, und, K, dist, K);
    raw = und;
  }
  if (raw.cols != cam.width || raw.rows != cam.height) {
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
