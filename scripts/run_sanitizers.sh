#!/usr/bin/env bash
# Sanitizer builds and runs (no findings allowed):
#  1. ASan + UBSan (default; scripts/run_tests.sh runs it): the clang build
#     that the fuzz harnesses use too (build-fuzz/, configured by
#     wild_mvs_configure_sanitized in scripts/common.sh: every target built
#     with -fsanitize=address,undefined -fno-sanitize-recover=undefined).
#     Runs every ROS-free unit and CLI test with ctest (ASAN_TESTS /
#     ASAN_EXCLUDE select; the ROS tests are left out: roscpp is not
#     sanitized), among them the end-to-end runs on small rendered scenes:
#     test_mvs_end_to_end (ReconstructView, 1 and 2 threads) and
#     test_cli_reconstruct (`wild_mvs reconstruct` sparse -> depth -> fuse
#     -> mesh, resumed, bad output folders). Leaks are findings too
#     (LeakSanitizer; test/sanitizers/lsan.supp lists third-party ones).
#     A gcc build of the same: cmake -DWILD_MVS_SANITIZE=ON.
#  2. ThreadSanitizer (opt-in, --tsan or --tsan-only; WILD_MVS_TSAN=1 for
#     scripts/run_tests.sh): build-tsan/, the parallel code: the fusion
#     tests and the MVS end-to-end test that runs ReconstructView with 2
#     threads (TSAN_TESTS, TSAN_EXCLUDE). Runs under `setarch -R` when
#     available (TSan fails on some kernels with "unexpected memory mapping"
#     when ASLR is on).
# Usage: scripts/run_sanitizers.sh [--tsan|--tsan-only]
# Environment: JOBS (default: cores), FUZZ_BUILD_DIR (the ASan build,
#   default build-fuzz), TSAN_BUILD_DIR, ASAN_TESTS (ctest -R regex, default
#   all), ASAN_EXCLUDE (ctest -E regex, default the ROS tests, the
#   repository checks, which compile nothing, and the photos pipeline, which
#   mostly runs colmap; its workspace writer is test_io_colmap_dense), TSAN_TESTS
#   (ctest -R regex), TSAN_EXCLUDE (ctest -E regex). A gtest case is the
#   ctest test <executable>.<Suite>.<Case> (<executable>_NOT_BUILT before
#   the build; gtest_discover_tests).
set -eo pipefail
ROOT="$(cd "$(dirname "$0")/.." && pwd)"
source "$ROOT/scripts/common.sh"
ASAN_BUILD_DIR="${FUZZ_BUILD_DIR:-$ROOT/build-fuzz}"
TSAN_BUILD_DIR="${TSAN_BUILD_DIR:-$ROOT/build-tsan}"
ASAN_TESTS="${ASAN_TESTS:-.}"
ASAN_EXCLUDE="${ASAN_EXCLUDE:-^(_ctest_|ros_|repo_|test_colmap_photos|config_files$)}"
TSAN_TESTS="${TSAN_TESTS:-^test_(fusion|fusion_synthetic|mvs_end_to_end)(\.|_NOT_BUILT$)}"
TSAN_EXCLUDE="${TSAN_EXCLUDE:-\.MvsEndToEnd\.(Ablations|VaryingLightingAndOccluder)$}"
do_asan=1 do_tsan=0
case "${1:-}" in
  --tsan) do_tsan=1 ;;
  --tsan-only) do_asan=0 do_tsan=1 ;;
  --asan-only | "") ;;
  *) echo "run_sanitizers.sh: unknown option '$1'" >&2; exit 2 ;;
