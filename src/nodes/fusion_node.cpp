// Copyright wild_mvs authors. rosrun wild_mvs fusion_node (see
// fusion_nodelet.h).
#include "wild_mvs/ros/fusion_nodelet.h"
#include "wild_mvs/ros/node_main.h"

int main(int argc, char** argv) {
  return wild_mvs::ros1::RunNode<wild_mvs::ros1::FusionNode>(argc, argv,
                                                             "fusion_node");
}
