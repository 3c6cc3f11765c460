#!/usr/bin/env bash
# MVE's dmrecon (the paper's reference implementation) side by side with
# wild_mvs (not a test). Runs dmrecon, built separately from MVE's sources
# (nothing of it is in this repository; `make` in its libs/util, libs/math,
# libs/mve, libs/dmrecon and apps/dmrecon with MVE's own flags), on
#   - templeSparseRing, all 16 views at 640x480 (dmrecon --scale 0);
#   - fountain-P11, all 11 views, 3072x2048 images matched at 1536x1024
#     (--scale 1: MVE halves the image per level);
# from the datasets' colmap_sift_gt models (the ground-truth cameras and the
# SIFT tracks wild_mvs gets), written as an MVE scene by bench/mve_scene.py,
# with dmrecon's default options otherwise and OMP_NUM_THREADS threads. The
# depth maps (MVE's depth is along the viewing ray) become a wild_mvs depth
# folder (z along the optical axis) and are scored by the rules of
# bench/run_bench.sh:
#   temple:   bench_depth_stats: samples inside the bounding box + 5 mm and
#             consistent with another view within 0.5 % (= correct);
#   fountain: `wild_mvs eval depth` against the ground-truth depth (correct
#             = estimates within 1 %).
# CPU-s and peak RSS are those of the whole dmrecon process (/usr/bin/time
# -v): on temple the median of --runs runs (the samples are the same in
# every run), on fountain one run (as bench/run_fountain.sh's).
#
# Usage: bench/run_mve.sh [--mve-bin DIR] [--threads N] [--runs N]
#                         [--only temple|fountain] [--out DIR]
# Writes OUT/NAME/summary.txt per dataset (and prints it) and, for
# bench/make_results.py, OUT/peers/speed_temple.tsv and OUT/peers/fountain.tsv.
# Environment: MVE_BIN (the folder with dmrecon; or --mve-bin DIR),
# WILD_MVS_BIN (the folder with wild_mvs and bench_depth_stats; default
# devel/lib/wild_mvs of the repo, else build-bench/bin), WILD_MVS_DATASETS
# (default ../shared/datasets of the repo).
# Takes long: temple about 3 CPU-minutes per run, fountain about 35
# (20 minutes on 2 cores).
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
DATASETS="${WILD_MVS_DATASETS:-$ROOT/../shared/datasets}"
MVE_BIN="${MVE_BIN:-}"
WILD_MVS_BIN="${WILD_MVS_BIN:-$ROOT/devel/lib/wild_mvs}"
[ -x "$WILD_MVS_BIN/bench_depth_stats" ] || WILD_MVS_BIN="$ROOT/build-bench/bin"
THREADS=2
RUNS=3
ONLY=""
OUT=""
while [ $# -gt 0 ]; do
  case "$1" in
    --mve-bin) MVE_BIN="$2"; shift 2 ;;
    --threads) THREADS="$2"; shift 2 ;;
    --runs) RUNS="$2"; shift 2 ;;
    --only) ONLY="$2"; shift 2 ;;
    --out) OUT="$2"; shift 2 ;;
    -h | --help) sed -n '2,32p' "$0"; exit 0 ;;
    *) echo "run_mve.sh: unknown option $1 (--help)" >&2; exit 2 ;;
  esac
done
case "$ONLY" in "" | temple | fountain) ;; *)
  echo "run_mve.sh: --only takes temple or fountain, not '$ONLY'" >&2
  exit 2 ;;
esac
[[ "$RUNS" =~ ^[1-9][0-9]*$ ]] || { echo "run_mve.sh: --runs must be >= 1" >&2; exit 2; }
[ -n "$MVE_BIN" ] || {
  echo "run_mve.sh: set MVE_BIN (or --mve-bin DIR) to the folder of MVE's dmrecon" >&2
  exit 2
}
[ -x "$MVE_BIN/dmrecon" ] || { echo "run_mve.sh: no $MVE_BIN/dmrecon (set MVE_BIN)" >&2; exit 1; }
for b in wild_mvs bench_depth_stats; do
  [ -x "$WILD_MVS_BIN/$b" ] || { echo "run_mve.sh: no $WILD_MVS_BIN/$b (set WILD_MVS_BIN)" >&2; exit 1; }
done
[ -x /usr/bin/time ] || { echo "run_mve.sh: needs /usr/bin/time (apt-get install time)" >&2; exit 1; }
[ -d "$DATASETS" ] || { echo "run_mve.sh: no datasets at $DATASETS" >&2; exit 1; }
[ -n "$OUT" ] || OUT="$(mktemp -d /tmp/mve_bench.XXXXXX)"
mkdir -p "$OUT/peers"
OUT="$(cd "$OUT" && pwd)"

