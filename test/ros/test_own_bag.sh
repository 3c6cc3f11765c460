#!/usr/bin/env bash
# reconstruct_bag.launch on "a user's own bag": the bundled sample written
# as a bag (wild_mvs_to_bag), its topics renamed (/cam0/color/image_raw,
# /cam0/color/camera_info), played with the launch's topic arguments; the
# launch must end by itself (the finisher reads only /diagnostics, on wall
# time, with use_sim_time) and save a cloud. Then once more as nodelets
# without sim time.
#   test/ros/test_own_bag.sh DEVEL_DIR SOURCE_DIR
set -eo pipefail
DEVEL=${1:?usage: test_own_bag.sh DEVEL_DIR SOURCE_DIR}
SRC=${2:?usage}
HERE=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
# shellcheck source=/dev/null
source "$DEVEL/setup.bash"
source "$HERE/ros_space_lib.sh"
cd "$TMP"
"$DEVEL/lib/wild_mvs/wild_mvs_to_bag" "$SRC/data/templeSparseRing" "$TMP/sample.bag" \
  --rate 4 --max-image-size 160 >"$TMP/to_bag.log" 2>&1 || fail "wild_mvs_to_bag"
/usr/bin/python3 - "$TMP/sample.bag" "$TMP/own.bag" <<'PY'
import sys, rosbag
names = {"/camera/image_raw": "/cam0/color/image_raw",
         "/camera/camera_info": "/cam0/color/camera_info"}
with rosbag.Bag(sys.argv[2], "w") as out:
    for topic, msg, t in rosbag.Bag(sys.argv[1]).read_messages():
        out.write(names.get(topic, topic), msg, t)
PY
port=$(/usr/bin/python3 -c 'import socket; s=socket.socket(); s.bind(("",0)); print(s.getsockname()[1])')
export ROS_MASTER_URI=http://localhost:$port
run() {  # name, roslaunch args...
  local name=$1 rc=0; shift
  timeout 240 roslaunch -p "$port" wild_mvs reconstruct_bag.launch bag:="$TMP/own.bag" \
    output:="$TMP/$name.ply" image:=/cam0/color/image_raw \
    config:="$SRC/config/sample.yaml" "$@" >"$TMP/$name.log" 2>&1 || rc=$?
  [ "$rc" = 0 ] || fail "$name: roslaunch exit $rc (124: did not end by itself)"
  # (Not anchored: the nodes share roslaunch's output, and another node's
  # line can end on the same line.)
  grep -q "wild_mvs: saved [1-9][0-9]* points" "$TMP/$name.log" || fail "$name: no cloud saved"
  [ -s "$TMP/$name.ply" ] || fail "$name: no $name.ply"
  echo "ok: $name: $(grep -ho 'wild_mvs: saved.*' "$TMP/$name.log")"
}
run sim_time
run nodelets nodelets:=true use_sim_time:=false
echo "PASS: own bag with renamed topics"
