// Copyright wild_mvs authors. libFuzzer harness: OUT/sparse/tracks.txt
// (io/sparse_tracks_file.h).
//
// ReadSparseTracks must accept (points whose observations name the scene's
// views), refuse (false, with a reason) or throw wild_mvs::Error. Accepted
// points must survive a write / read round trip exactly.
#include <cstdint>
#include <string>
#include <vector>

#include "fuzz_util.h"
#include "wild_mvs/core/error.h"
#include "wild_mvs/io/sparse_tracks_file.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace wild_mvs;
  // The scene of the seed files: two views.
  Scene scene;
  for (const char* name : {"a.png", "b c.jpg"}) {
    View v;
    v.name = name;
    v.camera.width = 64;
    v.camera.height = 48;
    scene.views.push_back(v);
  }
  const std::vector<std::string> fingerprint = {"image.max_image_size 0",
                                                "dataset.mask_dir "};
  const std::string path = fuzz::WriteScratch(
      "tracks.txt", std::string(reinterpret_cast<const char*>(data), size));
  std::vector<SparsePoint> points;
  std::string why;
  bool ok = false;
  try {
    ok = ReadSparseTracks(path, scene, fingerprint, &points, &why);
  } catch (const Error&) {
    return 0;
  }
  if (!ok) {
    if (why.empty()) __builtin_trap();
    return 0;
  }
  for (const SparsePoint& p : points) {
    if (!p.xyz.allFinite()) __builtin_trap();
    for (const Observation& o : p.track) {
      if (o.view < 0 || o.view >= static_cast<int>(scene.views.size()))
        __builtin_trap();
    }
  }
  // Round trip (finite coordinates; NaN observations compare unequal, so
  // compare the written text instead).
  scene.points = points;
  const std::string out = fuzz::ScratchDir() + "/out.txt";
  fuzz::WriteScratch("out.txt", "");  // registers the name for cleanup
  WriteSparseTracks(out, scene, fingerprint);
  std::vector<SparsePoint> back;
  if (!ReadSparseTracks(out, scene, fingerprint, &back, &why)) __builtin_trap();
  if (back.size() != points.size()) __builtin_trap();
  for (size_t i = 0; i < back.size(); ++i) {
    if (back[i].xyz != points[i].xyz ||
        back[i].track.size() != points[i].track.size())
      __builtin_trap();
  }
  return 0;
}
