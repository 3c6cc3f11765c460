// Copyright wild_mvs authors. rosrun wild_mvs depth_node (see depth_nodelet.h).
#include "wild_mvs/ros/depth_nodelet.h"
#include "wild_mvs/ros/node_main.h"

int main(int argc, char** argv) {
  return wild_mvs::ros1::RunNode<wild_mvs::ros1::DepthNode>(argc, argv,
                                                            "depth_node");
}
