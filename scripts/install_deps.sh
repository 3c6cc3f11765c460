#!/usr/bin/env bash
# Installs what wild_mvs needs on Debian 12 (Debian's own ROS 1 packages), only when missing.
# Usage: scripts/install_deps.sh [--no-ros] [--tests] [--extra] [--bench]
#   (none)     what the tool and the ROS nodes need to build and run
#   --no-ros   only the ROS-free core, I/O and CLI dependencies
#   --tests    also what the tests build with (GoogleTest, rostest,
#              depth_image_proc and tf2_tools for the standard-tools tests)
#   --extra    also fuzzing/sanitizer (clang), rviz/Xvfb screenshot tools and colmap (tests of the photos pipeline)
#   --bench    also what bench/run_all.sh needs (time, bc, matplotlib)
set -eo pipefail
export DEBIAN_FRONTEND=noninteractive
CORE="build-essential cmake pkg-config git libeigen3-dev libopencv-dev \
 libpcl-dev libyaml-cpp-dev libopenexr-dev libhwy-dev"
ROS="catkin ros-message-generation ros-message-runtime \
 libroscpp-dev libstd-msgs-dev libsensor-msgs-dev libgeometry-msgs-dev libnav-msgs-dev libdynamic-reconfigure-config-init-mutex-dev python3-dynamic-reconfigure \
 ros-std-msgs ros-sensor-msgs ros-geometry-msgs \
 libcv-bridge-dev libimage-transport-dev libtf2-ros-dev libtf2-eigen-dev libtf2-geometry-msgs-dev \
 libpcl-conversions-dev libpcl-ros-dev librosbag-dev \
 libnodelet-dev libnodeletlib-tools libmessage-filters-dev libimage-geometry-dev \
 libdiagnostic-msgs-dev ros-diagnostic-msgs libdiagnostic-updater-dev \
 libvisualization-msgs-dev ros-visualization-msgs libstd-srvs-dev ros-std-srvs \
 ros-core rosbash python3-rospy python3-rosbag python3-std-msgs python3-sensor-msgs \
 python3-geometry-msgs python3-std-srvs python3-diagnostic-msgs python3-numpy \
 python3-roslaunch pluginlib-dev python3-nav-msgs python3-tf2-ros python3-yaml"
TESTS="libgtest-dev libgmock-dev"
ROS_TESTS="librostest-dev python3-rostest libdepth-image-proc-dev tf2-tools"
EXTRA="clang libclang-rt-14-dev libfuzzer-14-dev rviz xvfb xauth colmap"
BENCH="time bc python3-matplotlib"
want="$CORE"
for a in "$@"; do
  case "$a" in
    --no-ros) NO_ROS=1 ;;
    --tests) TESTS_TOO=1 ;;
    --extra) want="$want $EXTRA" ;;
    --bench) want="$want $BENCH" ;;
    *) echo "install_deps.sh: unknown option '$a'" >&2; exit 2 ;;
  esac
done
[ -z "${TESTS_TOO:-}" ] || want="$want $TESTS"
[ -n "${NO_ROS:-}" ] || want="$want $ROS"
[ -n "${NO_ROS:-}" ] || [ -z "${TESTS_TOO:-}" ] || want="$want $ROS_TESTS"
missing=""
for p in $want; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing="$missing $p"
done
if [ -n "$missing" ]; then
  echo "install_deps.sh: installing:$missing"
  SUDO=""; [ "$(id -u)" = 0 ] || SUDO=sudo
  $SUDO apt-get -o DPkg::Lock::Timeout=900 update -qq
  $SUDO apt-get -o DPkg::Lock::Timeout=900 install -y -qq --no-install-recommends $missing >/dev/null
fi
