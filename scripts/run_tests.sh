#!/usr/bin/env bash
# Runs every test: installs what is missing (Debian 12 packages), builds,
# runs the unit, CLI and ROS tests with ctest. Usage: scripts/run_tests.sh
set -eo pipefail
source "$(dirname "$0")/common.sh"
bash "$WILD_MVS_ROOT/scripts/install_deps.sh" --extra
mkdir -p "$BUILD_DIR"
wild_mvs_build
cmake --build "$BUILD_DIR" -j"$JOBS" --target tests 2>/dev/null || true  # catkin test targets
ctest --test-dir "$BUILD_DIR" --output-on-failure -j"$JOBS"
