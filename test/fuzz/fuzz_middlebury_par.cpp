// Copyright wild_mvs authors. libFuzzer harness: Middlebury *_par.txt.
//
// The scratch folder holds small images a.png, b.png, c.png that the par
// lines can name (the reader takes image sizes from their headers).
#include <cstdint>
#include <string>

#include "fuzz_util.h"
#include "scene_checks.h"
#include "wild_mvs/core/error.h"
#include "wild_mvs/io/middlebury.h"

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  wild_mvs::fuzz::WriteSampleImages();
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace wild_mvs;
  const std::string path = fuzz::WriteScratch(
      "par.txt", std::string(reinterpret_cast<const char*>(data), size));
  try {
    const Scene scene = ReadMiddleburyPar(path);
    fuzz::CheckAcceptedScene(scene);
    for (const View& v : scene.views) v.camera.Validate("accepted camera");
  } catch (const Error&) {
  }
  return 0;
}
