#!/usr/bin/env bash
# Sanitizer builds and runs (no findings allowed):
#  1. build-asan/: the whole project with AddressSanitizer + UBSan
#     (-DWILD_MVS_SANITIZE=ON, ROS off); runs every unit and CLI test with
#     ctest, among them the end-to-end `wild_mvs reconstruct` of a small
#     synthetic scene (test_end_to_end_synthetic) when it exists.
#  2. build-tsan/: ThreadSanitizer build of the tests of the parallel code
#     (depth maps, region growing, fusion, thread pool), run under TSan.
# Usage: scripts/run_sanitizers.sh [--asan-only|--tsan-only]
# Environment: JOBS (default: cores), ASAN_BUILD_DIR, TSAN_BUILD_DIR,
#   TSAN_TESTS (ctest regex of the TSan tests).
set -eo pipefail
ROOT="$(cd "$(dirname "$0")/.." && pwd)"
source "$ROOT/scripts/common.sh"
ASAN_BUILD_DIR="${ASAN_BUILD_DIR:-$ROOT/build-asan}"
TSAN_BUILD_DIR="${TSAN_BUILD_DIR:-$ROOT/build-tsan}"
TSAN_TESTS="${TSAN_TESTS:-^test_(thread_pool|fusion|region_growing|reconstruct_view|depth_sweep|parallel)}"
do_asan=1 do_tsan=1
case "${1:-}" in
  --asan-only) do_tsan=0 ;;
  --tsan-only) do_asan=0 ;;
  "") ;;
  *) echo "run_sanitizers.sh: unknown option '$1'" >&2; exit 2 ;;
esac
SUPP="$ROOT/test/sanitizers"
launcher=()
command -v ccache >/dev/null && launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache)
configure() {  # build-dir cmake-args...
  local dir="$1"
  shift
  mkdir -p "$dir"
  cmake -S "$ROOT" -B "$dir" -DWILD_MVS_WITH_ROS=OFF \
    -DPYTHON_EXECUTABLE=/usr/bin/python3 -DPython3_EXECUTABLE=/usr/bin/python3 \
    "${launcher[@]}" "$@" >"$dir/cmake.log" 2>&1 || { cat "$dir/cmake.log"; return 1; }
}

status=0
if [ "$do_asan" = 1 ]; then
  echo "run_sanitizers.sh: AddressSanitizer + UBSan build in $ASAN_BUILD_DIR"
  start=$(date +%s)
  configure "$ASAN_BUILD_DIR" -DWILD_MVS_SANITIZE=ON \
    -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1 -g1"
  cmake --build "$ASAN_BUILD_DIR" -j"$JOBS"
  built=$(date +%s)
  # Leaks are findings too; the suppressions cover third-party libraries only.
  export ASAN_OPTIONS="detect_leaks=1:abort_on_error=0:strict_string_checks=1:detect_stack_use_after_return=1:check_initialization_order=1"
  export LSAN_OPTIONS="suppressions=$SUPP/lsan.supp:print_suppressions=0"
  export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1"
  if ctest --test-dir "$ASAN_BUILD_DIR" --output-on-failure -j"$JOBS" \
    2>&1 | tee "$ASAN_BUILD_DIR/ctest.log"; then
    :
  else
    status=1
  fi
  if grep -Eq 'ERROR: (Address|Leak)Sanitizer|runtime error:' "$ASAN_BUILD_DIR/ctest.log"; then
    echo "run_sanitizers.sh: sanitizer findings (see $ASAN_BUILD_DIR/ctest.log)"
    status=1
  fi
  unset ASAN_OPTIONS LSAN_OPTIONS UBSAN_OPTIONS
  echo "run_sanitizers.sh: ASan/UBSan build $((built - start)) s, tests $(($(date +%s) - built)) s"
fi

if [ "$do_tsan" = 1 ]; then
  echo "run_sanitizers.sh: ThreadSanitizer build in $TSAN_BUILD_DIR ($TSAN_TESTS)"
  start=$(date +%s)
  configure "$TSAN_BUILD_DIR" -DCMAKE_BUILD_TYPE=RelWithDebInfo \
    -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1 -g1" \
    -DCMAKE_CXX_FLAGS="-fsanitize=thread -fno-omit-frame-pointer" \
    -DCMAKE_EXE_LINKER_FLAGS="-fsanitize=thread" \
    -DCMAKE_SHARED_LINKER_FLAGS="-fsanitize=thread"
  targets=$(ctest --test-dir "$TSAN_BUILD_DIR" -N -R "$TSAN_TESTS" |
    sed -n 's/^ *Test *#[0-9]*: *//p')
  if [ -z "$targets" ]; then
    echo "run_sanitizers.sh: no tests match $TSAN_TESTS"
  else
    # shellcheck disable=SC2086
    cmake --build "$TSAN_BUILD_DIR" -j"$JOBS" --target $targets
    built=$(date +%s)
    export TSAN_OPTIONS="halt_on_error=1:second_deadlock_stack=1:suppressions=$SUPP/tsan.supp"
    # ctest -j1: TSan tests use every core themselves.
    if ctest --test-dir "$TSAN_BUILD_DIR" --output-on-failure -R "$TSAN_TESTS" \
      2>&1 | tee "$TSAN_BUILD_DIR/ctest.log"; then
      :
    else
      status=1
    fi
    if grep -q 'WARNING: ThreadSanitizer' "$TSAN_BUILD_DIR/ctest.log"; then
      echo "run_sanitizers.sh: ThreadSanitizer findings (see $TSAN_BUILD_DIR/ctest.log)"
      status=1
    fi
    unset TSAN_OPTIONS
    echo "run_sanitizers.sh: TSan build $((built - start)) s, tests $(($(date +%s) - built)) s"
  fi
fi
[ "$status" = 0 ] && echo "run_sanitizers.sh: no findings"
exit "$status"
