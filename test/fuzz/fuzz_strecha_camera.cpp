// Copyright wild_mvs authors. libFuzzer harness: Strecha .camera files and
// per-frame 3x4 projection matrices (.projmatrix, pavilion), the two
// one-file-per-image camera formats. The first byte picks the format.
//
// An accepted camera must be usable (finite, positive focal length and size
// for .camera, a proper rotation).
#include <cmath>
#include <cstdint>
#include <string>

#include "fuzz_util.h"
#include "wild_mvs/core/error.h"
#include "wild_mvs/io/projmatrix.h"
#include "wild_mvs/io/strecha.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace wild_mvs;
  if (size == 0) return 0;
  const bool projmatrix = data[0] & 1;
  const std::string text(reinterpret_cast<const char*>(data + 1), size - 1);
  try {
    if (!projmatrix) {
      const std::string path = fuzz::WriteScratch("0000.jpg.camera", text);
      const Camera c = ReadStrechaCamera(path);
      c.Validate("accepted .camera");
    } else {
      const std::string path = fuzz::WriteScratch("007.projmatrix", text);
      const Eigen::Matrix<double, 3, 4> P = ReadProjectionMatrix(path);
      if (!P.allFinite()) __builtin_trap();
      Camera c = DecomposeProjectionMatrix(P, path);
      if (!(c.fx > 0) || !(c.fy > 0) || !std::isfinite(c.cx) ||
          !std::isfinite(c.cy) || !c.R.allFinite() || !c.t.allFinite())
        __builtin_trap();
      c.width = c.height = 100;  // .projmatrix has no size; only K, R, t
      c.Validate("accepted .projmatrix");
    }
  } catch (const Error&) {
  }
  return 0;
}
