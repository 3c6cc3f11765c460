#!/usr/bin/env bash
# Scale benchmark (not a test): whole-process `wild_mvs reconstruct` (depth +
# consistency filter + fusion) on synthetic photo collections of growing size
# (bench/scenes/make_collection: random viewpoints, resolutions 320..1600 px,
# light, exposure, clutter; JPEG; COLMAP model with sparse tracks), measured
# with /usr/bin/time -v. The goal: CPU time per view and peak RSS flat from
# the smallest to the largest collection (docs/SCALE.md).
#
#   bench/run_scale.sh [--sizes 100,250,500] [--max-image-size 240]
#                      [--threads 2] [--work /tmp/wild_mvs_scale]
#                      [--image-cache-mb 64] [--map-cache-mb 64]
#                      [--pending-mb 32] [--fusion-mb MAP+PENDING]
#                      [--results DIR] [--table-only] [--rss-trace]
#                      [-- EXTRA_FLAGS...]
#
# Collections are rendered into WORK (never into the repository) once and
# reused: the largest first; the smaller ones hard-link the first N images of
# a larger one (view i of a collection depends only on the seed and i) and
# get their own model. Every run starts from an empty output folder. Prints a
# table (views, CPU-s, CPU-s per view, of it ReconstructView's per view,
# wall-s, peak RSS MB, samples, fused points, samples per view) and writes it
# to WORK/scale.tsv; --results DIR: copies it there with the raw outputs
# (time -v, summary.json, the log's summary lines). --table-only: no rendering or runs, the table of the runs already in
# WORK (e.g. one size per invocation, then all sizes). --rss-trace: sample
# the process's VmRSS every second into WORK/rssN.tsv (seconds, MB, the
# log's last line: where the peak is), copied with the results. BUILD_DIR (default build/) holds bin/wild_mvs and bin/make_collection.
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
FUSION_MB=""  # default: MAP_CACHE_MB + PENDING_MB
RESULTS=""
TABLE_ONLY=0
RSS_TRACE=0
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
    --fusion-mb) FUSION_MB="$2"; shift 2 ;;
    --results) RESULTS="$2"; shift 2 ;;
    --table-only) TABLE_ONLY=1; shift ;;
    --rss-trace) RSS_TRACE=1; shift ;;
    --) shift; EXTRA=("$@"); break ;;
    *) echo "run_scale.sh: unknown argument $1" >&2; exit 2 ;;
  esac
done
# The fusion's joint budget (maps + pending samples + cloud,
# fusion.memory_mb): the room the map cache and the pending samples have,
# which the cloud then shares with them (0 = none, the cloud on top).
[ -n "$FUSION_MB" ] || FUSION_MB=$(awk -v a="$MAP_CACHE_MB" -v b="$PENDING_MB" 'BEGIN {print a + b}')
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

# rss_trace PID OUT LOG: VmRSS of PID's child (the tool under time -v)
# every second until it exits.
rss_trace() {
  local pid="" t0 i
  for ((i = 0; i < 50; i++)); do
    pid=$(pgrep -P "$1" | head -1)
    [ -z "$pid" ] || break
    sleep 0.1
  done
  [ -n "$pid" ] || return 0
  t0=$(date +%s)
  : >"$2"
  while kill -0 "$pid" 2>/dev/null; do
    printf '%s\t%s\t%s\n' "$(($(date +%s) - t0))" \
      "$(awk '/VmRSS/ {print int($2 / 1024)}' "/proc/$pid/status" 2>/dev/null)" \
      "$(tail -c 300 "$3" 2>/dev/null | tr '\r' '\n' | grep -v '^$' | tail -1 | cut -c1-80)" >>"$2"
    sleep 1
  done
}

TSV="views	cpu_s	cpu_s_per_view	mvs_cpu_s_per_view	wall_s	peak_rss_mb	samples	fused_points	samples_per_view"
rows=()
for n in "${sizes[@]}"; do
  out="$WORK/out$n"
  if [ "$TABLE_ONLY" = 0 ]; then
    rm -rf "$out"
    echo "run_scale: reconstructing $n views at --max-image-size $MAX_IMAGE..." >&2
    rm -f "$WORK/rss$n.tsv"
    /usr/bin/time -v -o "$WORK/time$n.txt" "$BIN/wild_mvs" reconstruct "$WORK/c$n" "$out" \
      --max-image-size "$MAX_IMAGE" --stages depth,fuse --threads "$THREADS" \
      --image.cache_mb "$IMAGE_CACHE_MB" --fusion.map_cache_mb "$MAP_CACHE_MB" \
      --fusion.pending_mb "$PENDING_MB" --fusion.memory_mb "$FUSION_MB" \
      "${EXTRA[@]}" >"$WORK/log$n.txt" 2>&1 &
    tpid=$!
    [ "$RSS_TRACE" = 0 ] || rss_trace "$tpid" "$WORK/rss$n.tsv" "$WORK/log$n.txt" &
    wait "$tpid" ||
      { tail -20 "$WORK/log$n.txt" >&2; echo "run_scale.sh: run of $n views failed" >&2; exit 1; }
    wait
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
  echo "# bench/run_scale.sh $(date -u +%Y-%m-%dT%H:%MZ): --max-image-size $MAX_IMAGE --threads $THREADS --image.cache_mb $IMAGE_CACHE_MB --fusion.map_cache_mb $MAP_CACHE_MB --fusion.pending_mb $PENDING_MB --fusion.memory_mb $FUSION_MB ${EXTRA[*]:-}; $(nproc) cores"
  echo "$TSV"
  printf '%s\n' "${rows[@]}"
} >"$WORK/scale.tsv"
cat "$WORK/scale.tsv"
if [ -n "$RESULTS" ]; then
  mkdir -p "$RESULTS"
  cp "$WORK/scale.tsv" "$RESULTS/scale.tsv"
  for n in "${sizes[@]}"; do
    cp "$WORK/time$n.txt" "$RESULTS/time_$n.txt"
    cp "$WORK/out$n/summary.json" "$RESULTS/summary_$n.json"
    [ ! -f "$WORK/rss$n.tsv" ] || cp "$WORK/rss$n.tsv" "$RESULTS/rss_$n.tsv"
    grep -E '^(dataset|sparse|depth:|fuse|summary)' "$WORK/log$n.txt" \
      >"$RESULTS/log_$n.txt" || true
  done
fi
