#!/usr/bin/env bash
# Runs every test: installs what is missing (Debian 12 packages), builds,
# runs the unit, CLI and ROS tests with ctest, then the deterministic fuzz
# step of every reader (scripts/run_fuzz.sh: clang ASan/UBSan build in
# build-fuzz/; replays the committed corpus and regressions, then a fixed
# number of executions per harness with a fixed seed), and the sanitizer
# step (scripts/run_sanitizers.sh: gcc ASan + UBSan build in build-asan/, ROS
# off, running the unit and CLI tests again). WILD_MVS_TSAN=1 adds the
# ThreadSanitizer run of the parallel code; WILD_MVS_NO_SANITIZERS=1 and
# WILD_MVS_NO_FUZZ=1 skip those steps.
# Usage: scripts/run_tests.sh
set -eo pipefail
source "$(dirname "$0")/common.sh"
bash "$WILD_MVS_ROOT/scripts/install_deps.sh" --extra
mkdir -p "$BUILD_DIR"
wild_mvs_build
cmake --build "$BUILD_DIR" -j"$JOBS" --target tests 2>/dev/null || true  # catkin test targets
ctest --test-dir "$BUILD_DIR" --output-on-failure -j"$JOBS"
hard=0
if [ -z "${WILD_MVS_NO_SANITIZERS:-}" ]; then
  tsan=()
  [ -n "${WILD_MVS_TSAN:-}" ] && tsan=(--tsan)
  bash "$WILD_MVS_ROOT/scripts/run_sanitizers.sh" "${tsan[@]}" || hard=1
fi
if [ -z "${WILD_MVS_NO_FUZZ:-}" ]; then
  bash "$WILD_MVS_ROOT/scripts/run_fuzz.sh" || hard=1
fi
[ "$hard" = 0 ] || { echo "run_tests.sh: hardening checks failed" >&2; exit 1; }
