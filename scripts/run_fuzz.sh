#!/usr/bin/env bash
# Builds the libFuzzer harnesses with clang (ASan + UBSan) in build-fuzz/ and
# runs them.
#
# Usage:
#   scripts/run_fuzz.sh [HARNESS...]                  CI mode (the default)
#   scripts/run_fuzz.sh --replay [HARNESS...]         step 1 of CI mode only
#   scripts/run_fuzz.sh --explore SECONDS [HARNESS...]  long exploratory run
#
# CI mode (scripts/run_tests.sh) is bounded in time. Its replay step is
# exact; its fuzzing step uses a fixed seed and number of executions, which
# does not make it bit-repeatable (libFuzzer's comparison tracing sees
# addresses, and a folder is read in the file system's order), so a run can
# still find a new bug. Such a finding is real: fix it and keep the input.
#   1. Replay: every committed input of test/fuzz/corpus/<harness>/ (seeds and
#      the regressions of earlier findings, named crash_* / leak_* / ...)
#      runs once; each must pass.
#   2. Bounded fuzzing: each harness runs a fixed number of executions
#      (-runs=N, N from the table below or $FUZZ_RUNS) with a fixed seed
#      (-seed=$FUZZ_SEED, default 1), one process per harness, starting from
#      a fresh copy of its committed corpus. Sized so that steps 1 and 2
#      take about 2 minutes of the 2-core CI machine after the build.
# Explore mode runs each harness for SECONDS (-max_total_time), one harness
# at a time, with a random seed (or $FUZZ_SEED) and a corpus that persists
# across runs in build-fuzz/explore-corpus/<harness>/. Run it at low priority
# (nice -n 19) for minutes per harness to look for new bugs.
#
# HARNESS: names like fuzz_pfm (default: every harness built, i.e. each
# test/fuzz/fuzz_*.cpp, and test/fuzz/ros/ when ROS is found).
# Environment: JOBS harnesses run in parallel in CI mode (default: cores;
#   explore mode runs one at a time), FUZZ_BUILD_DIR (default build-fuzz),
#   FUZZ_SEED, FUZZ_RUNS (executions per harness in CI mode, overrides the
#   table), WILD_MVS_FUZZ_ROS=ON|OFF.
# Prints executions and findings per harness; exits non-zero when any
# harness found a crash, a sanitizer report, a leak, a timeout or an
# out-of-memory. Findings are kept in build-fuzz/findings/<harness>/; to
# reproduce one: build-fuzz/fuzz/<harness> <file>. A finding, once fixed,
# belongs in test/fuzz/corpus/<harness>/ (named crash_<what>) and
# test/unit/test_fuzz_regressions.cpp.
set -eo pipefail
ROOT="$(cd "$(dirname "$0")/.." && pwd)"
FUZZ_BUILD_DIR="${FUZZ_BUILD_DIR:-$ROOT/build-fuzz}"
source "$ROOT/scripts/common.sh"

mode=ci
case "${1:-}" in
  --explore)
    mode=explore
    EXPLORE_SECONDS="${2:-}"
    shift 2 || shift $#
    case "$EXPLORE_SECONDS" in '' | *[!0-9]*)
      echo "run_fuzz.sh: --explore needs SECONDS (a whole number), got '$EXPLORE_SECONDS'" >&2
      exit 2 ;;
    esac ;;
  --replay) mode=replay; shift ;;
  --ci) shift ;;
  [0-9]*)
    echo "run_fuzz.sh: a time limit is for exploring: use --explore $1" >&2
    exit 2 ;;
  -*) echo "run_fuzz.sh: unknown option '$1'" >&2; exit 2 ;;
esac

# Executions per harness in CI mode. Sized from the measured speed (exec/s on
# one core of the CI machine, first 10^4 executions) for about 15-25 s each.
declare -A CI_RUNS=(
  [fuzz_bundler]=40000
  [fuzz_colmap_binary]=60000
  [fuzz_colmap_text]=50000
  [fuzz_image_size]=40000
  [fuzz_middlebury_par]=60000
  [fuzz_pfm]=80000
  [fuzz_ply]=40000
  [fuzz_ros_messages]=100000
  [fuzz_strecha_camera]=60000
  [fuzz_yaml_config]=8000
)
DEFAULT_CI_RUNS=30000

command -v clang++ >/dev/null || {
  echo "run_fuzz.sh: clang++ not found (scripts/install_deps.sh --extra)" >&2
  exit 2
}
t_start=$(date +%s)
echo "run_fuzz.sh: building harnesses in $FUZZ_BUILD_DIR"
# The same configure as the sanitizer step (scripts/common.sh).
wild_mvs_configure_sanitized "$FUZZ_BUILD_DIR" || exit 1
cmake --build "$FUZZ_BUILD_DIR" -j"$JOBS" --target fuzzers >"$FUZZ_BUILD_DIR/build.log" 2>&1 ||
  { tail -60 "$FUZZ_BUILD_DIR/build.log"; exit 1; }
