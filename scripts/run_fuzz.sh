#!/usr/bin/env bash
# Builds the libFuzzer harnesses with clang (ASan + UBSan) in build-fuzz/ and
# runs each for a fixed time on a copy of its seed corpus.
#
# Usage: scripts/run_fuzz.sh [SECONDS] [HARNESS...]
#   SECONDS   per harness (default 30; $FUZZ_SECONDS also works)
#   HARNESS   names like fuzz_pfm (default: every harness built, i.e. each
#             test/fuzz/fuzz_*.cpp, and test/fuzz/ros/ when ROS is found)
# Environment: JOBS harnesses run in parallel (default: number of cores),
#   FUZZ_BUILD_DIR (default build-fuzz), FUZZ_SEED (libFuzzer -seed; default
#   1 so that a CI run is repeatable, 0 = random).
# Prints executions and findings per harness; exits non-zero when any
# harness found a crash, a sanitizer report, a leak, a timeout or an
# out-of-memory. Findings are kept in build-fuzz/findings/<harness>/; to
# reproduce one: build-fuzz/fuzz/<harness> <file>. A finding, once fixed,
# belongs in test/fuzz/corpus/<harness>/ and test/unit/test_fuzz_regressions.cpp.
set -eo pipefail
ROOT="$(cd "$(dirname "$0")/.." && pwd)"
FUZZ_BUILD_DIR="${FUZZ_BUILD_DIR:-$ROOT/build-fuzz}"
source "$ROOT/scripts/common.sh"
SECONDS_PER="${1:-${FUZZ_SECONDS:-30}}"
shift || true
case "$SECONDS_PER" in '' | *[!0-9]*)
  echo "run_fuzz.sh: SECONDS must be a whole number, got '$SECONDS_PER'" >&2
  exit 2 ;;
esac

command -v clang++ >/dev/null || {
  echo "run_fuzz.sh: clang++ not found (scripts/install_deps.sh --extra)" >&2
  exit 2
}
# The ROS harness (message decoding of the nodes) is built when catkin is
# installed; WILD_MVS_FUZZ_ROS=OFF skips it.
ros="${WILD_MVS_FUZZ_ROS:-}"
if [ -z "$ros" ]; then
  ros=OFF
  [ -f /usr/share/catkin/cmake/catkinConfig.cmake ] && ros=ON
fi
launcher=()
command -v ccache >/dev/null && launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache)
mkdir -p "$FUZZ_BUILD_DIR"
echo "run_fuzz.sh: building harnesses in $FUZZ_BUILD_DIR"
cmake -S "$ROOT" -B "$FUZZ_BUILD_DIR" -DCMAKE_CXX_COMPILER=clang++ \
  -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1 -g" \
  -DWILD_MVS_FUZZ=ON -DWILD_MVS_WITH_ROS="$ros" -DWILD_MVS_BUILD_TESTS=OFF \
  -DPYTHON_EXECUTABLE=/usr/bin/python3 -DPython3_EXECUTABLE=/usr/bin/python3 \
  "${launcher[@]}" >"$FUZZ_BUILD_DIR/cmake.log" 2>&1 ||
  { cat "$FUZZ_BUILD_DIR/cmake.log"; exit 1; }
cmake --build "$FUZZ_BUILD_DIR" -j"$JOBS" --target fuzzers

