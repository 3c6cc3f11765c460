// Copyright wild_mvs authors. Point cloud and triangle mesh value types.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <vector>

namespace wild_mvs {

// Structure of arrays; optional attributes are empty or of size().
// Positions in world units; normals unit length; colours in [0, 1] (sRGB
// for display); confidence in [0, 1]; support = number of views that agree.
struct PointCloud {
  std::vector<Eigen::Vector3f> xyz;
  std::vector<Eigen::Vector3f> normal;
  std::vector<Eigen::Vector3f> rgb;
  std::vector<float> confidence;
  std::vector<uint16_t> support;

  size_t size() const { return xyz.size(); }
  bool empty() const { return xyz.empty(); }
  bool has_normal() const { return !normal.empty(); }
  bool has_rgb() const { return !rgb.empty(); }
  bool has_confidence() const { return !confidence.empty(); }
  bool has_support() const { return !support.empty(); }
};

struct Mesh {
  PointCloud vertices;
  std::vector<Eigen::Vector3i> faces;  // counter-clockwise seen from outside
};

}  // namespace wild_mvs
