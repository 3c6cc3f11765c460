// Copyright wild_mvs authors.
#include "wild_mvs/core/depth_map.h"

namespace wild_mvs {

int DepthMap::CountValid() const {
  if (depth.empty()) return 0;
  return cv::countNonZero(depth > 0);
}

}  // namespace wild_mvs
