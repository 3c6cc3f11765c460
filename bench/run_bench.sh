#!/usr/bin/env bash
# Speed benchmark (not a test): the depth stage of `wild_mvs reconstruct`
# (whole process, default options, the consistency filter included) on
#   - templeSparseRing (data/templeSparseRing), all 16 views at 640x480,
#     with the ground-truth cameras and SIFT tracks of
#     DATASETS/middlebury_templeSparseRing/colmap_sift_gt where it exists
#     (the input the peers of docs/RESULTS.md got), else with tracks
#     computed from the images first (`--stages sparse`, not timed);
#   - fountain-P11, all 11 views at 1536x1024 (--max-image-size 1536);
# N times each (--runs, default 3) and reports the median of: CPU seconds
# (user + sys of the whole process, /usr/bin/time), samples, correct
# samples, correct samples per CPU second and peak RSS (docs/METHODS.md):
#   temple   correct = inside the object's bounding box (README.txt) + 5 mm
#            and consistent with another view's map within 0.5 % of depth;
#   fountain correct = within 1 % of the ground-truth depth.
# (both by bench_depth_stats). Raw outputs (the /usr/bin/time lines, logs,
# stats) and table.tsv go to --results DIR (default bench/out/bench-<UTC
# time>, ignored by git); the depth maps to a temporary folder (--keep-maps
# to keep it).
#
# Usage: bench/run_bench.sh [--runs N] [--threads N] [--only temple|fountain]
#            [--temple-size PX] [--fountain-size PX] [--skip-build]
#            [--results DIR] [--keep-maps] [-- EXTRA wild_mvs reconstruct ARGS]
# --temple-size / --fountain-size: working size (longest side; defaults
# 0 = as shipped, 640, and 1536).
# Environment: WILD_MVS_DATASETS (default: ../shared/datasets of the repo),
# BUILD_DIR (default: build-bench; only the targets used are built).
# Cost: temple about 35 CPU-s per run, fountain about 250-450 CPU-s.
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
DATASETS="${WILD_MVS_DATASETS:-$ROOT/../shared/datasets}"
THREADS=2
RUNS=3
RESULTS=""
TEMPLE_SIZE=0
FOUNTAIN_SIZE=1536
BUILD=1
ONLY=""
KEEP=0
EXTRA=()
while [ $# -gt 0 ]; do
  case "$1" in
    --runs) RUNS="$2"; shift 2 ;;
    --threads) THREADS="$2"; shift 2 ;;
    --temple-size) TEMPLE_SIZE="$2"; shift 2 ;;
    --fountain-size) FOUNTAIN_SIZE="$2"; shift 2 ;;
    --results) RESULTS="$2"; shift 2 ;;
    --skip-build) BUILD=0; shift ;;
    --only) ONLY="$2"; shift 2 ;;
    --keep-maps) KEEP=1; shift ;;
    --) shift; EXTRA=("$@"); break ;;
    *) echo "run_bench.sh: unknown option $1" >&2; exit 2 ;;
  esac
done
case "$ONLY" in "" | temple | fountain) ;; *)
  echo "run_bench.sh: --only takes temple or fountain, not '$ONLY'" >&2
  exit 2 ;;
esac
[[ "$RUNS" =~ ^[1-9][0-9]*$ ]] || { echo "run_bench.sh: --runs must be >= 1" >&2; exit 2; }
if [ "$ONLY" != temple ] && [ ! -d "$DATASETS/strecha_fountain-P11" ]; then
  echo "run_bench.sh: no $DATASETS/strecha_fountain-P11 (set WILD_MVS_DATASETS, or --only temple)" >&2
  exit 1
fi
[ -x /usr/bin/time ] || { echo "run_bench.sh: needs /usr/bin/time (Debian package 'time')" >&2; exit 1; }
# Its own ROS-free build folder, so the main build/ keeps its configuration.
export BUILD_DIR="${BUILD_DIR:-$ROOT/build-bench}"
if [ "$BUILD" = 1 ]; then
  mkdir -p "$BUILD_DIR"
  # shellcheck source=../scripts/common.sh
  source "$ROOT/scripts/common.sh"
  wild_mvs_configure -DWILD_MVS_WITH_ROS=OFF
  cmake --build "$BUILD_DIR" -j"${JOBS:-2}" --target wild_mvs bench_depth_stats >/dev/null
fi
BIN="$BUILD_DIR/bin"
[ -n "$RESULTS" ] || RESULTS="$ROOT/bench/out/bench-$(date -u +%Y%m%dT%H%M%S)"
mkdir -p "$RESULTS"
MAPS="$(mktemp -d /tmp/wild_mvs_bench.XXXXXX)"
[ "$KEEP" = 1 ] || trap 'rm -rf "$MAPS"' EXIT
T="$ROOT/data/templeSparseRing"
F="$DATASETS/strecha_fountain-P11"
# The temple's model: the GT cameras and tracks the peers got, else tracks
# computed once from the shipped images (not timed).
TMODEL="$DATASETS/middlebury_templeSparseRing/colmap_sift_gt"
if [ "$ONLY" != fountain ] && [ ! -f "$TMODEL/images.txt" ]; then
  TMODEL="$MAPS/temple_sparse/sparse"
  echo "== temple: no $DATASETS/middlebury_templeSparseRing/colmap_sift_gt, computing tracks" >&2
  "$BIN/wild_mvs" reconstruct "$T" "$MAPS/temple_sparse" --stages sparse \
    --threads "$THREADS" >"$RESULTS/temple_sparse.log" 2>&1
