// Copyright wild_mvs authors. libFuzzer harness: the image header probe
// (ReadImageSize: PNG, JPEG, PNM, BMP headers; OpenCV decoding otherwise),
// which Bundler, Middlebury and pavilion datasets use for image sizes.
// An accepted size must be positive.
#include <cstdint>
#include <string>

#include "fuzz_util.h"
#include "wild_mvs/core/error.h"
#include "wild_mvs/io/image_size.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace wild_mvs;
  const std::string path = fuzz::WriteScratch(
      "image.png", std::string(reinterpret_cast<const char*>(data), size));
  try {
    const ImageSize s = ReadImageSize(path);
    if (s.width <= 0 || s.height <= 0) __builtin_trap();
  } catch (const Error&) {
  }
  return 0;
}
