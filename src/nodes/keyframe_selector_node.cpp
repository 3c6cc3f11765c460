// Copyright wild_mvs authors. rosrun wild_mvs keyframe_selector_node: selects
// and tracks keyframes from a camera and publishes them for depth workers
// (see depth_nodelet.h).
#include "wild_mvs/ros/depth_nodelet.h"
#include "wild_mvs/ros/node_main.h"

int main(int argc, char** argv) {
  using wild_mvs::ros1::DepthNode;
  using wild_mvs::ros1::DepthRole;
  return wild_mvs::ros1::RunNode<DepthNode>(argc, argv, "keyframe_selector",
                                            DepthRole::kSelector);
}
