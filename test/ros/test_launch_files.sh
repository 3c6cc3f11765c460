#!/usr/bin/env bash
# The launch files expand with their arguments (roslaunch --nodes / --args /
# --dump-params, no master needed): node names, the remaps that follow
# image / camera_info / pose, the parameters the arguments set, the config
# default (node defaults only) and the rviz Fixed Frame.
#   test/ros/test_launch_files.sh DEVEL_DIR
set -eo pipefail
DEVEL=${1:?usage: test_launch_files.sh DEVEL_DIR}
export PATH=/usr/local/sbin:/usr/local/bin:/usr/sbin:/usr/bin:/sbin:/bin
# shellcheck source=/dev/null
source "$DEVEL/setup.bash"
export ROS_HOME=$(mktemp -d)
trap 'rm -rf "$ROS_HOME"' EXIT
cd "$ROS_HOME"
n=0
fail() { echo "FAIL: $*" >&2; exit 1; }
has() {  # has TEXT PATTERN WHAT
  grep -qE -- "$2" <<<"$1" || { echo "$1" >&2; fail "$3: no match for '$2'"; }
  n=$((n + 1))
}
hasnt() {
  ! grep -qE -- "$2" <<<"$1" || { echo "$1" >&2; fail "$3: unexpected '$2'"; }
  n=$((n + 1))
}
L=reconstruct_bag.launch

# Defaults: camera_info beside the image, sim time with --clock, node
# defaults only (config/sample.yaml not loaded), the finisher, no recorder.
nodes=$(roslaunch --nodes wild_mvs $L bag:=/tmp/a.bag)
for x in /player /depth_node /fusion_node /finish; do has "$nodes" "^$x\$" "$L nodes"; done
hasnt "$nodes" "^/(recorder|rviz|wild_mvs_manager)\$" "$L default nodes"
args=$(roslaunch --args /depth_node wild_mvs $L bag:=/tmp/a.bag)
has "$args" "image:=/camera/image_raw" "$L default image"
has "$args" "camera_info:=/camera/camera_info" "$L default camera_info"
play=$(roslaunch --args /player wild_mvs $L bag:=/tmp/a.bag)
has "$play" "--clock" "$L use_sim_time: rosbag play --clock"
params=$(roslaunch --dump-params wild_mvs $L bag:=/tmp/a.bag)
has "$params" "/use_sim_time: true" "$L /use_sim_time"
has "$params" "/depth_node/world_frame: world" "$L world_frame"
has "$params" "/depth_node/image_transport: raw" "$L transport"
has "$params" "/depth_node/pose_source: tf" "$L pose_source"
has "$params" "/depth_node/keyframe_min_baseline: 0.05" "$L config default (node defaults only)"
has "$params" "/depth_node/camera_frame: ''" "$L camera_frame default (the image header's frame)"
has "$params" "/depth_node/mvs/max_image_size: 0" "$L max_image_size default (node defaults)"
hasnt "$params" "/depth_node/max_image_size:" "$L one size parameter (mvs/max_image_size)"
params=$(roslaunch --dump-params wild_mvs $L bag:=/tmp/a.bag max_image_size:=320)
has "$params" "/depth_node/mvs/max_image_size: 320" "$L max_image_size"

# A user's own bag: other topics, transport, frames, pose topic, config.
A=(bag:=/tmp/a.bag image:=/cam0/color/image_raw transport:=compressed world_frame:=map
   camera_frame:=cam0_optical pose_source:=topic pose:=/cam0/pose use_sim_time:=false
   config:="$(rospack find wild_mvs)/config/sample.yaml")
args=$(roslaunch --args /depth_node wild_mvs $L "${A[@]}")
has "$args" "image:=/cam0/color/image_raw" "$L image"
has "$args" "camera_info:=/cam0/color/camera_info" "$L camera_info from the image's namespace"
has "$args" "pose:=/cam0/pose" "$L pose"
play=$(roslaunch --args /player wild_mvs $L "${A[@]}")
hasnt "$play" "--clock" "$L use_sim_time:=false"
params=$(roslaunch --dump-params wild_mvs $L "${A[@]}")
has "$params" "/use_sim_time: false" "$L use_sim_time:=false"
has "$params" "/depth_node/world_frame: map" "$L world_frame"
has "$params" "/fusion_node/world_frame: map" "$L world_frame (fusion)"
has "$params" "/depth_node/camera_frame: cam0_optical" "$L camera_frame"
has "$params" "/depth_node/image_transport: compressed" "$L transport"
has "$params" "/depth_node/pose_source: topic" "$L pose_source"
has "$params" "/depth_node/keyframe_min_baseline: 0.02" "$L config on top of the defaults"
args=$(roslaunch --args /depth_node wild_mvs $L bag:=/tmp/a.bag camera_info:=/info)
has "$args" "camera_info:=/info" "$L explicit camera_info"

