// Copyright wild_mvs authors.
#include "wild_mvs/io/ground_truth.h"

#include <ImfChannelList.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfInputFile.h>
#include <ImfOutputFile.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>

#include "wild_mvs/core/error.h"
#include "wild_mvs/core/metrics.h"
#include "wild_mvs/io/atomic_file.h"
#include "wild_mvs/io/pfm.h"

namespace wild_mvs {

namespace fs = std::filesystem;

namespace {

void Sanitize(cv::Mat* d) {
  for (int r = 0; r < d->rows; ++r) {
    float* p = d->ptr<float>(r);
    for (int c = 0; c < d->cols; ++c)
      if (!(std::isfinite(p[c]) && p[c] > 0 && p[c] <= kMaxValidDepth))
        p[c] = 0;
  }
}

std::string Lower(std::string s) {
  for (char& c : s) c = static_cast<char>(std::tolower(c));
  return s;
}

}  // namespace

cv::Mat ReadExrDepth(const std::string& path) {
  std::error_code ec;
  Require(fs::is_regular_file(path, ec), path, ": EXR file is missing");
  try {
    Imf::InputFile file(path.c_str());
    const Imath::Box2i dw = file.header().dataWindow();
    const long long w = static_cast<long long>(dw.max.x) - dw.min.x + 1;
    const long long h = static_cast<long long>(dw.max.y) - dw.min.y + 1;
    Require(
        w > 0 && h > 0 && w <= 100000 && h <= 100000 && w * h <= 400000000LL,
        path, ": invalid EXR size ", w, "x", h);
    const Imf::ChannelList& ch = file.header().channels();
    std::string name;
    for (const char* n : {"Z", "R", "Y"})
      if (ch.findChannel(n)) {
        name = n;
        break;
      }
    if (name.empty()) {
      Require(ch.begin() != ch.end(), path, ": EXR file has no channels");
      name = ch.begin().name();
    }
    cv::Mat depth(static_cast<int>(h), static_cast<int>(w), CV_32F,
                  cv::Scalar(0));
    Imf::FrameBuffer fb;
    char* base = reinterpret_cast<char*>(depth.ptr<float>(0)) -
                 (static_cast<ptrdiff_t>(dw.min.x) +
                  static_cast<ptrdiff_t>(dw.min.y) * w) *
                     static_cast<ptrdiff_t>(sizeof(float));
    fb.insert(name.c_str(), Imf::Slice(Imf::FLOAT, base, sizeof(float),
                                       sizeof(float) * w, 1, 1, 0.0));
    file.setFrameBuffer(fb);
    file.readPixels(dw.min.y, dw.max.y);
    Sanitize(&depth);
    return depth;
  } catch (const Error&) {
    throw;
  } catch (const std::exception& e) {
    throw Error(Msg(path, ": cannot read EXR: ", e.what()));
  }
}

void WriteExrDepth(const std::string& path, const cv::Mat& depth_in) {
  Require(!depth_in.empty() && depth_in.channels() == 1, path,
          ": EXR depth must be a non-empty single-channel image");
  cv::Mat depth;
  depth_in.convertTo(depth, CV_32F);
  depth = depth.clone();  // continuous
  ProduceFileAtomically(path, [&](const std::string& tmp) {
    try {
      Imf::Header header(depth.cols, depth.rows);
      header.channels().insert("Z", Imf::Channel(Imf::FLOAT));
      Imf::OutputFile file(tmp.c_str(), header);
      Imf::FrameBuffer fb;
      fb.insert("Z", Imf::Slice(Imf::FLOAT,
                                reinterpret_cast<char*>(depth.ptr<float>(0)),
                                sizeof(float), sizeof(float) * depth.cols));
      file.setFrameBuffer(fb);
      file.writePixels(depth.rows);
    } catch (const std::exception& e) {
      throw Error(Msg(path, ": cannot write EXR: ", e.what()));
    }
    return true;
  });
}

cv::Mat ReadGroundTruthDepth(const std::string& path) {
  const std::string ext = Lower(fs::path(path).extension().string());
  if (ext == ".exr") return ReadExrDepth(path);
  if (ext == ".pfm") {
    cv::Mat d = ReadPfm(path);
    Require(d.channels() == 1, path,
            ": ground-truth depth PFM must have 1 "
            "channel");
    Sanitize(&d);
    return d;
  }
  throw Error(Msg(path,
                  ": unknown ground-truth depth format (expected .pfm "
                  "or .exr)"));
}

Camera FountainRenderCamera(const Camera& real) {
  Camera c = real;
  c.width = 3072;
  c.height = 2048;
  c.fx = c.fy = 2759.48;
  c.cx = 1536;
  c.cy = 1024;
  return c;
}

cv::Mat FountainGroundTruthDepth(const std::string& exr_path,
                                 const Camera& target) {
  const cv::Mat render = ReadExrDepth(exr_path);
  Require(render.cols == 3072 && render.rows == 2048, exr_path,
          ": fountain-P11 GT depth must be 3072x2048, is ", render.cols, "x",
          render.rows);
  return ResampleDepth(render, FountainRenderCamera(target), target);
}

cv::Mat LoadGroundTruthDepthForView(const std::string& dataset_dir,
                                    const View& view, const Camera& target) {
  const fs::path d(dataset_dir);
  const std::string stem = view.Stem();
  std::error_code ec;
  const fs::path fountain = d / "gt_depth_blender_exr" / (stem + ".exr");
  if (fs::exists(fountain, ec))
    return FountainGroundTruthDepth(fountain.string(), target);
  for (const char* ext : {".pfm", ".exr"}) {
    const fs::path p = d / "gt_depth" / (stem + ext);
    if (!fs::exists(p, ec)) continue;
    const cv::Mat gt = ReadGroundTruthDepth(p.string());
    const Camera& vc = view.camera;
    Require(gt.cols > 0 && gt.rows > 0, p.string(), ": empty depth");
    // The GT has the view's camera, at its own resolution.
    const Camera src = vc.Resized(gt.cols, gt.rows);
    return ResampleDepth(gt, src, target);
  }
  return cv::Mat();
}

}  // namespace wild_mvs
