#!/usr/bin/env bash
# `cmake --install BUILD --prefix P` gives a working, self-contained install
# space: P/setup.bash, rosrun wild_mvs depth_node / fusion_node and the
# nodelet plugin from P (not from the source or devel space), the launch
# files, config, the CLI and the messages.
#   test/ros/test_install_space.sh BUILD_DIR [DEVEL_DIR]
set -eo pipefail
BUILD=${1:?usage: test_install_space.sh BUILD_DIR [DEVEL_DIR]}
HERE=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
PREFIX=$(mktemp -d)
trap 'rm -rf "$PREFIX"' EXIT
cmake --install "$BUILD" --prefix "$PREFIX" >"$PREFIX.install.log" 2>&1 ||
  { tail -30 "$PREFIX.install.log" >&2; rm -f "$PREFIX.install.log"; echo "FAIL: cmake --install" >&2; exit 1; }
rm -f "$PREFIX.install.log"
for f in setup.bash lib/wild_mvs/depth_node lib/wild_mvs/fusion_node \
         lib/wild_mvs/keyframe_selector_node lib/wild_mvs/depth_worker_node \
         share/wild_mvs/config/keyframe_selector.yaml \
         share/wild_mvs/config/depth_worker.yaml \
         lib/wild_mvs/wild_mvs_to_bag lib/wild_mvs/finish_when_idle.py \
         lib/libwild_mvs_ros.so bin/wild_mvs share/wild_mvs/package.xml \
         share/wild_mvs/nodelet_plugins.xml share/wild_mvs/launch/reconstruct_bag.launch \
         share/wild_mvs/config/depth_node.yaml share/wild_mvs/config/wild_mvs.rviz \
         include/wild_mvs/DepthView.h include/wild_mvs/SaveCloud.h; do
  [ -e "$PREFIX/$f" ] || { echo "FAIL: not installed: $f" >&2; exit 1; }
done
# Only the install space: a clean environment, not the devel space.
env -i HOME="$HOME" PATH=/usr/local/sbin:/usr/local/bin:/usr/sbin:/usr/bin:/sbin:/bin \
  bash -c '
set -eo pipefail
PREFIX=$1; HERE=$2
source "$PREFIX/setup.bash"
source "$HERE/ros_space_lib.sh"
trap "cleanup; rm -rf \"$PREFIX\"" EXIT
cd "$TMP"
[ "$(rospack find wild_mvs)" = "$PREFIX/share/wild_mvs" ] ||
  fail "rospack find wild_mvs = $(rospack find wild_mvs), not the install space"
where=$(rosrun --prefix echo wild_mvs depth_node </dev/null)
case "$where" in "$PREFIX"/*) ;; *) fail "rosrun wild_mvs depth_node runs $where, not from $PREFIX" ;; esac
echo "rosrun wild_mvs depth_node -> $where"
command -v wild_mvs | grep -q "^$PREFIX/bin/wild_mvs$" || fail "wild_mvs CLI not on PATH from $PREFIX"
wild_mvs --help >/dev/null || fail "wild_mvs --help"
wild_mvs to-bag --help | grep -q -- "--rate" || fail "wild_mvs to-bag does not find $PREFIX/lib/wild_mvs/wild_mvs_to_bag"
python3 -c "from wild_mvs.msg import DepthView; from wild_mvs.srv import SaveCloud" || fail "Python messages"

start_master
rosrun wild_mvs depth_node >"$TMP/depth_node.log" 2>&1 &
depth=$!; PIDS+=($depth)
wait_for_topic /depth_node/depth_view || fail "rosrun wild_mvs depth_node (install space): no /depth_node/depth_view"
rosnode list | grep -qx /depth_node || fail "rosnode list has no /depth_node"
stop "$depth" depth_node
echo "ok: rosrun wild_mvs depth_node from the install space"

rosrun nodelet nodelet standalone wild_mvs/FusionNodelet __name:=fusion >"$TMP/standalone.log" 2>&1 &
sa=$!; PIDS+=($sa)
wait_for_topic /fusion/cloud || fail "nodelet standalone wild_mvs/FusionNodelet (install space)"
stop "$sa" "nodelet standalone"
echo "ok: nodelet standalone wild_mvs/FusionNodelet from the install space"
roslaunch --nodes wild_mvs reconstruct_bag.launch bag:=/tmp/x.bag | grep -qx /depth_node ||
  fail "roslaunch wild_mvs reconstruct_bag.launch from the install space"
echo "PASS: install space $PREFIX"
' install_test "$PREFIX" "$HERE"