# record, rviz (Fixed Frame = world_frame, image display follows image), nodelets
nodes=$(roslaunch --nodes wild_mvs $L bag:=/tmp/a.bag nodelets:=true rviz:=true record:=/tmp/r.bag)
for x in /wild_mvs_manager /depth_node /fusion_node /recorder /rviz; do has "$nodes" "^$x\$" "$L nodes"; done
rec=$(roslaunch --args /recorder wild_mvs $L bag:=/tmp/a.bag record:=/tmp/r.bag)
for t in /depth_node/depth_view /fusion_node/cloud /diagnostics /tf /tf_static; do
  has "$rec" " $t( |\$)" "$L record topics"
done
rv=$(roslaunch --args /rviz wild_mvs $L bag:=/tmp/a.bag rviz:=true world_frame:=map image:=/cam0/image_raw)
has "$rv" "-f map" "$L rviz fixed frame"
has "$rv" "/camera/image_raw:=/cam0/image_raw" "$L rviz image remap"

# live.launch, workers.launch, depth_worker.launch: the same argument names
args=$(roslaunch --args /depth_node wild_mvs live.launch camera:=/cam1)
has "$args" "image:=/cam1/image_raw" "live.launch camera"
has "$args" "camera_info:=/cam1/camera_info" "live.launch camera_info"
params=$(roslaunch --dump-params wild_mvs live.launch world_frame:=map transport:=compressed)
has "$params" "/depth_node/world_frame: map" "live.launch world_frame"
has "$params" "/fusion_node/world_frame: map" "live.launch world_frame (fusion)"
has "$params" "/depth_node/image_transport: compressed" "live.launch transport"
nodes=$(roslaunch --nodes wild_mvs workers.launch image:=/cam0/image_raw)
for x in /keyframe_selector /depth_worker_0 /depth_worker_1 /fusion_node; do has "$nodes" "^$x\$" "workers.launch nodes"; done
args=$(roslaunch --args /keyframe_selector wild_mvs workers.launch image:=/cam0/image_raw)
has "$args" "camera_info:=/cam0/camera_info" "workers.launch camera_info"
has "$args" "/keyframe_selector_node " "workers.launch selector executable"
args=$(roslaunch --args /depth_worker_1 wild_mvs workers.launch)
has "$args" "keyframes:=/keyframe_selector/keyframes" "workers.launch worker keyframes"
has "$args" "/depth_worker_node " "workers.launch worker executable"
has "$args" "get_keyframe:=/keyframe_selector/get_keyframe" "workers.launch worker get_keyframe"
args=$(roslaunch --args /fusion_node wild_mvs workers.launch)
has "$args" "keyframe_index:=/keyframe_selector/keyframe_index" "workers.launch fusion keyframe_index"
params=$(roslaunch --dump-params wild_mvs workers.launch world_frame:=map)
# Each role loads its own config file: the selector's has the camera input
# and no matching, a worker's the matching and no camera input.
has "$params" "/keyframe_selector/pose_source: tf" "workers.launch selector config"
hasnt "$params" "/keyframe_selector/mvs/mpgc/" "workers.launch selector config"
has "$params" "/depth_worker_1/mvs/mpgc/window: 5" "workers.launch worker config"
hasnt "$params" "/depth_worker_1/pose_source" "workers.launch worker config"
params=$(roslaunch --dump-params wild_mvs depth_worker.launch index:=2 count:=3 world_frame:=odom)
has "$params" "/depth_worker_2/worker_count: 3" "depth_worker.launch count"
has "$params" "/depth_worker_2/world_frame: odom" "depth_worker.launch world_frame"
hasnt "$params" "/depth_worker_2/image_transport" "depth_worker.launch config"
echo "PASS: $n launch checks"