fi

# field KEY FILE: value of KEY=... on the TOTAL line of a stats file.
field() { grep '^TOTAL' "$2" | tr ' ' '\n' | sed -n "s/^$1=//p" | grep . || echo -; }
# median of the arguments (numbers).
median() { printf '%s\n' "$@" | sort -g | awk '{a[NR]=$1} END {print (NR%2 ? a[(NR+1)/2] : (a[NR/2]+a[NR/2+1])/2)}'; }

{
  echo "# wild_mvs bench $(date -u +%FT%TZ), commit $(git -C "$ROOT" rev-parse HEAD 2>/dev/null || echo unknown)"
  echo "# $(nproc) cores: $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2-)"
  echo "# temple model $TMODEL, sizes temple $TEMPLE_SIZE fountain $FOUNTAIN_SIZE"
  echo "# threads $THREADS, runs $RUNS, extra args: ${EXTRA[*]+${EXTRA[*]}}"
  echo "# CPU SIMD flags: $(grep -m1 -o -w 'avx2\|avx512f' /proc/cpuinfo | tr '\n' ' ')"
  echo "# WILD_MVS_SIMD_TARGET=${WILD_MVS_SIMD_TARGET:-} (empty: the best the CPU has; the log says which)"
} >"$RESULTS/README.txt"

TSV="$RESULTS/table.tsv"
printf 'dataset\timpl\truns\tcpu_s\tsamples\tcorrect\tcorrect_fraction\tcorrect_per_cpu_s\tpeak_rss_mb\n' >"$TSV"

# bench NAME: RUNS runs of the depth stage on dataset NAME, one TSV row.
bench() {
  local name="$1" k cpus=() samples=() corrects=() rates=() rss=()
  for k in $(seq 1 "$RUNS"); do
    local out="$MAPS/$name.run$k" base="$RESULTS/$name.run$k"
    rm -rf "$out"
    local args=()
    if [ "$name" = temple ]; then
      args=("$T" "$out" --model "$TMODEL" --images "$T" --max-image-size "$TEMPLE_SIZE")
    else
      args=("$F" "$out" --model "$F/colmap_sift_gt" --images "$F/images"
            --max-image-size "$FOUNTAIN_SIZE")
    fi
    echo "== $name run $k/$RUNS: wild_mvs reconstruct ${args[*]} --stages depth --threads $THREADS ${EXTRA[*]+${EXTRA[*]}}" >&2
    /usr/bin/time -f "%U %S %M" -o "$base.time" \
      "$BIN/wild_mvs" reconstruct "${args[@]}" --stages depth \
      --threads "$THREADS" ${EXTRA[@]+"${EXTRA[@]}"} >"$base.log" 2>&1 ||
      { echo "run_bench.sh: wild_mvs failed, see $base.log" >&2; exit 1; }
    if [ "$name" = temple ]; then
      "$BIN/bench_depth_stats" "$TMODEL" "$T" "$out" \
        --bbox -0.073568 0.021728 -0.012445 0.028855 0.181892 0.062736 \
        --margin 0.005 --consistency 0.005 >"$base.stats"
      corrects+=("$(field correct "$base.stats")")
    else
      "$BIN/bench_depth_stats" "$F/colmap_sift_gt" "$F/images" "$out" \
        --gt "$F" --consistency 0.01 >"$base.stats"
      corrects+=("$(field correct_1pct "$base.stats")")
    fi
    samples+=("$(field samples "$base.stats")")
    read -r user sys maxkb <"$base.time"
    local cpu
    cpu=$(echo "$user + $sys" | bc -l)
    cpus+=("$cpu")
    rss+=("$(echo "$maxkb / 1024" | bc -l)")
    rates+=("$(echo "${corrects[-1]} / $cpu" | bc -l)")
    tail -n 1 "$base.stats" >&2
    echo "   cpu_s=$cpu peak_rss_kb=$maxkb" >&2
  done
  local s c
  s=$(median "${samples[@]}")
  c=$(median "${corrects[@]}")
  printf '%s\twild_mvs\t%s\t%.1f\t%.0f\t%.0f\t%.4f\t%.0f\t%.0f\n' "$name" "$RUNS" \
    "$(median "${cpus[@]}")" "$s" "$c" "$(echo "$c / $s" | bc -l)" \
    "$(median "${rates[@]}")" "$(median "${rss[@]}")" >>"$TSV"
}

if [ -z "$ONLY" ] || [ "$ONLY" = temple ]; then bench temple; fi
if [ -z "$ONLY" ] || [ "$ONLY" = fountain ]; then bench fountain; fi

echo >&2
column -t -s $'\t' "$TSV" >&2
echo "(medians of $RUNS runs; raw outputs in $RESULTS)" >&2
