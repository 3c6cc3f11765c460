#!/usr/bin/env bash
# Runs every test: installs what is missing (Debian 12 packages), builds,
# runs the unit, CLI and ROS tests with ctest, then the deterministic fuzz
# step of every reader (scripts/run_fuzz.sh: clang ASan/UBSan build in
# build-fuzz/; replays the committed corpus and regressions, then a fixed
# number of executions per harness with a fixed seed). WILD_MVS_SANITIZERS=1 also runs
# scripts/run_sanitizers.sh (ASan/UBSan build running every test again, and
# TSan on the parallel code); WILD_MVS_NO_FUZZ=1 skips the fuzz run.
# Usage: scripts/run_tests.sh
set -eo pipefail
source "$(dirname "$0")/common.sh"
bash "$WILD_MVS_ROOT/scripts/install_deps.sh" --extra
mkdir -p "$BUILD_DIR"
wild_mvs_build
cmake --build "$BUILD_DIR" -j"$JOBS" --target tests 2>/dev/null || true  # catkin test targets
ctest --test-dir "$BUILD_DIR" --output-on-failure -j"$JOBS"
hard=0
if [ -n "${WILD_MVS_SANITIZERS:-}" ]; then
  bash "$WILD_MVS_ROOT/scripts/run_sanitizers.sh" || hard=1
fi
if [ -z "${WILD_MVS_NO_FUZZ:-}" ]; then
  bash "$WILD_MVS_ROOT/scripts/run_fuzz.sh" || hard=1
fi
[ "$hard" = 0 ] || { echo "run_tests.sh: hardening checks failed" >&2; exit 1; }
