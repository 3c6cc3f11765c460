// Copyright wild_mvs authors. Images as camera drivers send them (a buffer
// of rows in a named encoding, or compressed bytes) decoded to the core's
// linear RGB (ROS-free; the ROS layer passes sensor_msgs/Image and
// CompressedImage fields in, conversions.h).
//
// Encodings are the ROS names (sensor_msgs/image_encodings): mono8, mono16,
// rgb8/16, bgr8/16, rgba8, bgra8; 32FC1 / 32FC3 are taken as linear; the
// Bayer patterns bayer_rggb8, bayer_bggr8, bayer_gbrg8, bayer_grbg8 and
// their 16-bit bayer_*16 variants are demosaiced bilinearly with
// cv::cvtColor. Every function validates its input and throws
// wild_mvs::Error naming the problem, so a malformed image never reaches an
// algorithm.
#pragma once

#include <cstddef>
#include <cstdint>
#include <opencv2/core.hpp>
#include <string>

namespace wild_mvs {

// A view of an image buffer (not owned): `height` rows of `step` bytes.
struct PixelBuffer {
  uint32_t width = 0, height = 0;
  std::string encoding;
  bool big_endian = false;
  uint32_t step = 0;
  const uint8_t* data = nullptr;
  size_t size = 0;  // bytes at data
};

// Largest image side accepted (images and camera_info).
constexpr uint32_t kMaxBufferImageSide = 32768;

// The buffer as a cv::Mat of `type` over its data (not copied) after
// checking the layout: a non-empty size up to kMaxBufferImageSide, a step of
// at least a row (a multiple of the channel size), data of at least step *
// height bytes, little-endian multi-byte data. `what` starts the errors.
cv::Mat WrapPixels(const PixelBuffer& buffer, int type,
                   const std::string& what);

// The image as CV_32FC3 linear RGB (linearize: undo sRGB gamma on integer
// encodings), never sharing the buffer. Rejects unknown or depth-like
// encodings (16UC1 "depth") with an Error naming the encoding, a Bayer
// image below 2x2, non-finite float pixels, and what WrapPixels rejects.
cv::Mat PixelsToLinearRgb(const PixelBuffer& buffer, bool linearize);

// JPEG / PNG bytes (`format` names them in errors) decoded with
// cv::imdecode, as CV_32FC3 linear RGB.
cv::Mat DecodeToLinearRgb(const uint8_t* data, size_t size,
                          const std::string& format, bool linearize);

}  // namespace wild_mvs