esac
SUPP="$ROOT/test/sanitizers"
configure() {  # build-dir cmake-args...
  local dir="$1"
  shift
  mkdir -p "$dir"
  cmake -S "$ROOT" -B "$dir" -DWILD_MVS_WITH_ROS=OFF \
    -DPYTHON_EXECUTABLE=/usr/bin/python3 -DPython3_EXECUTABLE=/usr/bin/python3 \
    "${CCACHE_ARGS[@]}" "$@" >"$dir/cmake.log" 2>&1 || { cat "$dir/cmake.log"; return 1; }
}
# The build targets of the tests selected by ctest arguments (cli_* tests
# run the tool; a gtest case <executable>.<Suite>.<Case>, or the placeholder
# <executable>_NOT_BUILT of a test binary not built yet, names its binary).
test_targets() {  # build-dir ctest-args...
  local dir="$1"
  shift
  ctest --test-dir "$dir" -N "$@" | sed -n 's/^ *Test *#[0-9]*: *//p' |
    sed 's/^cli_.*/wild_mvs/; s/_NOT_BUILT$//; s/\..*$//' | sort -u | tr '\n' ' '
}
build() {  # build-dir targets...
  local dir="$1"
  shift
  # shellcheck disable=SC2068
  cmake --build "$dir" -j"$JOBS" --target $@ >"$dir/build.log" 2>&1 ||
    { tail -60 "$dir/build.log"; return 1; }
  # Warnings fail nothing here: the normal (gcc) build is the one kept
  # warning-free; these builds only show them.
  if grep -E 'warning:' "$dir/build.log"; then
    echo "run_sanitizers.sh: build warnings in the sanitizer build (above)" >&2
  fi
}

status=0
if [ "$do_asan" = 1 ]; then
  echo "run_sanitizers.sh: ASan + UBSan build in $ASAN_BUILD_DIR"
  start=$(date +%s)
  wild_mvs_configure_sanitized "$ASAN_BUILD_DIR"
  sel=(-R "$ASAN_TESTS")
  [ -n "$ASAN_EXCLUDE" ] && sel+=(-E "$ASAN_EXCLUDE")
  build "$ASAN_BUILD_DIR" "$(test_targets "$ASAN_BUILD_DIR" "${sel[@]}")" wild_mvs
  built=$(date +%s)
  # Leaks are findings too; the suppressions cover third-party libraries only.
  export ASAN_OPTIONS="detect_leaks=1:abort_on_error=0:strict_string_checks=1:detect_stack_use_after_return=1:check_initialization_order=1"
  export LSAN_OPTIONS="suppressions=$SUPP/lsan.supp:print_suppressions=0"
  export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1"
  if ctest --test-dir "$ASAN_BUILD_DIR" --output-on-failure -j"$JOBS" \
    "${sel[@]}" 2>&1 | tee "$ASAN_BUILD_DIR/ctest.log"; then
    :
  else
    status=1
  fi
  # Findings in child processes (the CLI run by a test) show in the log too.
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
  tsel=(-R "$TSAN_TESTS")
  [ -n "$TSAN_EXCLUDE" ] && tsel+=(-E "$TSAN_EXCLUDE")
  targets="$(test_targets "$TSAN_BUILD_DIR" "${tsel[@]}")"
  if [ -z "$targets" ]; then
    echo "run_sanitizers.sh: no tests match $TSAN_TESTS"
    status=1
  else
    build "$TSAN_BUILD_DIR" "$targets"
    built=$(date +%s)
    export TSAN_OPTIONS="halt_on_error=1:second_deadlock_stack=1:suppressions=$SUPP/tsan.supp"
    norandom=()
    setarch -R true 2>/dev/null && norandom=(setarch -R)
    # ctest -j1: the parallel tests use every core themselves.
    if "${norandom[@]}" ctest --test-dir "$TSAN_BUILD_DIR" --output-on-failure \
      "${tsel[@]}" 2>&1 | tee "$TSAN_BUILD_DIR/ctest.log"; then
      :
    else
      status=1
    fi
    if grep -Eq 'WARNING: ThreadSanitizer|FATAL: ThreadSanitizer' "$TSAN_BUILD_DIR/ctest.log"; then
      echo "run_sanitizers.sh: ThreadSanitizer findings or failure (see $TSAN_BUILD_DIR/ctest.log)"
      status=1
    fi
    unset TSAN_OPTIONS
    echo "run_sanitizers.sh: TSan build $((built - start)) s, tests $(($(date +%s) - built)) s"
  fi
fi
[ "$status" = 0 ] && echo "run_sanitizers.sh: no findings"
exit "$status"
