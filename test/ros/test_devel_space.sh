#!/usr/bin/env bash
# The devel space works with the standard ROS tools from any directory:
# rosrun finds the node executables and finish_when_idle.py (rosrun skips
# <package>/build/, hence the devel space outside build/ for <source>/build),
# and the nodelets load standalone and into a manager.
#   test/ros/test_devel_space.sh BUILD_DIR DEVEL_DIR
set -eo pipefail
BUILD=${1:?usage: test_devel_space.sh BUILD_DIR DEVEL_DIR}
DEVEL=${2:?usage}
HERE=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
[ -f "$DEVEL/setup.bash" ] || { echo "FAIL: no $DEVEL/setup.bash" >&2; exit 1; }
# shellcheck source=/dev/null
source "$DEVEL/setup.bash"
source "$HERE/ros_space_lib.sh"
cd "$TMP"   # not the source or build folder

for exe in depth_node keyframe_selector_node depth_worker_node fusion_node \
  finish_when_idle.py; do
  # exactly one candidate (rosrun asks to pick one otherwise), in DEVEL
  rosrun --prefix 'echo' wild_mvs "$exe" >"$TMP/which.log" 2>&1 </dev/null ||
    fail "rosrun wild_mvs $exe: $(cat "$TMP/which.log")"
  where=$(cat "$TMP/which.log")
  if grep -q "non-unique" <<<"$where"; then
    # Other build folders of this checkout (build-fuzz/, build-tsan/ from
    # the sanitizer steps) hold copies of the Python scripts; rosrun lists
    # them too. Accept only those besides the devel space's own.
    others=$(grep -E '^[0-9]+\) ' <<<"$where" | sed 's/^[0-9]*) //' |
      grep -v "^$DEVEL/lib/wild_mvs/$exe\$" | grep -v "/build-[a-z]*/" || true)
    [ -z "$others" ] && grep -q "$DEVEL/lib/wild_mvs/$exe" <<<"$where" &&
      where="$DEVEL/lib/wild_mvs/$exe"
  fi
  [[ "$where" == "$DEVEL/lib/wild_mvs/$exe" ]] ||
    fail "rosrun wild_mvs $exe: expected $DEVEL/lib/wild_mvs/$exe, got: $where"
  echo "rosrun wild_mvs $exe -> $where"
done

start_master
rosrun wild_mvs depth_node >"$TMP/depth_node.log" 2>&1 &
depth=$!; PIDS+=($depth)
rosrun wild_mvs fusion_node >"$TMP/fusion_node.log" 2>&1 &
fusion=$!; PIDS+=($fusion)
wait_for_topic /depth_node/depth_view || fail "rosrun wild_mvs depth_node: no /depth_node/depth_view"
wait_for_topic /fusion_node/cloud || fail "rosrun wild_mvs fusion_node: no /fusion_node/cloud"
wait_for_service /fusion_node/save || fail "no /fusion_node/save service"
stop "$depth" depth_node
stop "$fusion" fusion_node
echo "ok: rosrun depth_node, fusion_node"

# nodelet standalone
rosrun nodelet nodelet standalone wild_mvs/DepthNodelet __name:=standalone_depth \
  >"$TMP/standalone.log" 2>&1 &
sa=$!; PIDS+=($sa)
wait_for_topic /standalone_depth/depth_view || fail "nodelet standalone wild_mvs/DepthNodelet"
stop "$sa" "nodelet standalone"
echo "ok: nodelet standalone wild_mvs/DepthNodelet"

# nodelet load into a manager
rosrun nodelet nodelet manager __name:=manager >"$TMP/manager.log" 2>&1 &
mgr=$!; PIDS+=($mgr)
rosrun nodelet nodelet load wild_mvs/FusionNodelet manager __name:=loaded_fusion \
  >"$TMP/load_fusion.log" 2>&1 &
lf=$!; PIDS+=($lf)
rosrun nodelet nodelet load wild_mvs/DepthNodelet manager __name:=loaded_depth \
  >"$TMP/load_depth.log" 2>&1 &
ld=$!; PIDS+=($ld)
wait_for_topic /loaded_depth/depth_view || fail "nodelet load wild_mvs/DepthNodelet manager"
wait_for_topic /loaded_fusion/cloud || fail "nodelet load wild_mvs/FusionNodelet manager"
# The selector and the worker nodelets: a selector publishes keyframes and
# no depth, a worker depth views.
rosrun nodelet nodelet load wild_mvs/KeyframeSelectorNodelet manager \
  __name:=loaded_selector >"$TMP/load_selector.log" 2>&1 &
lsel=$!; PIDS+=($lsel)
rosrun nodelet nodelet load wild_mvs/DepthWorkerNodelet manager \
  __name:=loaded_worker >"$TMP/load_worker.log" 2>&1 &
lw=$!; PIDS+=($lw)
wait_for_topic /loaded_selector/keyframes ||
  fail "nodelet load wild_mvs/KeyframeSelectorNodelet manager"
wait_for_topic /loaded_worker/depth_view ||
  fail "nodelet load wild_mvs/DepthWorkerNodelet manager"
! rostopic list | grep -qx /loaded_selector/depth_view ||
  fail "the keyframe selector advertises depth_view"
stop "$lw" "nodelet load (worker)"
stop "$lsel" "nodelet load (selector)"
stop "$ld" "nodelet load (depth)"
stop "$lf" "nodelet load (fusion)"
stop "$mgr" "nodelet manager"
echo "ok: nodelet load into a manager"
echo "PASS: devel space $DEVEL"
