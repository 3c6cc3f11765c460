#!/usr/bin/env bash
# MVS benchmark (issue 3, section 7; not a test). Builds the ROS-free tree,
# then reconstructs
#   - templeSparseRing, all 16 views at full resolution (640x480);
#   - fountain-P11, all 11 views at half resolution (1536x1024);
# with the colmap_sift_gt models and the default options, one view at a time
# with every thread inside the view, and prints a table: wall and CPU
# seconds (total and per depth map), valid samples, samples per CPU second,
# peak RSS, and the quality numbers of bench_depth_stats (temple: samples in
# the README's bounding box enlarged by 5 mm and samples consistent with
# another view within 0.5 % of depth; fountain: completeness, fraction
# within 1 / 2 cm and median error against the ground-truth depth).
#
# Usage: bench/run_bench.sh [--threads N] [--out DIR] [--skip-build]
#                           [--only temple|fountain] [-- EXTRA bench_mvs ARGS]
# Environment: WILD_MVS_DATASETS (default: ../shared/datasets of the repo).
# Takes many minutes (about 2-4 CPU-minutes on an idle core per dataset).
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
DATASETS="${WILD_MVS_DATASETS:-$ROOT/../shared/datasets}"
THREADS=2
OUT=""
BUILD=1
ONLY=""
EXTRA=()
while [ $# -gt 0 ]; do
  case "$1" in
    --threads) THREADS="$2"; shift 2 ;;
    --out) OUT="$2"; shift 2 ;;
    --skip-build) BUILD=0; shift ;;
    --only) ONLY="$2"; shift 2 ;;
    --) shift; EXTRA=("$@"); break ;;
    *) echo "run_bench.sh: unknown option $1" >&2; exit 2 ;;
  esac
done
[ -d "$DATASETS" ] || { echo "run_bench.sh: no datasets at $DATASETS" >&2; exit 1; }
# Its own ROS-free build folder, so the main build/ keeps its configuration.
export BUILD_DIR="${BUILD_DIR:-$ROOT/build-bench}"
if [ "$BUILD" = 1 ]; then
  mkdir -p "$BUILD_DIR"
  # shellcheck source=../scripts/common.sh
  source "$ROOT/scripts/common.sh"
  JOBS="${JOBS:-2}" wild_mvs_build -DWILD_MVS_WITH_ROS=OFF >/dev/null
fi
BIN="$BUILD_DIR/bin"
[ -n "$OUT" ] || OUT="$(mktemp -d /tmp/wild_mvs_bench.XXXXXX)"
mkdir -p "$OUT"

# run NAME MODEL IMAGES [bench_mvs args...]: reconstruct into $OUT/NAME.
run() {
  local name="$1" model="$2" images="$3"
  shift 3
  echo "== $name: bench_mvs $*" >&2
  "$BIN/bench_mvs" "$model" "$images" \
    --threads "$THREADS" --save "$OUT/$name" "$@" ${EXTRA[@]+"${EXTRA[@]}"} \
    | tee "$OUT/$name.txt" >&2
}

# field KEY FILE: value of KEY=... on the TOTAL line.
field() { grep '^TOTAL' "$2" | tr ' ' '\n' | sed -n "s/^$1=//p" | grep . || echo -; }

T="$DATASETS/middlebury_templeSparseRing"
F="$DATASETS/strecha_fountain-P11"
ROWS=()
if [ -z "$ONLY" ] || [ "$ONLY" = temple ]; then
  run temple "$T/colmap_sift_gt" "$T"
  "$BIN/bench_depth_stats" "$T/colmap_sift_gt" "$T" "$OUT/temple" \
    --bbox -0.073568 0.021728 -0.012445 0.028855 0.181892 0.062736 \
    --margin 0.005 --consistency 0.005 | tee "$OUT/temple.stats" >&2
  ROWS+=(temple)
fi
if [ -z "$ONLY" ] || [ "$ONLY" = fountain ]; then
  run fountain "$F/colmap_sift_gt" "$F/images" --max-image-size 1536
  "$BIN/bench_depth_stats" "$F/colmap_sift_gt" "$F/images" "$OUT/fountain" \
    --gt "$F" --consistency 0.01 | tee "$OUT/fountain.stats" >&2
  ROWS+=(fountain)
fi

printf '\n%-9s %5s %9s %8s %8s %9s %9s %13s %7s %9s %10s %8s %6s %6s %8s\n' \
  dataset views samples wall_s cpu_s wall/map cpu/map samples/cpu_s rss_MB \
  in_bbox consistent complete "<=1cm" "<=2cm" median_m
for name in "${ROWS[@]}"; do
  txt="$OUT/$name.txt"
  st="$OUT/$name.stats"
  views=$(field views "$txt")
  wall=$(field seconds "$txt")
  cpu=$(field cpu_seconds "$txt")
  printf '%-9s %5s %9s %8.1f %8.1f %9.2f %9.2f %13s %7s %9s %10s %8s %6s %6s %8s\n' \
    "$name" "$views" "$(field samples "$txt")" "$wall" "$cpu" \
    "$(echo "$wall / $views" | bc -l)" "$(echo "$cpu / $views" | bc -l)" \
    "$(field samples_per_cpu_second "$txt")" "$(field peak_rss_mb "$txt")" \
    "$(field in_bbox "$st")" "$(field correct "$st")" \
    "$(field gt_completeness "$st")" "$(field within_1cm "$st")" \
    "$(field within_2cm "$st")" "$(field median_error_m "$st")"
done
echo "(outputs in $OUT; temple 'consistent' = in the box and consistent;" \
  "fountain 'consistent' = consistent with another view within 1 %)"
