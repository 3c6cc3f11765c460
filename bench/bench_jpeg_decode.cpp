// Copyright wild_mvs authors. Decode time and peak memory of a large JPEG
// through LoadViewImage, full versus reduced decoding (io/image_files.h).
//
//   bench_jpeg_decode --make FILE.jpg [WIDTH HEIGHT]
//     writes a textured test JPEG (default 5472 x 3648, 20 MP).
//   bench_jpeg_decode FILE.jpg MAX_SIZE full|reduced [REPEAT]
//     loads it REPEAT times (default 3) as a view downscaled to MAX_SIZE
//     pixels (as --max-image-size does), "full" by decoding the whole file
//     and resizing (the behaviour before reduced decoding), "reduced"
//     through LoadViewImage; prints the median time and the process's peak
//     RSS. Run once per mode (separate processes: separate RSS peaks).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <string>
#include <vector>

#include "wild_mvs/core/error.h"
#include "wild_mvs/core/image.h"
#include "wild_mvs/core/stats.h"
#include "wild_mvs/io/image_files.h"
#include "wild_mvs/io/image_size.h"

using namespace wild_mvs;  // NOLINT

namespace {

int Make(const std::string& path, int w, int h) {
  cv::Mat img(h, w, CV_8UC3);
  cv::RNG rng(7);
  cv::Mat noise(h / 8 + 1, w / 8 + 1, CV_8UC3);
  rng.fill(noise, cv::RNG::UNIFORM, 0, 255);
  cv::resize(noise, img, img.size(), 0, 0, cv::INTER_CUBIC);
  cv::imwrite(path, img, {cv::IMWRITE_JPEG_QUALITY, 92});
  std::printf("wrote %s (%d x %d)\n", path.c_str(), w, h);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    if (argc >= 3 && std::string(argv[1]) == "--make") {
      return Make(argv[2], argc > 4 ? std::atoi(argv[3]) : 5472,
                  argc > 4 ? std::atoi(argv[4]) : 3648);
    }
    if (argc < 4) {
      std::fprintf(stderr,
                   "usage: bench_jpeg_decode --make FILE.jpg [W H]\n"
                   "       bench_jpeg_decode FILE.jpg MAX_SIZE full|reduced "
                   "[REPEAT]\n");
      return 2;
    }
    const std::string path = argv[1], mode = argv[3];
    const int max_size = std::atoi(argv[2]);
    const int repeat = argc > 4 ? std::max(1, std::atoi(argv[4])) : 3;
    Require(mode == "full" || mode == "reduced", "mode must be full|reduced");
    // The file size from the header (no decode: it would count in the RSS).
    const ImageSize size = ReadImageSize(path);
    View v;
    v.name = path;
    v.image_path = path;
    v.camera.width = size.width;
    v.camera.height = size.height;
    v.camera.fx = v.camera.fy = size.width;
    v.camera.cx = size.width / 2.0;
    v.camera.cy = size.height / 2.0;
    v.file_width = size.width;
    v.file_height = size.height;
    v.camera = v.camera.Scaled(static_cast<double>(max_size) /
                               std::max(size.width, size.height));
    std::vector<double> secs;
    ImageOptions o;
    int factor = 1;
    for (int i = 0; i < repeat; ++i) {
      const auto t0 = std::chrono::steady_clock::now();
      cv::Mat img;
      if (mode == "full") {
        cv::Mat full = cv::imread(
            path, cv::IMREAD_UNCHANGED | cv::IMREAD_IGNORE_ORIENTATION);
        cv::Mat small;
        cv::resize(full, small, cv::Size(v.camera.width, v.camera.height), 0, 0,
                   cv::INTER_AREA);
        img = ToLinearRgb(small, o.linearize);
      } else {
        img = LoadViewImage(v, o);
      }
      secs.push_back(
          std::chrono::duration<double>(std::chrono::steady_clock::now() - t0)
              .count());
    }
    if (mode == "reduced") ReadViewImageFile(v, &factor);  // the factor used
    std::sort(secs.begin(), secs.end());
    std::printf(
        "%s: %d x %d -> %d x %d (%s, factor %d): median %.3f s over %d, "
        "peak RSS %.0f MB\n",
        path.c_str(), v.file_width, v.file_height, v.camera.width,
        v.camera.height, mode.c_str(), mode == "full" ? 1 : factor,
        secs[secs.size() / 2], repeat, PeakRssMb());
    return 0;
  } catch (const Error& e) {
    std::fprintf(stderr, "bench_jpeg_decode: %s\n", e.what());
    return 1;
  }
}
