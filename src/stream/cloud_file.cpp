// Copyright wild_mvs authors.
#include "wild_mvs/stream/cloud_file.h"

#include <algorithm>
#include <cstdint>
#include <ostream>

#include "wild_mvs/core/error.h"
#include "wild_mvs/io/atomic_file.h"

namespace wild_mvs {

void SaveCloudPly(const std::string& path, const PointCloud& cloud) {
  Require(!path.empty(), "SaveCloudPly: empty path");
  const bool n = cloud.has_normal(), c = cloud.has_rgb(),
             q = cloud.has_confidence();
  Require((!n || cloud.normal.size() == cloud.size()) &&
              (!c || cloud.rgb.size() == cloud.size()) &&
              (!q || cloud.confidence.size() == cloud.size()),
          "SaveCloudPly: ", path, ": attribute arrays differ in size");
  WriteFileAtomically(path, [&](std::ostream& os) {
    os << "ply\nformat binary_little_endian 1.0\n"
       << "comment wild_mvs fusion node\n"
       << "element vertex " << cloud.size() << "\n"
       << "property float x\nproperty float y\nproperty float z\n";
    if (n) os << "property float nx\nproperty float ny\nproperty float nz\n";
    if (c)
      os << "property uchar red\nproperty uchar green\nproperty uchar blue\n";
    if (q) os << "property float confidence\n";
    os << "end_header\n";
    auto put = [&os](const auto& v) {
      os.write(reinterpret_cast<const char*>(&v), sizeof(v));
    };
    for (size_t i = 0; i < cloud.size(); ++i) {
      for (int k = 0; k < 3; ++k) put(cloud.xyz[i][k]);
      if (n)
        for (int k = 0; k < 3; ++k) put(cloud.normal[i][k]);
      if (c)
        for (int k = 0; k < 3; ++k)
          put(static_cast<uint8_t>(
              std::clamp(cloud.rgb[i][k], 0.0f, 1.0f) * 255.0f + 0.5f));
      if (q) put(cloud.confidence[i]);
    }
  });
}

}  // namespace wild_mvs
