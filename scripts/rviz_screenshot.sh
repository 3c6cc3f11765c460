#!/usr/bin/env bash
# Screenshot of rviz watching the ROS pipeline, under Xvfb (no display
# needed): plays BAG through depth_node + fusion_node with rviz, waits until
# VIEWS depth views are fused (diagnostics) and the cloud was published,
# then saves the screen to OUT.png. Own ROS master on a free port.
#   scripts/rviz_screenshot.sh BAG OUT.png VIEWS [roslaunch args]
# e.g. (the bundled sample; docs/rviz.png):
#   scripts/ros_reconstruct.sh data/templeSparseRing /tmp/temple_ros
#   scripts/rviz_screenshot.sh /tmp/temple_ros/input.bag docs/rviz.png 16 \
#     rviz_config:=$PWD/config/wild_mvs_sample.rviz
# Needs rviz, xvfb and imagemagick (apt-get install rviz xvfb imagemagick).
set -eo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/common.sh"
BAG=$(realpath "${1:?usage: rviz_screenshot.sh BAG OUT.png VIEWS [roslaunch args]}")
OUT=$(realpath -m "${2:?usage}")
VIEWS=${3:?usage}
shift 3
for t in rviz Xvfb /usr/bin/import; do
  command -v "$t" >/dev/null || { echo "rviz_screenshot.sh: $t missing (apt-get install rviz xvfb imagemagick)" >&2; exit 1; }
done
set +u
source "$(wild_mvs_devel_dir)/setup.bash"
PORT=$(/usr/bin/python3 -c 'import socket; s=socket.socket(); s.bind(("",0)); print(s.getsockname()[1])')
export ROS_MASTER_URI=http://localhost:$PORT
DISP=$((90 + RANDOM % 100))
Xvfb ":$DISP" -screen 0 1280x800x24 >/dev/null 2>&1 &
xvfb=$!
export DISPLAY=":$DISP"
TMP=$(mktemp -d)
roslaunch -p "$PORT" wild_mvs reconstruct_bag.launch bag:="$BAG" output:="$TMP/cloud.ply" \
  finish:=false rviz:=true config:="$WILD_MVS_ROOT/config/sample.yaml" "$@" >"$TMP/roslaunch.log" 2>&1 &
launch=$!
trap 'kill -INT $launch 2>/dev/null; sleep 3; kill $xvfb 2>/dev/null; rm -rf "$TMP"' EXIT
/usr/bin/python3 - "$VIEWS" <<'PY'
import sys, time, rospy
from diagnostic_msgs.msg import DiagnosticArray
want, fused = int(sys.argv[1]), [0]
def on(msg):
    for st in msg.status:
        if st.name.startswith("fusion_node"):
            for kv in st.values:
                if kv.key == "views fused":
                    fused[0] = int(kv.value)
for _ in range(120):
    try:
        rospy.init_node("wait_fused", anonymous=True)
        break
    except Exception:
        time.sleep(0.5)
rospy.Subscriber("/diagnostics", DiagnosticArray, on)
end = time.time() + 1800
while fused[0] < want and time.time() < end and not rospy.is_shutdown():
    time.sleep(1)
print("rviz_screenshot: %d views fused" % fused[0])
PY
sleep 8  # the cloud after the last view (publish_period) and a few rviz frames
mkdir -p "$(dirname "$OUT")"
/usr/bin/import -display ":$DISP" -window root "$OUT"
echo "rviz_screenshot: saved $OUT"
