// Copyright wild_mvs authors. libFuzzer harness: Bundler v0.3 bundle.out +
// list.txt.
//
// Input: bundle.out #WMSPLIT list.txt. The scratch folder holds small images
// a.png, b.png, c.png (and images/ with the same) so that list entries can
// name real images, whose sizes the reader takes from their headers.
#include <cstdint>
#include <string>
#include <vector>

#include "fuzz_util.h"
#include "scene_checks.h"
#include "wild_mvs/core/error.h"
#include "wild_mvs/io/bundler.h"

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  wild_mvs::fuzz::WriteSampleImages();
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace wild_mvs;
  const std::vector<std::string> parts = fuzz::SplitInput(data, size, 2);
  const std::string bundle = fuzz::WriteScratch("bundle.out", parts[0]);
  if (parts.size() < 2) {
    fuzz::RemoveScratch("list.txt");
  } else {
    fuzz::WriteScratch("list.txt", parts[1]);
  }
  try {
    const Scene scene = ReadBundler(bundle, fuzz::ScratchDir() + "/list.txt");
    fuzz::CheckAcceptedScene(scene);
  } catch (const Error&) {
  }
  return 0;
}