# mve NAME MODEL IMAGES SCALE N: N dmrecon runs on a fresh scene each in
# OUT/NAME (run K: OUT/NAME/run-K.time and .log); the last run's depth maps
# as a wild_mvs folder OUT/NAME/wild. Prints "cpu_s rss_mb" (medians).
mve() {
  local d="$OUT/$1" model="$2" images="$3" scale="$4" n="$5" k
  mkdir -p "$d"
  for k in $(seq 1 "$n"); do
    rm -rf "$d/scene"
    python3 "$ROOT/bench/mve_scene.py" from-colmap "$model" "$images" "$d/scene" >&2
    echo "== dmrecon --scale $scale ($1, run $k of $n)" >&2
    OMP_NUM_THREADS="$THREADS" /usr/bin/time -v -o "$d/run-$k.time" \
      "$MVE_BIN/dmrecon" --scale="$scale" --progress=silent "$d/scene" \
      >"$d/run-$k.log" 2>&1 || {
      echo "run_mve.sh: dmrecon failed ($d/run-$k.log):" >&2
      tail -20 "$d/run-$k.log" >&2
      exit 1
    }
  done
  rm -rf "$d/wild"
  python3 "$ROOT/bench/mve_scene.py" to-wild-mvs "$d/scene" "depth-L$scale" "$d/wild" \
    >"$d/convert.txt"
  for k in $(seq 1 "$n"); do
    awk -F': ' '/User time/ {u = $2} /System time/ {s = $2} /Maximum resident/ {m = $2}
      END {printf "%.1f %.0f\n", u + s, m / 1024}' "$d/run-$k.time"
  done | sort -n | awk '{c[NR] = $1; r[NR] = $2} END {m = int((NR + 1) / 2); print c[m], r[m]}'
}

# kv KEY FILE: value of KEY=... on the TOTAL line.
kv() { grep '^TOTAL' "$2" | tr ' ' '\n' | sed -n "s/^$1=//p" | grep . || echo -; }

T="$DATASETS/middlebury_templeSparseRing"
F="$DATASETS/strecha_fountain-P11"
if [ -z "$ONLY" ] || [ "$ONLY" = temple ]; then
  read -r cpu rss < <(mve temple "$T/colmap_sift_gt" "$T" 0 "$RUNS")
  "$WILD_MVS_BIN/bench_depth_stats" "$T/colmap_sift_gt" "$T" "$OUT/temple/wild" \
    --bbox -0.073568 0.021728 -0.012445 0.028855 0.181892 0.062736 \
    --margin 0.005 --consistency 0.005 >"$OUT/temple/stats.txt"
  samples=$(kv samples "$OUT/temple/stats.txt")
  correct=$(kv correct "$OUT/temple/stats.txt")
  per=$(echo "$correct / $cpu" | bc -l | xargs printf %.0f)
  {
    echo "temple: dmrecon ${cpu} CPU-s (median of $RUNS), peak RSS ${rss} MB"
    echo "temple: samples=$samples in_bbox=$(kv in_bbox "$OUT/temple/stats.txt")" \
      "correct=$correct (in box +5 mm and consistent within 0.5 %)" \
      "correct_per_cpu_s=$per"
  } | tee "$OUT/temple/summary.txt"
  {
    printf 'system\tsize\tcpu_s\tsamples\tcorrect\tcorrect_per_cpu_s\tpeak_rss_mb\tsource\n'
    printf 'MVE dmrecon\t640\t%s\t%s\t%s\t%s\t%s\t%s\n' "$cpu" "$samples" "$correct" "$per" "$rss" \
      "bench/run_mve.sh, default options, $THREADS threads, median of $RUNS"
  } >"$OUT/peers/speed_temple.tsv"
fi
if [ -z "$ONLY" ] || [ "$ONLY" = fountain ]; then
  [ -d "$F" ] || { echo "run_mve.sh: no $F" >&2; exit 1; }
  read -r cpu rss < <(mve fountain "$F/colmap_sift_gt" "$F/images" 1 1)
  W="$OUT/fountain/wild"
  "$WILD_MVS_BIN/wild_mvs" eval depth --est "$W" --dataset "$F" \
    --rel-thresholds 0.01,0.05 --json "$OUT/fountain/eval_depth.json" \
    >"$OUT/fountain/eval_depth.txt"
  python3 - "$OUT/fountain/eval_depth.json" "$cpu" "$rss" "$OUT/peers/fountain.tsv" "$THREADS" <<'EOF' | tee "$OUT/fountain/summary.txt"
import json, sys
j = json.load(open(sys.argv[1]))
cpu, rss, tsv, threads = float(sys.argv[2]), sys.argv[3], sys.argv[4], sys.argv[5]
est = max(1, j["estimated"])
off5 = 1 - j["relative_accuracy"][1]
print(f"fountain: dmrecon {cpu:.1f} CPU-s (one run), peak RSS {rss} MB")
print(f"fountain: samples={j['estimated']} with_estimate={j['completeness']:.4f} "
      f"within_1pct={j['relative_accuracy'][0]:.4f} off_5pct={off5:.4f} "
      f"without_gt={j['outside_gt'] / est:.4f} "
      f"median_abs_m={j['median_abs_error']:.5f}")
cols = ["system", "size", "coverage", "within1%", "off>5%", "background",
        "median_abs_mm", "F@1cm", "F@2cm", "F@5cm", "cpu_s", "rss_mb", "source"]
vals = ["MVE dmrecon", "1536", f"{j['completeness']:.4f}",
        f"{j['relative_accuracy'][0]:.4f}", f"{off5:.4f}",
        f"{j['outside_gt'] / est:.4f}", f"{1000 * j['median_abs_error']:.1f}",
        "-", "-", "-", f"{cpu:.1f}", rss,
        f"bench/run_mve.sh, default options, {threads} threads, one run "
        "(depth maps only)"]
with open(tsv, "w") as f:
    f.write("\t".join(cols) + "\n" + "\t".join(vals) + "\n")
EOF
fi
