// Copyright wild_mvs authors. rosrun wild_mvs depth_node: keyframes selected
// from a camera and reconstructed in one process (see depth_nodelet.h).
#include "wild_mvs/ros/depth_nodelet.h"
#include "wild_mvs/ros/node_main.h"

int main(int argc, char** argv) {
  using wild_mvs::ros1::DepthNode;
  using wild_mvs::ros1::DepthRole;
  return wild_mvs::ros1::RunNode<DepthNode>(argc, argv, "depth_node",
                                            DepthRole::kStandalone);
}