if [ $# -gt 0 ]; then
  harnesses=("$@")
else
  harnesses=()
  for f in "$FUZZ_BUILD_DIR"/fuzz/fuzz_*; do
    [ -x "$f" ] && harnesses+=("$(basename "$f")")
  done
fi
[ ${#harnesses[@]} -gt 0 ] || { echo "run_fuzz.sh: no harnesses" >&2; exit 2; }

# Scratch files of the harnesses (fast, private, removed at the end).
scratch_base=/tmp
[ -w /dev/shm ] && scratch_base=/dev/shm
export WILD_MVS_FUZZ_TMP
WILD_MVS_FUZZ_TMP="$(mktemp -d "$scratch_base/wild_mvs_fuzz_run.XXXXXX")"
trap 'rm -rf "$WILD_MVS_FUZZ_TMP"' EXIT
export ASAN_OPTIONS="${ASAN_OPTIONS:-allocator_may_return_null=0:detect_leaks=1}"
export UBSAN_OPTIONS="${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1}"

run_one() {  # harness
  local h="$1" bin="$FUZZ_BUILD_DIR/fuzz/$1" seeds="$ROOT/test/fuzz/corpus/${1#fuzz_}"
  local work="$FUZZ_BUILD_DIR/corpus/$h" findings="$FUZZ_BUILD_DIR/findings/$h"
  local log="$FUZZ_BUILD_DIR/logs/$h.log"
  rm -rf "$findings"
  mkdir -p "$work" "$findings" "$(dirname "$log")"
  local args=(-max_total_time="$SECONDS_PER" -seed="${FUZZ_SEED:-1}"
    -timeout=10 -rss_limit_mb=2048
    -malloc_limit_mb=1024 -print_final_stats=1 -artifact_prefix="$findings/")
  [ -f "$ROOT/test/fuzz/$h.dict" ] && args+=(-dict="$ROOT/test/fuzz/$h.dict")
  local dirs=("$work")
  [ -d "$seeds" ] && dirs+=("$seeds")
  set +e
  "$bin" "${args[@]}" "${dirs[@]}" >"$log" 2>&1
  local rc=$?
  set -e
  echo "$rc" >"$log.rc"
}

echo "run_fuzz.sh: ${#harnesses[@]} harnesses x ${SECONDS_PER}s, $JOBS in parallel"
running=0
for h in "${harnesses[@]}"; do
  [ -x "$FUZZ_BUILD_DIR/fuzz/$h" ] || { echo "run_fuzz.sh: no harness $h" >&2; exit 2; }
  rm -f "$FUZZ_BUILD_DIR/logs/$h.log.rc"
  run_one "$h" &
  running=$((running + 1))
  if [ "$running" -ge "$JOBS" ]; then
    wait -n || true
    running=$((running - 1))
  fi
done
wait

failed=0
printf '%-26s %12s %10s %8s  %s\n' harness executions exec/s corpus result
for h in "${harnesses[@]}"; do
  log="$FUZZ_BUILD_DIR/logs/$h.log"
  rc="$(cat "$log.rc" 2>/dev/null || echo 99)"
  execs="$(sed -n 's/^stat::number_of_executed_units: *//p' "$log" | tail -1)"
  rate="$(sed -n 's/^stat::average_exec_per_sec: *//p' "$log" | tail -1)"
  cov="$(grep -Eo 'corp: [0-9]+' "$log" | tail -1 | grep -Eo '[0-9]+' || true)"
  if [ "$rc" = 0 ]; then
    result=ok
  else
    failed=1
    what="$(grep -Eo 'ERROR: (AddressSanitizer|LeakSanitizer|libFuzzer|UndefinedBehaviorSanitizer)[^(]*|runtime error: .*|terminate called after throwing.*|what\(\): .*' "$log" | head -2 | tr '\n' ' ' || true)"
    result="FINDING (exit $rc): $what"
  fi
  printf '%-26s %12s %10s %8s  %s\n' "$h" "${execs:-?}" "${rate:-?}" "${cov:-?}" "$result"
done
if [ "$failed" != 0 ]; then
  echo "run_fuzz.sh: findings (inputs in $FUZZ_BUILD_DIR/findings/, logs in $FUZZ_BUILD_DIR/logs/):"
  for h in "${harnesses[@]}"; do
    ls "$FUZZ_BUILD_DIR/findings/$h"/ 2>/dev/null | sed "s|^|  $h: |"
    rc="$(cat "$FUZZ_BUILD_DIR/logs/$h.log.rc" 2>/dev/null || echo 99)"
    [ "$rc" = 0 ] || tail -40 "$FUZZ_BUILD_DIR/logs/$h.log" | sed "s|^|  $h| |"
  done
  exit 1
fi
echo "run_fuzz.sh: no findings"
