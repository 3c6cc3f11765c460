// Copyright wild_mvs authors. wild_mvs_to_bag DATASET OUT.bag [--rate HZ]
// [--with-points]: a dataset folder (any format LoadDataset reads) as a bag
// of /camera/image_raw, /camera/camera_info, /tf and optionally
// /sparse_points (see wild_mvs/ros/scene_bag.h). `wild_mvs to-bag` runs it.
#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <opencv2/imgproc.hpp>
#include <string>
#include <vector>

#include "wild_mvs/core/error.h"
#include "wild_mvs/core/image.h"
#include "wild_mvs/ros/scene_bag.h"
#if __has_include("wild_mvs/io/dataset.h")
#include "wild_mvs/io/dataset.h"
#define WILD_MVS_HAVE_DATASET 1
#else
#include "wild_mvs/io/colmap.h"
#endif

namespace {

const char* kUsage =
    "usage: wild_mvs to-bag DATASET OUT.bag [--rate HZ] [--with-points]\n"
    "                       [--world-frame NAME] [--camera-frame NAME]\n"
    "                       [--max-image-size PX] [--compressed png|jpeg]\n"
    "                       [--with-pose] [--frames-per-view N]\n"
    "                       [--frame-rate HZ] [--body-frame NAME]\n"
    "                       [--start-time SEC]\n"
    "(the same as wild_mvs_to_bag DATASET OUT.bag ...)\n"
    "Writes the dataset's views as /camera/image_raw (rgb8),\n"
    "/camera/camera_info and /tf (world -> camera optical frame) at HZ\n"
    "frames per second (default 5), plus /sparse_points "
    "(wild_mvs/SparsePoints)\n"
    "with --with-points. --max-image-size shrinks the views (longest side,\n"
    "cameras and points scaled), --compressed writes\n"
    "/camera/image_raw/compressed (sensor_msgs/CompressedImage) instead of\n"
    "the raw images, --with-pose also writes /camera/pose\n"
    "(geometry_msgs/PoseStamped, the same pose as /tf).\n"
    "As a robot records: --frames-per-view N frames of each view, "
    "--frame-rate\n"
    "HZ apart (default 30; same image and pose, distinct stamps), "
    "--body-frame\n"
    "NAME puts /tf world -> NAME at 100 Hz and a latched /tf_static NAME ->\n"
    "camera optical frame instead of /tf world -> camera, --start-time SEC\n"
    "the first stamp (default 1000; e.g. an epoch time).\n";

wild_mvs::Scene Load(const std::string& dir) {
#ifdef WILD_MVS_HAVE_DATASET
  wild_mvs::DatasetOptions o;
  o.path = dir;
  return wild_mvs::LoadDataset(o);
#else
  return wild_mvs::ReadColmapModel(dir + "/sparse", dir + "/images");
#endif
}

double ParseDouble(const std::string& opt, const char* s) {
  char* end = nullptr;
  const double v = std::strtod(s, &end);
  wild_mvs::Require(end != s && *end == '\0', opt, ": '", s,
                    "' is not a number");
  return v;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    std::string dataset, out;
    wild_mvs::ros1::SceneBagOptions options;
    int max_image_size = 0;
    for (int i = 1; i < argc; ++i) {
      const std::string a = argv[i];
      auto value = [&]() -> const char* {
        wild_mvs::Require(i + 1 < argc, a, " needs a value");
        return argv[++i];
      };
      if (a == "-h" || a == "--help") {
        std::fputs(kUsage, stdout);
        return 0;
      } else if (a == "--rate") {
        options.rate = ParseDouble(a, value());
      } else if (a == "--with-points") {
        options.with_points = true;
      } else if (a == "--max-image-size") {
        max_image_size = static_cast<int>(ParseDouble(a, value()));
        wild_mvs::Require(max_image_size >= 16, "--max-image-size ",
                          max_image_size, " must be >= 16");
      } else if (a == "--compressed") {
        options.compression = value();
      } else if (a == "--with-pose") {
        options.with_pose = true;
      } else if (a == "--frames-per-view") {
        options.frames_per_view = static_cast<int>(ParseDouble(a, value()));
      } else if (a == "--frame-rate") {
        options.frame_rate = ParseDouble(a, value());
      } else if (a == "--body-frame") {
        options.body_frame = value();
        wild_mvs::Require(!options.body_frame.empty(), a, " needs a name");
      } else if (a == "--start-time") {
        options.start_time = ParseDouble(a, value());
      } else if (a == "--world-frame") {
        options.world_frame = value();
      } else if (a == "--camera-frame") {
        options.camera_frame = value();
      } else if (!a.empty() && a[0] == '-') {
        throw wild_mvs::Error("unknown option '" + a + "'");
      } else if (dataset.empty()) {
        dataset = a;
      } else if (out.empty()) {
        out = a;
      } else {
        throw wild_mvs::Error("unexpected argument '" + a + "'");
      }
    }
    if (dataset.empty() || out.empty()) {
      std::fputs(kUsage, stderr);
      return 2;
    }
    options.Check();
    wild_mvs::Scene scene = Load(dataset);
    // Shrunk views: camera, image and observations scaled alike.
    std::vector<cv::Size> full(scene.views.size());
    std::vector<double> scale(scene.views.size(), 1.0);
    for (size_t i = 0; i < scene.views.size(); ++i) {
      wild_mvs::Camera& c = scene.views[i].camera;
      full[i] = cv::Size(c.width, c.height);
      const int longest = std::max(c.width, c.height);
      if (max_image_size > 0 && longest > max_image_size) {
        wild_mvs::View& v = scene.views[i];
        if (v.file_width == 0) {  // the image file keeps its size
          v.file_width = c.width;
          v.file_height = c.height;
        }
        c = c.Scaled(double(max_image_size) / longest);
        scale[i] = double(c.width) / full[i].width;
      }
    }
    for (wild_mvs::SparsePoint& p : scene.points)
      for (wild_mvs::Observation& o : p.track)
        if (o.view >= 0 && o.view < static_cast<int>(scale.size()))
          o.xy *= scale[o.view];
    wild_mvs::ImageOptions io;
    io.linearize = false;  // keep the camera's sRGB values
    wild_mvs::ros1::WriteSceneBag(
        scene,
        [&](int i) {
          const cv::Mat rgb = wild_mvs::LoadViewImage(scene.views[i], io);
          // LoadViewImage gives [0, 1] floats in the file's encoding.
          cv::Mat out8;
          rgb.convertTo(out8, CV_8UC3, 255.0);
          const wild_mvs::Camera& c = scene.views[i].camera;
          if (out8.cols != c.width || out8.rows != c.height)
            cv::resize(out8, out8, cv::Size(c.width, c.height), 0, 0,
                       cv::INTER_AREA);
          return out8;
        },
        out, options);
    std::printf(
        "wrote %s: %zu views %dx%d at %.3g Hz, %d frame%s each%s%s (%s)\n",
        out.c_str(), scene.views.size(), scene.views[0].camera.width,
        scene.views[0].camera.height, options.rate, options.frames_per_view,
        options.frames_per_view == 1 ? "" : "s",
        options.body_frame.empty() ? ""
                                   : (", /tf of " + options.body_frame).c_str(),
        options.with_points ? ", sparse points" : "", scene.source.c_str());
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "wild_mvs_to_bag: error: %s\n", e.what());
    return 1;
  }
}
