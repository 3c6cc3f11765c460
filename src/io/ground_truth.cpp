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

cv::Mat ResampleDepth(const cv::Mat& depth, const Camera& src,
                      const Camera& dst) {
  Require(depth.type() == CV_32F && !depth.empty(),
          "ResampleDepth: depth must be a non-empty CV_32F image");
  Require(depth.cols == src.width && depth.rows == src.height,
          "ResampleDepth: depth is ", depth.cols, "x", depth.rows,
          " but its camera is ", src.width, "x", src.height);
  Require((src.R - dst.R).norm() < 1e-9 &&
              (src.t - dst.t).norm() < 1e-9 * (1 + src.t.norm()),
          "ResampleDepth: the cameras must have the same pose");
  cv::Mat out(dst.height, dst.width, CV_32F, cv::Scalar(0));
  const int W = depth.cols, H = depth.rows;
  for (int r = 0; r < dst.height; ++r) {
    float* o = out.ptr<float>(r);
    const double y = (r + 0.5 - dst.cy) / dst.fy;
    const double fr = src.fy * y + src.cy - 0.5;  // source row (centres)
    for (int c = 0; c < dst.width; ++c) {
      const double x = (c + 0.5 - dst.cx) / dst.fx;
      const double fc = src.fx * x + src.cx - 0.5;
      if (fc < -0.5 || fr < -0.5 || fc > W - 0.5 || fr > H - 0.5) continue;
      const int c0 = static_cast<int>(std::floor(fc));
      const int r0 = static_cast<int>(std::floor(fr));
      const double ax = fc - c0, ay = fr - r0;
      auto at = [&](int rr, int cc) {
        rr = std::clamp(rr, 0, H - 1);
        cc = std::clamp(cc, 0, W - 1);
        return depth.at<float>(rr, cc);
      };
      const float d00 = at(r0, c0), d01 = at(r0, c0 + 1), d10 = at(r0 + 1, c0),
                  d11 = at(r0 + 1, c0 + 1);
      const float lo = std::min({d00, d01, d10, d11});
      const float hi = std::max({d00, d01, d10, d11});
      if (lo > 0 && hi - lo <= 0.01f * lo) {
        o[c] = static_cast<float>((1 - ay) * ((1 - ax) * d00 + ax * d01) +
                                  ay * ((1 - ax) * d10 + ax * d11));
      } else {
        o[c] = at(static_cast<int>(std::lround(fr)),
                  static_cast<int>(std::lround(fc)));
      }
    }
  }
  return out;
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
