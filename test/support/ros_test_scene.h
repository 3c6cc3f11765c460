// Copyright wild_mvs authors. The synthetic stream shared by the stream and
// ROS tests: boxes and a sphere on a textured ground plane, seen by cameras
// moving in 10-degree steps on an arc (a robot circling an object), small
// images so the tests stay fast.
#pragma once

#include "synthetic_scene.h"

namespace wild_mvs {
namespace testing {

// Cameras 10 degrees apart.
inline SyntheticSpec RosTestSpec(int num_views = 6) {
  SyntheticSpec s = ClutteredSceneSpec(false, false);
  s.camera_centers =
      MakeRingCameras(num_views, 2.6, 1.5, 10.0 * (num_views - 1));
  s.width = 160;
  s.height = 120;
  s.focal = 150;
  s.num_sparse_points = 300;
  return s;
}

}  // namespace testing
}  // namespace wild_mvs
