// Copyright wild_mvs authors. libFuzzer harness: PFM images.
//
// ReadPfm must return a 1- or 3-channel float image whose pixels were all in
// the file, or throw wild_mvs::Error. An accepted image must survive a
// write / read round trip bit for bit.
#include <cstdint>
#include <cstring>
#include <opencv2/core.hpp>
#include <string>

#include "fuzz_util.h"
#include "wild_mvs/core/error.h"
#include "wild_mvs/io/pfm.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace wild_mvs;
  const std::string path = fuzz::WriteScratch(
      "in.pfm", std::string(reinterpret_cast<const char*>(data), size));
  cv::Mat image;
  try {
    image = ReadPfm(path);
  } catch (const Error&) {
    return 0;
  }
  if (image.type() != CV_32F && image.type() != CV_32FC3) __builtin_trap();
  if (image.empty() || !image.isContinuous()) __builtin_trap();
  // Every pixel must come from the file: no invented data.
  if (image.total() * image.elemSize() > size) __builtin_trap();
  const std::string out = fuzz::ScratchDir() + "/out.pfm";
  fuzz::WriteScratch("out.pfm", "");  // registers the name for cleanup
  WritePfm(out, image);
  const cv::Mat back = ReadPfm(out);
  if (back.type() != image.type() || back.size() != image.size() ||
      std::memcmp(back.data, image.data, image.total() * image.elemSize()) != 0)
    __builtin_trap();
  return 0;
}
