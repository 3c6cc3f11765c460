// Copyright wild_mvs authors. libFuzzer harness: COLMAP binary model.
//
// Input: cameras.bin #WMSPLIT images.bin #WMSPLIT points3D.bin (a missing
// part = an absent file). ReadColmapBinary must return a scene or throw
// wild_mvs::Error.
#include <cstdint>
#include <string>
#include <vector>

#include "fuzz_util.h"
#include "scene_checks.h"
#include "wild_mvs/core/error.h"
#include "wild_mvs/io/colmap.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace wild_mvs;
  static const char* kNames[] = {"cameras.bin", "images.bin", "points3D.bin"};
  const std::vector<std::string> parts = fuzz::SplitInput(data, size, 3);
  for (size_t i = 0; i < 3; ++i) {
    if (i < parts.size()) {
      fuzz::WriteScratch(kNames[i], parts[i]);
    } else {
      fuzz::RemoveScratch(kNames[i]);
    }
  }
  try {
    const Scene scene = ReadColmapBinary(fuzz::ScratchDir(), "/images");
    fuzz::CheckAcceptedScene(scene);
  } catch (const Error&) {
  }
  return 0;
}
