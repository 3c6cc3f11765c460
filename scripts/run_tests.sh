#!/usr/bin/env bash
# Runs every test: installs what is missing (Debian 12 packages), builds,
# runs the unit, CLI and ROS tests with ctest, then the hardening steps on
# one clang AddressSanitizer + UndefinedBehaviorSanitizer build (build-fuzz/):
#  - scripts/run_sanitizers.sh: the ROS-free unit and CLI tests again in
#    that build (among them end-to-end reconstructions of rendered scenes),
#    no sanitizer report or leak allowed;
#  - scripts/run_fuzz.sh: every reader's fuzz harness, bounded: the
#    committed corpus and regressions replayed, then a fixed number of
#    executions per harness with a fixed seed.
# WILD_MVS_TSAN=1 adds the ThreadSanitizer run of the parallel depth and
# fusion code (build-tsan/, about 5 more minutes); WILD_MVS_NO_SANITIZERS=1
# and WILD_MVS_NO_FUZZ=1 skip those steps.
# Usage: scripts/run_tests.sh
set -eo pipefail
source "$(dirname "$0")/common.sh"
bash "$WILD_MVS_ROOT/scripts/install_deps.sh" --tests --extra
mkdir -p "$BUILD_DIR"
# Everything, with the tests and the ROS nodes (the demo's build folder
# may have been configured without them).
wild_mvs_build -DWILD_MVS_WITH_ROS=ON -DWILD_MVS_BUILD_TESTS=ON
cmake --build "$BUILD_DIR" -j"$JOBS" --target tests 2>/dev/null || true  # catkin test targets
ctest --test-dir "$BUILD_DIR" --output-on-failure -j"$JOBS" | tee "$BUILD_DIR/ctest.log"
# Tests that need ../shared skip (and show as skipped) without it; where it
# is present (CI has it), a skipped test is a failure.
if [ -d "$WILD_MVS_ROOT/../shared/datasets" ] && grep -q "(Skipped)" "$BUILD_DIR/ctest.log"; then
  echo "run_tests.sh: ../shared is present but tests were skipped:" >&2
  grep "(Skipped)" "$BUILD_DIR/ctest.log" >&2
  exit 1
fi
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
