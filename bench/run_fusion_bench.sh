#!/bin/bash
# Fusion benchmark over `wild_mvs reconstruct` output folders: runs
# bench_fusion once per folder (a separate process each, so every peak RSS
# is its own) and prints one table row per run.
#
#   bench/run_fusion_bench.sh [--bin BENCH_FUSION] [--threads T]
#                             [--repeat R] [--cache-mb M] [--pending-mb P]
#                             OUT[:N] [OUT[:N] ...]
#
# OUT:N fuses only the first N views (name order) of OUT. With --repeat R
# each run is repeated R times and the row with the median CPU time is kept
# (the machine may be shared). Columns: views, wall and CPU seconds, output
# points, the fusion's own peak accounting (total; depth maps held at once),
# the process's peak RSS and its RSS before fusion started. --cache-mb and
# --pending-mb set the fusion's depth-map cache and pending-sample budgets
# (defaults 512 and 256 MB: below them everything is kept, so to see the
# bound, give budgets smaller than all maps together).
#
# Example (templeSparseRing = 16 views, templeRing = 47 views, 640 x 480):
#   bench/run_fusion_bench.sh /tmp/templeSR /tmp/templeRing:16 /tmp/templeRing
set -euo pipefail

ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
BIN="${BENCH_FUSION:-$ROOT/build/bin/bench_fusion}"
THREADS=1
REPEAT=1
EXTRA=()
RUNS=()
while [[ $# -gt 0 ]]; do
  case "$1" in
    --bin) BIN="$2"; shift 2 ;;
    --threads) THREADS="$2"; shift 2 ;;
    --repeat) REPEAT="$2"; shift 2 ;;
    --cache-mb|--pending-mb) EXTRA+=("$1" "$2"); shift 2 ;;
    -h|--help) awk 'NR > 1 && /^#/ { sub(/^# ?/, ""); print; next } NR > 1 { exit }' "$0"; exit 0 ;;
    -*) echo "run_fusion_bench.sh: unknown option $1" >&2; exit 2 ;;
    *) RUNS+=("$1"); shift ;;
  esac
done
[[ ${#RUNS[@]} -gt 0 ]] || { echo "usage: $0 [--bin B] [--threads T] [--repeat R] OUT[:N] ..." >&2; exit 2; }
[[ -x "$BIN" ]] || { echo "run_fusion_bench.sh: $BIN is not executable (build first)" >&2; exit 1; }

printf '%-28s %5s %8s %8s %9s %10s %10s %10s %10s\n' \
  run views wall_s cpu_s points fusion_MB maps_MB peakRSS_MB base_MB
for run in "${RUNS[@]}"; do
  dir="${run%%:*}"
  n=0
  [[ "$run" == *:* ]] && n="${run##*:}"
  [[ -d "$dir/cameras" ]] || { echo "run_fusion_bench.sh: $dir/cameras: not a reconstruct folder" >&2; exit 1; }
  rows=()
  for ((r = 0; r < REPEAT; ++r)); do
    args=("$dir" --threads "$THREADS" "${EXTRA[@]}")
    [[ "$n" -gt 0 ]] && args+=(--views "$n")
    out="$("$BIN" "${args[@]}")" || { echo "run_fusion_bench.sh: bench_fusion failed on $run" >&2; exit 1; }
    # "views V  time W s (...)  cpu C s  points P ..." /
    # "memory: fusion peak F MB (held maps peak M MB, ...) process peak RSS R MB (B MB before fusion)"
    row="$(awk '
      /^views / { for (i = 1; i <= NF; ++i) {
                    if ($i == "views") v = $(i + 1); if ($i == "time") w = $(i + 1);
                    if ($i == "cpu") c = $(i + 1); if ($i == "points") p = $(i + 1); } }
      /^memory:/ { for (i = 1; i <= NF; ++i) {
                    if ($i == "fusion" && $(i + 1) == "peak") f = $(i + 2);
                    if ($i == "maps" && $(i + 1) == "peak") m = $(i + 2);
                    if ($i == "RSS") rss = $(i + 1);
                    if ($i == "before") b = substr($(i - 2), 2); } }
      END { printf "%s %s %s %s %s %s %s %s\n", v, w, c, p, f, m, rss, b }' <<<"$out")"
    rows+=("$row")
  done
  # Median by CPU time.
  best="$(printf '%s\n' "${rows[@]}" | sort -g -k3 | sed -n "$(((REPEAT + 1) / 2))p")"
  read -r v w c p f m rss b <<<"$best"
  label="$(basename "$dir")"
  [[ "$n" -gt 0 ]] && label="$label:$n"
  printf '%-28s %5s %8s %8s %9s %10s %10s %10s %10s\n' \
    "$label" "$v" "$w" "$c" "$p" "$f" "$m" "$rss" "$b"
done
