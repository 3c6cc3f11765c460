#!/usr/bin/env bash
# The ROS pipeline end to end on a dataset: dataset -> bag (wild_mvs to-bag)
# -> rosbag play -> depth_node -> fusion_node -> saved PLY, with its own ROS
# master on a free port. Prints the wall time and each node's peak memory.
#   scripts/ros_reconstruct.sh DATASET OUT_DIR [RATE_HZ] [extra roslaunch args...]
# e.g. scripts/ros_reconstruct.sh data/templeSparseRing /tmp/temple_ros 2 max_image_size:=320
set -eo pipefail
source "$(dirname "$0")/common.sh"
DATASET=${1:?usage: ros_reconstruct.sh DATASET OUT_DIR [RATE_HZ] [roslaunch args]}
OUT=${2:?usage: ros_reconstruct.sh DATASET OUT_DIR [RATE_HZ] [roslaunch args]}
RATE=${3:-2}
shift 3 || shift $#
mkdir -p "$OUT"
set +u
source "$BUILD_DIR/devel/setup.bash"
PORT=$(python3 -c 'import socket; s=socket.socket(); s.bind(("",0)); print(s.getsockname()[1])')
export ROS_MASTER_URI=http://localhost:$PORT
"$BUILD_DIR/devel/lib/wild_mvs/wild_mvs_to_bag" "$DATASET" "$OUT/input.bag" --rate "$RATE"
start=$(date +%s.%N)
roslaunch -p "$PORT" wild_mvs reconstruct_bag.launch bag:="$OUT/input.bag" \
  output:="$OUT/cloud.ply" "$@" 2>&1 | tee "$OUT/roslaunch.log" | \
  grep -E "wild_mvs: saved|keyframe [0-9]+ \(rev|ERROR|FATAL|peak" || true
end=$(date +%s.%N)
echo "end-to-end (bag play + depth + fusion + save): $(python3 -c "print(round($end-$start,1))") s"
grep -h "peak RSS" "$OUT/roslaunch.log" || true
ls -l "$OUT/cloud.ply"
