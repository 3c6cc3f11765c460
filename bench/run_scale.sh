#!/usr/bin/env bash
# Scale benchmark (issue 12): whole-process `wild_mvs reconstruct` (depth +
# consistency filter + fusion) on synthetic photo collections of growing size
# (bench/scenes/make_collection: random viewpoints, resolutions 320..1600 px,
# light, exposure, clutter; JPEG; COLMAP model with sparse tracks), measured
# with /usr/bin/time -v. The goal: CPU time per view and peak RSS flat from
# the smallest to the largest collection (docs/SCALE.md).
#
#   bench/run_scale.sh [--sizes 100,250,500] [--max-image-size 240]
#                      [--threads 2] [--work /tmp/wild_mvs_scale]
#                      [--image-cache-mb 64] [--map-cache-mb 64]
#                      [--pending-mb 32] [--no-results] [--table-only]
#                      [-- EXTRA_FLAGS...]
#
# Collections are rendered into WORK (never into the repository) once and
# reused: the largest first; the smaller ones hard-link the first N images of
# a larger one (view i of a collection depends only on the seed and i) and
# get their own model. Every run starts from an empty output folder. Prints a
# table (views, CPU-s, CPU-s per view, of it ReconstructView's per view,
# wall-s, peak RSS MB, samples, fused points, samples per view) and writes it
# to bench/results/scale.tsv with the raw outputs (time -v, summary.json,
# the log's summary lines) under bench/results/scale/ (--no-results: stdout
# only). --table-only: no rendering or runs, the table of the runs already in
# WORK (e.g. one size per invocation, then all sizes). BUILD_DIR (default build/) holds bin/wild_mvs and bin/make_collection.
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
BUILD_DIR="${BUILD_DIR:-$ROOT/build}"
BIN="$BUILD_DIR/bin"
SIZES=100,250,500
MAX_IMAGE=240
THREADS=2
WORK=/tmp/wild_mvs_scale
IMAGE_CACHE_MB=64
MAP_CACHE_MB=64
PENDING_MB=32
RESULTS=1
TABLE_ONLY=0
EXTRA=()
while [ $# -gt 0 ]; do
  case "$1" in
    --sizes) SIZES="$2"; shift 2 ;;
    --max-image-size) MAX_IMAGE="$2"; shift 2 ;;
    --threads) THREADS="$2"; shift 2 ;;
    --work) WORK="$2"; shift 2 ;;
    --image-cache-mb) IMAGE_CACHE_MB="$2"; shift 2 ;;
    --map-cache-mb) MAP_CACHE_MB="$2"; shift 2 ;;
    --pending-mb) PENDING_MB="$2"; shift 2 ;;
    --no-results) RESULTS=0; shift ;;
    --table-only) TABLE_ONLY=1; shift ;;
    --) shift; EXTRA=("$@"); break ;;
    *) echo "run_scale.sh: unknown argument $1" >&2; exit 2 ;;
  esac
done
for tool in wild_mvs make_collection; do
  [ -x "$BIN/$tool" ] || { echo "run_scale.sh: $BIN/$tool missing (build first)" >&2; exit 1; }
done
[ -x /usr/bin/time ] || { echo "run_scale.sh: /usr/bin/time missing (apt-get install time)" >&2; exit 1; }
mkdir -p "$WORK"
IFS=, read -r -a sizes <<<"$SIZES"
largest=0
for n in "${sizes[@]}"; do [ "$n" -gt "$largest" ] && largest=$n; done

