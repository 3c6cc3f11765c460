// Copyright wild_mvs authors. Saving the fusion node's cloud.
#pragma once

#include <string>

#include "wild_mvs/core/point_cloud.h"

namespace wild_mvs {

// Writes `cloud` as a binary little-endian PLY (x y z float; nx ny nz float,
// red green blue uchar, confidence float when present) atomically: a
// temporary file beside `path` renamed over it when complete, so an
// interrupted save never damages an earlier file. Throws Error naming the
// path and the problem.
void SaveCloudPly(const std::string& path, const PointCloud& cloud);

}  // namespace wild_mvs
