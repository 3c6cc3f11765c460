// Copyright wild_mvs authors.
#include "wild_mvs/io/image_size.h"

#include <cctype>
#include <cerrno>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <opencv2/imgcodecs.hpp>
#include <vector>

#include "wild_mvs/core/error.h"

namespace wild_mvs {
namespace {

uint32_t BigEndian32(const unsigned char* p) {
  return (uint32_t(p[0]) << 24) | (uint32_t(p[1]) << 16) |
         (uint32_t(p[2]) << 8) | p[3];
}
uint16_t BigEndian16(const unsigned char* p) {
  return static_cast<uint16_t>((p[0] << 8) | p[1]);
}

bool ProbeJpeg(std::ifstream& in, ImageSize* s) {
  in.seekg(2);
  unsigned char b[9];
  for (int guard = 0; guard < 100000; ++guard) {
    int c = in.get();
    if (c == EOF) return false;
    if (c != 0xFF) continue;
    do c = in.get();
    while (c == 0xFF);
    if (c == EOF) return false;
    if (c == 0xD8 || c == 0x01 || (c >= 0xD0 && c <= 0xD7)) continue;
    if (c == 0xD9 || c == 0xDA) return false;  // end / scan before a frame
    if (!in.read(reinterpret_cast<char*>(b), 2)) return false;
    const int len = BigEndian16(b);
    if (len < 2) return false;
    const bool sof =
        c >= 0xC0 && c <= 0xCF && c != 0xC4 && c != 0xC8 && c != 0xCC;
    if (sof) {
      if (!in.read(reinterpret_cast<char*>(b), 5)) return false;
      s->height = BigEndian16(b + 1);
      s->width = BigEndian16(b + 3);
      return true;
    }
    in.seekg(len - 2, std::ios::cur);
    if (!in) return false;
  }
  return false;
}

bool ProbePnm(std::ifstream& in, ImageSize* s) {
  in.seekg(2);
  long long v[2];
  for (int i = 0; i < 2; ++i) {
    int c = in.get();
    while (c != EOF && (std::isspace(c) || c == '#')) {
      if (c == '#')
        while (c != EOF && c != '\n') c = in.get();
      c = in.get();
    }
    if (c == EOF || !std::isdigit(c)) return false;
    long long n = 0;
    while (c != EOF && std::isdigit(c) && n < 100000000) {
      n = n * 10 + (c - '0');
      c = in.get();
    }
    v[i] = n;
  }
  s->width = static_cast<int>(v[0]);
  s->height = static_cast<int>(v[1]);
  return true;
}

}  // namespace

ImageSize ReadImageSize(const std::string& path) {
  std::error_code ec;
  Require(std::filesystem::is_regular_file(path, ec), path,
          ": image file is missing");
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    const int err = errno;
    throw Error(Msg(path, ": cannot open image: ", std::strerror(err)));
  }
  unsigned char h[32] = {0};
  in.read(reinterpret_cast<char*>(h), sizeof(h));
  const std::streamsize n = in.gcount();
  in.clear();
  ImageSize s;
  bool ok = false;
  if (n >= 24 && std::memcmp(h, "\x89PNG\r\n\x1a\n", 8) == 0 &&
      std::memcmp(h + 12, "IHDR", 4) == 0) {
    s.width = static_cast<int>(BigEndian32(h + 16));
    s.height = static_cast<int>(BigEndian32(h + 20));
    ok = true;
  } else if (n >= 4 && h[0] == 0xFF && h[1] == 0xD8) {
    ok = ProbeJpeg(in, &s);
  } else if (n >= 3 && h[0] == 'P' &&
             ((h[1] >= '1' && h[1] <= '6') || h[1] == 'F' || h[1] == 'f') &&
             std::isspace(h[2])) {
    ok = ProbePnm(in, &s);
  } else if (n >= 26 && h[0] == 'B' && h[1] == 'M') {
    int32_t w, hh;
    std::memcpy(&w, h + 18, 4);
    std::memcpy(&hh, h + 22, 4);
    // A negative height means a top-down bitmap; INT32_MIN has no positive
    // counterpart (not a real size: OpenCV decides below).
    s.width = w;
    s.height = hh == INT32_MIN ? 0 : (hh < 0 ? -hh : hh);
    ok = true;
  }
  if (!ok || s.width <= 0 || s.height <= 0) {
    // Unknown or unusual header: let OpenCV decode it.
    cv::Mat img;
    try {
      img = cv::imread(path,
                       cv::IMREAD_UNCHANGED | cv::IMREAD_IGNORE_ORIENTATION);
    } catch (const cv::Exception&) {
    }
    Require(!img.empty(), path,
            ": cannot read image (truncated, corrupt or not an image)");
    s.width = img.cols;
    s.height = img.rows;
  }
  return s;
}

}  // namespace wild_mvs
