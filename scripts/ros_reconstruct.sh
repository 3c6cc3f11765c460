#!/usr/bin/env bash
# The ROS pipeline end to end on a dataset: dataset -> bag (wild_mvs to-bag)
# -> rosbag play -> depth_node -> fusion_node -> saved PLY, with its own ROS
# master on a free port (no running roscore needed). Works from any current
# directory; ends with one summary line (keyframes, depth maps, cloud points,
# saved path, time) and each node's peak memory.
#
#   scripts/ros_reconstruct.sh DATASET OUT_DIR [RATE_HZ] [--max-image-size PX]
#                              [roslaunch args, e.g. rviz:=true nodelets:=true]
#
# RATE_HZ: frames per second of the bag (default 2). --max-image-size PX
# (or the launch argument max_image_size:=PX) writes the bag at that size
# (longest side; default 320, 0 = as the dataset).
# Output: OUT_DIR/cloud.ply, OUT_DIR/input.bag, OUT_DIR/roslaunch.log.
# e.g. scripts/ros_reconstruct.sh data/templeSparseRing /tmp/temple_ros
set -eo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/common.sh"
usage="usage: ros_reconstruct.sh DATASET OUT_DIR [RATE_HZ] [--max-image-size PX] [roslaunch args]"
DATASET=${1:?$usage}
OUT=${2:?$usage}
shift 2
RATE=2
SIZE=320
if [[ "${1:-}" =~ ^[0-9.]+$ ]]; then RATE=$1; shift; fi
LAUNCH_ARGS=()
while [ $# -gt 0 ]; do
  case "$1" in
    --max-image-size) SIZE=${2:?--max-image-size needs a value}; shift ;;
    --rate) RATE=${2:?--rate needs a value}; shift ;;
    max_image_size:=*) SIZE=${1#max_image_size:=}; LAUNCH_ARGS+=("$1") ;;  # bag size too
    *) LAUNCH_ARGS+=("$1") ;;
  esac
  shift
done
[ -d "$DATASET" ] || { echo "ros_reconstruct.sh: no dataset folder '$DATASET'" >&2; exit 2; }
DATASET=$(cd "$DATASET" && pwd)  # roslaunch runs nodes in ~/.ros: absolute paths
mkdir -p "$OUT"
OUT=$(cd "$OUT" && pwd)
DEVEL=$(wild_mvs_devel_dir)
LIB="$DEVEL/lib/wild_mvs"
[ -x "$LIB/depth_node" ] && [ -x "$LIB/wild_mvs_to_bag" ] ||
  { echo "ros_reconstruct.sh: no ROS build in $BUILD_DIR (devel space $DEVEL; run scripts/run_demo.sh or wild_mvs_build)" >&2; exit 1; }
set +u
source "$DEVEL/setup.bash"
PORT=$(/usr/bin/python3 -c 'import socket; s=socket.socket(); s.bind(("",0)); print(s.getsockname()[1])')
export ROS_MASTER_URI=http://localhost:$PORT
export ROS_LOG_DIR="$OUT/ros_log"

start=$(date +%s.%N)
size_args=()
[ "$SIZE" = 0 ] || size_args=(--max-image-size "$SIZE")
"$LIB/wild_mvs_to_bag" "$DATASET" "$OUT/input.bag" --rate "$RATE" "${size_args[@]}"
rc=0
# config/sample.yaml: the small-scene overrides (every frame of the bundled
# sample's short arc is a keyframe); a later config:=... argument wins.
roslaunch -p "$PORT" wild_mvs reconstruct_bag.launch bag:="$OUT/input.bag" \
  output:="$OUT/cloud.ply" config:="$WILD_MVS_ROOT/config/sample.yaml" "${LAUNCH_ARGS[@]}" >"$OUT/roslaunch.log" 2>&1 || rc=$?
end=$(date +%s.%N)
grep -E "keyframe [0-9]+ \(rev|ERROR|FATAL" "$OUT/roslaunch.log" | sed 's/^/  /' || true
seconds=$(/usr/bin/python3 -c "print(round($end-$start,1))")
saved=$(grep -ho "wild_mvs: saved.*" "$OUT/roslaunch.log" | tail -1)
depth=$(grep -ho "depth node: .*" "$OUT/roslaunch.log" | tail -1)
if [ "$rc" != 0 ] || [ ! -s "$OUT/cloud.ply" ] || [ -z "$saved" ]; then
  echo "ros_reconstruct.sh: FAILED (roslaunch exit $rc, no saved cloud): see $OUT/roslaunch.log" >&2
  tail -20 "$OUT/roslaunch.log" >&2
  exit 1
fi
points=$(sed -n 's/^wild_mvs: saved \([0-9]*\) points.*/\1/p' <<<"$saved")
keyframes=$(sed -n 's/.* \([0-9]*\) keyframes, .*/\1/p' <<<"$depth")
maps=$(sed -n 's/.* \([0-9]*\) depth maps.*/\1/p' <<<"$depth")
dropped=$(sed -n 's/.* \([0-9]*\) frames dropped.*/\1/p' <<<"$depth")
evicted=$(sed -n 's/.* \([0-9]*\) keyframes evicted.*/\1/p' <<<"$depth")
grep -h "peak RSS" "$OUT/roslaunch.log" | sed 's/^/  /' || true
echo "ros_reconstruct: $(basename "$DATASET"): ${keyframes:-?} keyframes, ${maps:-?} depth maps, ${points:-?} cloud points, ${dropped:-?} frames dropped, ${evicted:-?} keyframes evicted before a depth map; saved $OUT/cloud.ply; ${seconds} s (bag, nodes, save)"
