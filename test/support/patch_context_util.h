// Copyright wild_mvs authors. PatchContext of a rendered scene for the MVS
// unit tests: view `ref` as R, every other view a neighbour (global score
// 1), the scene's images as they are (no copy).
#pragma once

#include <opencv2/core.hpp>

#include "synthetic_scene.h"
#include "wild_mvs/core/patch.h"

namespace wild_mvs {
namespace testing {

inline MatchImage AsMatch(const cv::Mat& m) {
  MatchImage im;
  im.data = m.ptr<float>();
  im.width = m.cols;
  im.height = m.rows;
  im.channels = m.channels();
  return im;
}

inline PatchContext MakeContext(const SyntheticScene& s, int ref) {
  PatchContext ctx;
  ctx.ref_camera = s.scene.views[ref].camera;
  ctx.ref_image = AsMatch(s.images[ref]);
  for (size_t v = 0; v < s.scene.views.size(); ++v) {
    if (static_cast<int>(v) == ref) continue;
    ctx.AddView(static_cast<int>(v), s.scene.views[v].camera,
                AsMatch(s.images[v]), 1.0);
  }
  return ctx;
}

}  // namespace testing
}  // namespace wild_mvs
