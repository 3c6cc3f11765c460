# Shared by the scripts: a sane PATH for Debian's ROS, the build folder, and
# configure/build helpers. Source it; works from any current directory.
# shellcheck shell=bash
WILD_MVS_ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
export PATH=/usr/local/sbin:/usr/local/bin:/usr/sbin:/usr/bin:/sbin:/bin  # no pyenv python
export ROS_HOSTNAME=${ROS_HOSTNAME:-localhost}
export ROS_MASTER_URI=${ROS_MASTER_URI:-http://localhost:11311}
BUILD_DIR="${BUILD_DIR:-$WILD_MVS_ROOT/build}"
JOBS="${JOBS:-$(nproc)}"

# The catkin devel space of $BUILD_DIR (setup.bash, lib/wild_mvs/<nodes>):
# <source>/devel for the default build folder <source>/build (rosrun skips
# everything under <package>/build/; see cmake/ros_setup.cmake), else
# $BUILD_DIR/devel; a configured build's CMakeCache.txt has the last word.
wild_mvs_devel_dir() {
  local d=""
  [ -f "$BUILD_DIR/CMakeCache.txt" ] &&
    d=$(sed -n 's/^CATKIN_DEVEL_PREFIX:[A-Z]*=//p' "$BUILD_DIR/CMakeCache.txt")
  if [ -z "$d" ]; then
    if [ "$(realpath -m "$BUILD_DIR")" = "$WILD_MVS_ROOT/build" ]; then
      d="$WILD_MVS_ROOT/devel"
    else
      d="$BUILD_DIR/devel"
    fi
  fi
  echo "$d"
}

# ccache, when installed, makes rebuilds and other checkouts cheap.
CCACHE_ARGS=()
if command -v ccache >/dev/null 2>&1; then
  CCACHE_ARGS=(-DCMAKE_C_COMPILER_LAUNCHER=ccache -DCMAKE_CXX_COMPILER_LAUNCHER=ccache)
fi

# The scripts' builds are unity builds (CMake joins up to 8 sources of a
# target into one compile): half the compile time of a fresh build. The
# sanitizer build below compiles every source on its own, so both ways are
# built and tested.
wild_mvs_configure() {  # extra cmake args...
  cmake -S "$WILD_MVS_ROOT" -B "$BUILD_DIR" -DCMAKE_BUILD_TYPE=Release -DCMAKE_UNITY_BUILD=ON "${CCACHE_ARGS[@]}" \
    -DPYTHON_EXECUTABLE=/usr/bin/python3 -DPython3_EXECUTABLE=/usr/bin/python3 "$@" >"$BUILD_DIR.cmake.log" 2>&1 \
    || { cat "$BUILD_DIR.cmake.log"; return 1; }
}

wild_mvs_build() {  # extra cmake args...: configure, then build everything
  wild_mvs_configure "$@" && cmake --build "$BUILD_DIR" -j"$JOBS"
}

# What the demo runs: the tool, the two nodes, the bag converter and the
# messages (finish_when_idle.py calls the fusion node's save service).
WILD_MVS_DEMO_TARGETS=(wild_mvs depth_node fusion_node wild_mvs_to_bag wild_mvs_generate_messages)

# The clang AddressSanitizer + UndefinedBehaviorSanitizer build (default
# build-fuzz/): library, tool and tests sanitized, the library also with
# libFuzzer coverage (cmake/fuzz.cmake). scripts/run_sanitizers.sh runs the
# tests of this build and scripts/run_fuzz.sh its fuzz harnesses; both
# configure it through this function, identically, so the second one
# rebuilds nothing. WILD_MVS_FUZZ_ROS=ON|OFF: the ROS message harness
# (default: when catkin is installed).
wild_mvs_configure_sanitized() {  # build-dir
  local dir="$1" ros="${WILD_MVS_FUZZ_ROS:-}"
  if [ -z "$ros" ]; then
    ros=OFF
    [ -f /usr/share/catkin/cmake/catkinConfig.cmake ] && ros=ON
  fi
  mkdir -p "$dir"
  cmake -S "$WILD_MVS_ROOT" -B "$dir" -DCMAKE_CXX_COMPILER=clang++ \
    -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1 -g" \
    -DWILD_MVS_FUZZ=ON -DWILD_MVS_WITH_ROS="$ros" -DWILD_MVS_BUILD_TESTS=ON \
    -DPYTHON_EXECUTABLE=/usr/bin/python3 -DPython3_EXECUTABLE=/usr/bin/python3 \
    "${CCACHE_ARGS[@]}" >"$dir/cmake.log" 2>&1 || { cat "$dir/cmake.log"; return 1; }
}