# Collections: the largest rendered, the others link the images of a larger
# collection in WORK (those that exist; make_collection renders the rest).
render() {  # N
  local n=$1 dir="$WORK/c$1" src="" d m f i
  for d in "$WORK"/c*/images; do
    m=${d%/images}
    m=${m##*/c}
    [[ $m =~ ^[0-9]+$ ]] && [ "$m" -gt "$n" ] && src="$WORK/c$m/images"
  done
  if [ -n "$src" ]; then
    mkdir -p "$dir/images"
    for ((i = 0; i < n; i++)); do
      f=$(printf 'img_%04d.jpg' "$i")
      [ -e "$dir/images/$f" ] || [ ! -e "$src/$f" ] || ln "$src/$f" "$dir/images/$f"
    done
  fi
  "$BIN/make_collection" "$dir" --views "$n" --seed 1 >&2
}
if [ "$TABLE_ONLY" = 0 ]; then
  render "$largest"
  for n in "${sizes[@]}"; do [ "$n" -ne "$largest" ] && render "$n"; done
fi

TSV="views	cpu_s	cpu_s_per_view	mvs_cpu_s_per_view	wall_s	peak_rss_mb	samples	fused_points	samples_per_view"
rows=()
for n in "${sizes[@]}"; do
  out="$WORK/out$n"
  if [ "$TABLE_ONLY" = 0 ]; then
    rm -rf "$out"
    echo "run_scale: reconstructing $n views at --max-image-size $MAX_IMAGE..." >&2
    /usr/bin/time -v -o "$WORK/time$n.txt" "$BIN/wild_mvs" reconstruct "$WORK/c$n" "$out" \
      --max-image-size "$MAX_IMAGE" --stages depth,fuse --threads "$THREADS" \
      --image.cache_mb "$IMAGE_CACHE_MB" --fusion.map_cache_mb "$MAP_CACHE_MB" \
      --fusion.pending_mb "$PENDING_MB" "${EXTRA[@]}" >"$WORK/log$n.txt" 2>&1 \
      || { tail -20 "$WORK/log$n.txt" >&2; echo "run_scale.sh: run of $n views failed" >&2; exit 1; }
  fi
  [ -f "$WORK/time$n.txt" ] && [ -f "$out/summary.json" ] ||
    { echo "run_scale.sh: no finished run of $n views in $WORK" >&2; exit 1; }
  user=$(awk -F': ' '/User time/ {print $2}' "$WORK/time$n.txt")
  sys=$(awk -F': ' '/System time/ {print $2}' "$WORK/time$n.txt")
  rss=$(awk -F': ' '/Maximum resident/ {print $2}' "$WORK/time$n.txt")
  wall=$(awk -F': ' '/Elapsed/ {print $2}' "$WORK/time$n.txt" |
    awk -F: '{s = 0; for (i = 1; i <= NF; i++) s = s * 60 + $i; print s}')
  samples=$(sed -n 's/.*"valid_samples": \([0-9]*\).*/\1/p' "$out/summary.json")
  points=$(sed -n 's/.*"fused_points": \([0-9]*\).*/\1/p' "$out/summary.json")
  # CPU of ReconstructView per view (the views' logs; raw/ when filtered).
  logs="$out/raw/log"
  [ -d "$logs" ] || logs="$out/log"
  mvs=$(cat "$logs"/*.json | sed -n 's/.*"cpu_seconds": \([0-9.e+-]*\).*/\1/p' |
    awk '{s += $1} END {print s + 0}')
  rows+=("$(awk -v n="$n" -v u="$user" -v s="$sys" -v w="$wall" -v r="$rss" \
    -v sm="$samples" -v p="$points" -v m="$mvs" 'BEGIN {
      printf "%d\t%.1f\t%.3f\t%.3f\t%.1f\t%.0f\t%d\t%d\t%.0f", n, u + s,
             (u + s) / n, m / n, w, r / 1024, sm, p, sm / n }')")
done

{
  echo "# bench/run_scale.sh $(date -u +%Y-%m-%dT%H:%MZ): --max-image-size $MAX_IMAGE --threads $THREADS --image.cache_mb $IMAGE_CACHE_MB --fusion.map_cache_mb $MAP_CACHE_MB --fusion.pending_mb $PENDING_MB ${EXTRA[*]:-}; $(nproc) cores"
  echo "$TSV"
  printf '%s\n' "${rows[@]}"
} >"$WORK/scale.tsv"
cat "$WORK/scale.tsv"
if [ "$RESULTS" = 1 ]; then
  mkdir -p "$ROOT/bench/results/scale"
  cp "$WORK/scale.tsv" "$ROOT/bench/results/scale.tsv"
  for n in "${sizes[@]}"; do
    cp "$WORK/time$n.txt" "$ROOT/bench/results/scale/time_$n.txt"
    cp "$WORK/out$n/summary.json" "$ROOT/bench/results/scale/summary_$n.json"
    grep -E '^(dataset|sparse|depth:|fuse|summary)' "$WORK/log$n.txt" \
      >"$ROOT/bench/results/scale/log_$n.txt" || true
  done
fi
