// Copyright wild_mvs authors. rosrun wild_mvs depth_worker_node: reconstructs
// its share of a keyframe selector's keyframes (see depth_nodelet.h).
#include "wild_mvs/ros/depth_nodelet.h"
#include "wild_mvs/ros/node_main.h"

int main(int argc, char** argv) {
  using wild_mvs::ros1::DepthNode;
  using wild_mvs::ros1::DepthRole;
  return wild_mvs::ros1::RunNode<DepthNode>(argc, argv, "depth_worker",
                                            DepthRole::kWorker);
}
