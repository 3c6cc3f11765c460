// Copyright wild_mvs authors.
#include "wild_mvs/io/pixel_buffer.h"

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <vector>

#include "wild_mvs/core/error.h"
#include "wild_mvs/core/image.h"

namespace wild_mvs {

cv::Mat WrapPixels(const PixelBuffer& b, int type, const std::string& what) {
  Require(b.width > 0 && b.height > 0, what, ": empty image (", b.width, "x",
          b.height, ")");
  Require(b.width <= kMaxBufferImageSide && b.height <= kMaxBufferImageSide,
          what, ": image of ", b.width, "x", b.height, " is too large");
  const size_t row_bytes = static_cast<size_t>(b.width) * CV_ELEM_SIZE(type);
  Require(b.step >= row_bytes, what, ": step ", b.step,
          " is shorter than a row of ", b.width, " pixels of encoding '",
          b.encoding, "' (", row_bytes, " bytes)");
  Require(b.size >= static_cast<size_t>(b.step) * b.height, what, ": data has ",
          b.size,
          " bytes, step * height = ", static_cast<size_t>(b.step) * b.height);
  const int bytes_per_channel = CV_ELEM_SIZE1(type);
  const bool host_big_endian = false;  // x86 / ARM little endian
  Require(bytes_per_channel == 1 || b.big_endian == host_big_endian, what,
          ": big-endian ", b.encoding, " data is not supported");
  Require(b.step % bytes_per_channel == 0, what, ": step ", b.step,
          " is not a multiple of the channel size");
  // const_cast: the Mat is only read (and cloned before it is kept).
  return cv::Mat(static_cast<int>(b.height), static_cast<int>(b.width), type,
                 const_cast<uint8_t*>(b.data), b.step);
}

namespace {

bool IsBayer(const std::string& e) {
  for (const char* p : {"rggb", "bggr", "gbrg", "grbg"})
    for (const char* bits : {"8", "16"})
      if (e == std::string("bayer_") + p + bits) return true;
  return false;
}

}  // namespace

cv::Mat PixelsToLinearRgb(const PixelBuffer& b, bool linearize) {
  const std::string& e = b.encoding;
  const std::string what = "image (encoding '" + e + "')";
  cv::Mat m;
  if (e == "mono8") {
    m = WrapPixels(b, CV_8UC1, what);
  } else if (e == "mono16") {
    m = WrapPixels(b, CV_16UC1, what);
  } else if (e == "bgr8" || e == "rgb8") {
    m = WrapPixels(b, CV_8UC3, what);
  } else if (e == "bgr16" || e == "rgb16") {
    m = WrapPixels(b, CV_16UC3, what);
  } else if (e == "bgra8" || e == "rgba8") {
    m = WrapPixels(b, CV_8UC4, what);
  } else if (e == "32FC1") {
    m = WrapPixels(b, CV_32FC1, what);
  } else if (IsBayer(e)) {
    const bool is16 = e.compare(e.size() - 2, 2, "16") == 0;
    cv::Mat raw = WrapPixels(b, is16 ? CV_16UC1 : CV_8UC1, what);
    Require(raw.cols >= 2 && raw.rows >= 2, what,
            ": a Bayer image needs at least 2x2 pixels");
    // OpenCV names a Bayer pattern by the 2x2 block starting at pixel (1, 1)
    // (its second row and column), ROS by the one at (0, 0): image_proc's
    // mapping (rggb -> BayerBG, bggr -> BayerRG, gbrg -> BayerGR, grbg ->
    // BayerGB). Checked by the PixelBuffer.BayerDemosaic test.
    const std::string pattern = e.substr(6, 4);
    int code;
    if (pattern == "rggb") {
      code = cv::COLOR_BayerBG2BGR;
    } else if (pattern == "bggr") {
      code = cv::COLOR_BayerRG2BGR;
    } else if (pattern == "gbrg") {
      code = cv::COLOR_BayerGR2BGR;
    } else {
      code = cv::COLOR_BayerGB2BGR;
    }
    cv::cvtColor(raw, m, code);  // BGR, a new buffer
  } else if (e == "32FC3") {
    m = WrapPixels(b, CV_32FC3, what);
  } else {
    throw Error(Msg("image: unsupported encoding '", e,
                    "' (expected mono8, mono16, rgb8, bgr8, rgba8, bgra8, "
                    "rgb16, bgr16, 32FC1, 32FC3, bayer_rggb8, bayer_bggr8, "
                    "bayer_gbrg8, bayer_grbg8 or their 16-bit variants)"));
  }
  // ToLinearRgb expects OpenCV's BGR(A) order.
  cv::Mat bgr;
  if (e == "rgb8" || e == "rgb16" || e == "32FC3") {
    cv::cvtColor(m, bgr, cv::COLOR_RGB2BGR);
  } else if (e == "rgba8") {
    cv::cvtColor(m, bgr, cv::COLOR_RGBA2BGR);
  } else {
    bgr = m;
  }
  const bool is_float = m.depth() == CV_32F;
  if (is_float) {
    Require(cv::checkRange(bgr, true, nullptr, -1e6, 1e6), what,
            ": non-finite pixel values");
  }
  cv::Mat out = ToLinearRgb(bgr, linearize && !is_float);
  if (out.data == b.data) out = out.clone();  // never alias the buffer
  return out;
}

cv::Mat DecodeToLinearRgb(const uint8_t* data, size_t size,
                          const std::string& format, bool linearize) {
  Require(size > 0, "compressed image: no data (format '", format, "')");
  cv::Mat bgr;
  try {
    const cv::Mat bytes(1, static_cast<int>(size), CV_8UC1,
                        const_cast<uint8_t*>(data));
    bgr = cv::imdecode(bytes, cv::IMREAD_UNCHANGED);
  } catch (const cv::Exception& e) {
    throw Error(Msg("compressed image (format '", format,
                    "'): cannot decode: ", e.what()));
  }
  Require(!bgr.empty(), "compressed image (format '", format,
          "'): cannot decode ", size, " bytes");
  return ToLinearRgb(bgr, linearize);
}

}  // namespace wild_mvs