# The project is warning-free under clang too.
if grep -E 'warning:' "$FUZZ_BUILD_DIR/build.log"; then
  echo "run_fuzz.sh: the clang build has warnings (above)" >&2
fi
t_built=$(date +%s)

if [ $# -gt 0 ]; then
  harnesses=("$@")
else
  harnesses=()
  for f in "$FUZZ_BUILD_DIR"/fuzz/fuzz_*; do
    [ -x "$f" ] && harnesses+=("$(basename "$f")")
  done
fi
[ ${#harnesses[@]} -gt 0 ] || { echo "run_fuzz.sh: no harnesses" >&2; exit 2; }
for h in "${harnesses[@]}"; do
  [ -x "$FUZZ_BUILD_DIR/fuzz/$h" ] || { echo "run_fuzz.sh: no harness $h" >&2; exit 2; }
done

# Scratch files of the harnesses (fast, private, removed at the end).
scratch_base=/tmp
[ -w /dev/shm ] && scratch_base=/dev/shm
export WILD_MVS_FUZZ_TMP
WILD_MVS_FUZZ_TMP="$(mktemp -d "$scratch_base/wild_mvs_fuzz_run.XXXXXX")"
trap 'rm -rf "$WILD_MVS_FUZZ_TMP"' EXIT
export ASAN_OPTIONS="${ASAN_OPTIONS:-allocator_may_return_null=0:detect_leaks=1}"
export UBSAN_OPTIONS="${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1}"

seeds_of() { echo "$ROOT/test/fuzz/corpus/${1#fuzz_}"; }
common_args() {  # harness findings-dir
  local a=(-timeout=25 -rss_limit_mb=2048 -malloc_limit_mb=1024
    -print_final_stats=1 -artifact_prefix="$2/")
  [ -f "$ROOT/test/fuzz/$1.dict" ] && a+=(-dict="$ROOT/test/fuzz/$1.dict")
  printf '%s\n' "${a[@]}"
}

# Step 1 (CI and replay modes): every committed input once.
replay_failed=0
if [ "$mode" != explore ]; then
  echo "run_fuzz.sh: replaying the committed corpus of ${#harnesses[@]} harnesses"
  printf '%-26s %8s  %s\n' harness inputs result
  for h in "${harnesses[@]}"; do
    seeds="$(seeds_of "$h")"
    log="$FUZZ_BUILD_DIR/logs/$h.replay.log"
    findings="$FUZZ_BUILD_DIR/findings/$h"
    rm -rf "$findings"
    mkdir -p "$findings" "$(dirname "$log")"
    inputs=()
    [ -d "$seeds" ] && while IFS= read -r f; do inputs+=("$f"); done \
      < <(find "$seeds" -type f | LC_ALL=C sort)
    if [ ${#inputs[@]} -eq 0 ]; then
      printf '%-26s %8s  %s\n' "$h" 0 "no committed inputs"
      continue
    fi
    mapfile -t args < <(common_args "$h" "$findings")
    if "$FUZZ_BUILD_DIR/fuzz/$h" "${args[@]}" "${inputs[@]}" >"$log" 2>&1; then
      printf '%-26s %8s  %s\n' "$h" "${#inputs[@]}" ok
    else
      replay_failed=1
      bad="$(grep -Eo '^Running: .*' "$log" | tail -1 | sed 's|^Running: ||')"
      what="$(grep -Eo 'ERROR: (AddressSanitizer|LeakSanitizer|libFuzzer|UndefinedBehaviorSanitizer)[^(]*|runtime error: .*|terminate called after throwing.*|what\(\): .*' "$log" | head -2 | tr '\n' ' ' || true)"
      printf '%-26s %8s  %s\n' "$h" "${#inputs[@]}" "FAILED on ${bad#"$ROOT"/}: $what"
      tail -40 "$log" | sed "s#^#  $h: #"
    fi
  done
  t_replayed=$(date +%s)
  echo "run_fuzz.sh: replay $((t_replayed - t_built)) s"
  if [ "$mode" = replay ]; then
    [ "$replay_failed" = 0 ] || exit 1
    echo "run_fuzz.sh: every committed input passes"
    exit 0
  fi
fi

# Step 2: fuzzing (bounded and seeded in CI mode, timed in explore mode).
run_one() {  # harness
  local h="$1" bin="$FUZZ_BUILD_DIR/fuzz/$1" seeds
  seeds="$(seeds_of "$1")"
  local findings="$FUZZ_BUILD_DIR/findings/$h" work
  local log="$FUZZ_BUILD_DIR/logs/$h.log"
  mkdir -p "$findings" "$(dirname "$log")"
  local args
  mapfile -t args < <(common_args "$h" "$findings")
  if [ "$mode" = explore ]; then
    work="$FUZZ_BUILD_DIR/explore-corpus/$h"  # grows across runs
    args+=(-max_total_time="$EXPLORE_SECONDS" -seed="${FUZZ_SEED:-0}")
  else
    work="$FUZZ_BUILD_DIR/ci-corpus/$h"  # fresh: same start every time
    rm -rf "$work"
    args+=(-runs="${FUZZ_RUNS:-${CI_RUNS[$h]:-$DEFAULT_CI_RUNS}}"
      -seed="${FUZZ_SEED:-1}")
  fi
  mkdir -p "$work"
  local dirs=("$work")
  [ -d "$seeds" ] && dirs+=("$seeds")
  set +e
  "$bin" "${args[@]}" "${dirs[@]}" >"$log" 2>&1
  local rc=$?
  set -e
  echo "$rc" >"$log.rc"
  # CPU seconds of the harness (user + sys of this subshell's children).
  times >"$log.times"  # a builtin without a pipe: no subshell
  tail -1 "$log.times" | awk '{ n = 0; for (i = 1; i <= 2; ++i) {
      split($i, p, /[ms]/); n += p[1] * 60 + p[2] } printf "%.0f\n", n }' \
    >"$log.cpu"
}

t_fuzz=$(date +%s)
if [ "$mode" = explore ]; then
  par=1
  echo "run_fuzz.sh: exploring ${#harnesses[@]} harnesses x ${EXPLORE_SECONDS}s, one at a time"
else
  par="$JOBS"
  echo "run_fuzz.sh: ${#harnesses[@]} harnesses, fixed executions, seed ${FUZZ_SEED:-1}, $par in parallel"
fi
running=0
for h in "${harnesses[@]}"; do
  rm -f "$FUZZ_BUILD_DIR/logs/$h.log.rc"
  if [ "$mode" = explore ]; then
    rm -rf "$FUZZ_BUILD_DIR/findings/$h"
  fi
  run_one "$h" &
  running=$((running + 1))
  if [ "$running" -ge "$par" ]; then
    wait -n || true
    running=$((running - 1))
  fi
done
wait

failed="$replay_failed"
total=0 total_cpu=0
printf '%-26s %12s %10s %6s %8s  %s\n' harness executions exec/s CPU-s corpus result
for h in "${harnesses[@]}"; do
  log="$FUZZ_BUILD_DIR/logs/$h.log"
  rc="$(cat "$log.rc" 2>/dev/null || echo 99)"
  execs="$(sed -n 's/^stat::number_of_executed_units: *//p' "$log" | tail -1)"
  rate="$(sed -n 's/^stat::average_exec_per_sec: *//p' "$log" | tail -1)"
  cov="$(grep -Eo 'corp: [0-9]+' "$log" | tail -1 | grep -Eo '[0-9]+' || true)"
  total=$((total + ${execs:-0}))
  if [ "$rc" = 0 ]; then
    result=ok
  else
    failed=1
    what="$(grep -Eo 'ERROR: (AddressSanitizer|LeakSanitizer|libFuzzer|UndefinedBehaviorSanitizer)[^(]*|runtime error: .*|terminate called after throwing.*|what\(\): .*' "$log" | head -2 | tr '\n' ' ' || true)"
    result="FINDING (exit $rc): $what"
  fi
  cpu="$(cat "$log.cpu" 2>/dev/null || true)"
  total_cpu=$((total_cpu + ${cpu:-0}))
  printf '%-26s %12s %10s %6s %8s  %s\n' "$h" "${execs:-?}" "${rate:-?}" "${cpu:-?}" "${cov:-?}" "$result"
done
t_end=$(date +%s)
echo "run_fuzz.sh: $total executions, $total_cpu CPU-s; build $((t_built - t_start)) s, fuzzing $((t_end - t_fuzz)) s, total $((t_end - t_start)) s"
if [ "$failed" != 0 ]; then
  echo "run_fuzz.sh: findings (inputs in $FUZZ_BUILD_DIR/findings/, logs in $FUZZ_BUILD_DIR/logs/):"
  for h in "${harnesses[@]}"; do
    find "$FUZZ_BUILD_DIR/findings/$h" -type f 2>/dev/null | sed "s#^#  $h: #"
    rc="$(cat "$FUZZ_BUILD_DIR/logs/$h.log.rc" 2>/dev/null || echo 99)"
    [ "$rc" = 0 ] || tail -40 "$FUZZ_BUILD_DIR/logs/$h.log" | sed "s#^#  $h: #"
  done
  exit 1
fi
echo "run_fuzz.sh: no findings"
