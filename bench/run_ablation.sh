#!/usr/bin/env bash
# Does each mechanism earn its place? (not a test; docs/METHODS.md, "Benchmark
# protocol"). Runs bench/run_families.sh with the default options and then
# once per switch of the method (`--ablation.NAME false`, core/ablation.h),
# on the same rendered scenes, and writes OUT/default.tsv and
# OUT/no_NAME.tsv (run_families.sh's table). bench/make_results.py shows
# them side by side: a mechanism whose absence is at least as good on every
# family, in coverage within 1 % and in estimates off by more than 5 %, is
# one the policy deletes.
#
# Usage: bench/run_ablation.sh [--seeds report|S1,S2..] [--size 320]
#          [--families "relief weak courtyard"] [--switches "a b .."]
#          [--threads 2] [--out DIR] [--skip-build]
# Defaults: report seeds, images 320x240 (one switch costs the time of one
# family run: the whole set took 65 min on 2 cores shared with another job), every
# switch.
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
SEEDS=report
SIZE=320
FAMILIES="relief weak courtyard"
SWITCHES=""  # default: every switch the tool registers under ablation.
THREADS=2
OUT="$ROOT/build-bench/ablation"
BUILD_ARG=()
while [ $# -gt 0 ]; do
  case "$1" in
    --seeds) SEEDS="$2"; shift 2 ;;
    --size) SIZE="$2"; shift 2 ;;
    --families) FAMILIES="$2"; shift 2 ;;
    --switches) SWITCHES="$2"; shift 2 ;;
    --threads) THREADS="$2"; shift 2 ;;
    --out) OUT="$2"; shift 2 ;;
    --skip-build) BUILD_ARG=(--skip-build); shift ;;
    -h|--help) sed -n '2,/^set -euo/p' "$0" | sed '$d; s/^# \{0,1\}//'; exit 0 ;;
    *) echo "run_ablation.sh: unknown option $1 (see --help)" >&2; exit 2 ;;
  esac
done
mkdir -p "$OUT"
run() {
  bash "$ROOT/bench/run_families.sh" ${BUILD_ARG[@]+"${BUILD_ARG[@]}"} \
    --seeds "$SEEDS" --size "$SIZE" --families "$FAMILIES" \
    --threads "$THREADS" --out "$OUT" "$@" >&2
  # The binaries exist after the first run.
  BUILD_ARG=(--skip-build)
}
run --tag default
if [ -z "$SWITCHES" ]; then
  SWITCHES=$("${BUILD_DIR:-$ROOT/build-bench}/bin/wild_mvs" reconstruct --dump-config |
    awk '/^ablation:/ { on = 1; next } /^[^ #]/ { on = 0 }
         on && /^  [a-z_]+:/ { sub(":", "", $1); print $1 }')
  [ -n "$SWITCHES" ] || { echo "run_ablation.sh: no ablation switches found" >&2; exit 1; }
fi
for s in $SWITCHES; do
  run --tag "no_$s" -- "--ablation.$s" false
done
printf 'key\tvalue\nsize\t%s\nseeds\t%s\nswitches\t%s\n' "$SIZE" "$SEEDS" \
  "$(echo $SWITCHES)" >"$OUT/setting.tsv"
echo "run_ablation.sh: tables in $OUT" >&2
