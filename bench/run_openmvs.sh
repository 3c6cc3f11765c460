#!/usr/bin/env bash
# OpenMVS (CPU) side by side with wild_mvs (not a test).
# Runs OpenMVS, built separately (nothing of it is in this repository), on
#   - templeSparseRing, all 16 views (640x480);
#   - fountain-P11, all 11 views (3072x2048 images, depth maps at 1536x1024);
# from the datasets' colmap_sift_gt models (the same GT cameras and sparse
# points wild_mvs gets), and scores its per-view depth maps by the rules of
# bench/run_bench.sh and the README:
#   temple:   bench_depth_stats: samples inside the bounding box +5 mm and
#             consistent with another view within 0.5 % (= correct);
#   fountain: `wild_mvs eval depth` against the ground-truth depth: GT pixels
#             with an estimate, estimates within 1 % relative (correct =
#             estimates within 1 %); bench_depth_stats --gt too (1 / 2 cm);
#             with --cloud also OpenMVS's fused cloud against the GT cloud
#             (`wild_mvs eval cloud`, as bench/run_cloud_eval.sh) and the
#             share of correct samples it represents (`eval depth --cloud`).
# Per dataset: InterfaceCOLMAP (COLMAP text model -> scene.mvs), then
# DensifyPointCloud with its default options (resolution-level 1,
# max-resolution 2560, min-resolution 640: fountain's 3072x2048 images are
# processed at 1536x1024, temple's 640x480 at full size; depth maps kept,
# fused cloud written) and --max-threads THREADS. Each step's whole-process
# user+sys CPU seconds and peak RSS come from /usr/bin/time -v. The .dmap
# depth maps are converted by bench/dmap_to_wild_mvs.py into a wild_mvs
# depth folder (OUT/NAME/wild) and scored there.
#
# Usage: bench/run_openmvs.sh [--openmvs-bin DIR] [--threads N] [--out DIR] [--only temple|fountain]
#                             [--cloud] [--score-only] [-- EXTRA DensifyPointCloud ARGS]
# --score-only: do not run OpenMVS, score the outputs already in OUT.
# Writes OUT/NAME/summary.txt per dataset (and prints it).
# Environment: OPENMVS_BIN (required: the folder with OpenMVS's
#   InterfaceCOLMAP and DensifyPointCloud; or --openmvs-bin DIR), WILD_MVS_BIN (folder with wild_mvs
#   and bench_depth_stats; default devel/lib/wild_mvs of the repo, else
#   build-bench/bin), WILD_MVS_DATASETS (default ../shared/datasets of the
#   repo), GT_CLOUD (fountain GT cloud for --cloud; default
#   OUT/gt_cloud_s2_v0.005.ply, made when missing).
# Takes long: fountain is tens of CPU-minutes.
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
DATASETS="${WILD_MVS_DATASETS:-$ROOT/../shared/datasets}"
OPENMVS_BIN="${OPENMVS_BIN:-}"
if [ -z "${WILD_MVS_BIN:-}" ]; then
  WILD_MVS_BIN="$ROOT/devel/lib/wild_mvs"
  [ -x "$WILD_MVS_BIN/bench_depth_stats" ] || WILD_MVS_BIN="$ROOT/build-bench/bin"
fi
THREADS=2
OUT=""
ONLY=""
CLOUD=0
SCORE_ONLY=0
EXTRA=()
while [ $# -gt 0 ]; do
  case "$1" in
    --threads) THREADS="$2"; shift 2 ;;
    --openmvs-bin) OPENMVS_BIN="$2"; shift 2 ;;
    --out) OUT="$2"; shift 2 ;;
    --only) ONLY="$2"; shift 2 ;;
    --cloud) CLOUD=1; shift ;;
    --score-only) SCORE_ONLY=1; shift ;;
    -h|--help) awk 'NR > 1 && /^#/ { sub(/^# ?/, ""); print; next } NR > 1 { exit }' "$0"; exit 0 ;;
    --) shift; EXTRA=("$@"); break ;;
    *) echo "run_openmvs.sh: unknown option $1 (--help)" >&2; exit 2 ;;
  esac
done
if [ "$SCORE_ONLY" = 0 ]; then
  [ -n "$OPENMVS_BIN" ] || {
    echo "run_openmvs.sh: set OPENMVS_BIN (or --openmvs-bin DIR) to the folder of OpenMVS's InterfaceCOLMAP and DensifyPointCloud" >&2
    exit 2
  }
  for b in InterfaceCOLMAP DensifyPointCloud; do
    [ -x "$OPENMVS_BIN/$b" ] || { echo "run_openmvs.sh: no $OPENMVS_BIN/$b (set OPENMVS_BIN)" >&2; exit 1; }
  done
fi
for b in wild_mvs bench_depth_stats; do
  [ -x "$WILD_MVS_BIN/$b" ] || { echo "run_openmvs.sh: no $WILD_MVS_BIN/$b (set WILD_MVS_BIN)" >&2; exit 1; }
done
[ -x /usr/bin/time ] || { echo "run_openmvs.sh: needs /usr/bin/time (apt-get install time)" >&2; exit 1; }
[ -d "$DATASETS" ] || { echo "run_openmvs.sh: no datasets at $DATASETS" >&2; exit 1; }
[ -n "$OUT" ] || OUT="$(mktemp -d /tmp/openmvs_bench.XXXXXX)"
mkdir -p "$OUT"
OUT="$(cd "$OUT" && pwd)"

# timed LOG_PREFIX CMD...: runs CMD with /usr/bin/time -v, stdout+stderr of
# CMD to LOG_PREFIX.log, the time report to LOG_PREFIX.time.
timed() {
  local prefix="$1"
  shift
  echo "== $*" >&2
  /usr/bin/time -v -o "$prefix.time" "$@" >"$prefix.log" 2>&1 || {
    echo "run_openmvs.sh: failed ($prefix.log):" >&2
    tail -20 "$prefix.log" >&2
    exit 1
  }
}

# time_field FILE: "cpu_s rss_mb wall" of a /usr/bin/time -v report.
time_field() {
  awk -F': ' '/User time/ {u = $2} /System time/ {s = $2}
    /Maximum resident/ {m = $2} /Elapsed \(wall/ {w = $2}
    END {printf "%.1f %.0f %s\n", u + s, m / 1024, w}' "$1"
}

# prepare NAME MODEL IMAGES: a COLMAP project OUT/NAME/colmap (sparse/ and
# images/ of symbolic links) for InterfaceCOLMAP, which expects that layout.
prepare() {
  local dir="$OUT/$1/colmap" model="$2" images="$3" name
  rm -rf "$dir"
  mkdir -p "$dir/sparse" "$dir/images"
  for f in cameras.txt images.txt points3D.txt; do
    ln -s "$model/$f" "$dir/sparse/$f"
  done
  # The images the model names (NAME is relative to IMAGES).
  awk '!/^#/ { if ((++n % 2) == 1) print $10 }' "$model/images.txt" |
    while read -r name; do ln -s "$images/$name" "$dir/images/$name"; done
}

# openmvs NAME MODEL IMAGES: InterfaceCOLMAP + DensifyPointCloud in OUT/NAME
# (openmvs_run; skipped with --score-only),
# then the depth maps as a wild_mvs folder OUT/NAME/wild.
openmvs() {
  local d="$OUT/$1"
  mkdir -p "$d"
  if [ "$SCORE_ONLY" = 0 ]; then
    openmvs_run "$@"
  fi
  rm -rf "$d/wild"
  python3 "$ROOT/bench/dmap_to_wild_mvs.py" --confidence "$d/wild" "$d"/depth*.dmap \
    | tee "$d/convert.txt" >&2
}

openmvs_run() {
  local d="$OUT/$1"
  prepare "$@"
  rm -f "$d"/depth*.dmap "$d"/scene*.mvs "$d"/scene*.ply "$d"/InterfaceCOLMAP-*.log \
    "$d"/DensifyPointCloud-*.log
  timed "$d/interface" "$OPENMVS_BIN/InterfaceCOLMAP" -w "$d" \
    -i "$d/colmap/" -o "$d/scene.mvs" --image-folder "$d/colmap/images/"
  timed "$d/densify" "$OPENMVS_BIN/DensifyPointCloud" -w "$d" \
    -i "$d/scene.mvs" -o "$d/scene_dense.mvs" --max-threads "$THREADS" \
    ${EXTRA[@]+"${EXTRA[@]}"}
}

# kv KEY FILE: value of KEY=... on the TOTAL line.
kv() { grep '^TOTAL' "$2" | tr ' ' '\n' | sed -n "s/^$1=//p" | grep . || echo -; }

T="$DATASETS/middlebury_templeSparseRing"
F="$DATASETS/strecha_fountain-P11"
if [ -z "$ONLY" ] || [ "$ONLY" = temple ]; then
  openmvs temple "$T/colmap_sift_gt" "$T"
  "$WILD_MVS_BIN/bench_depth_stats" "$T/colmap_sift_gt" "$T" "$OUT/temple/wild" \
    --bbox -0.073568 0.021728 -0.012445 0.028855 0.181892 0.062736 \
    --margin 0.005 --consistency 0.005 | tee "$OUT/temple/stats.txt" >&2
  read -r cpu rss wall < <(time_field "$OUT/temple/densify.time")
  read -r icpu _ _ < <(time_field "$OUT/temple/interface.time")
  samples=$(kv samples "$OUT/temple/stats.txt")
  correct=$(kv correct "$OUT/temple/stats.txt")
  {
    echo "temple: DensifyPointCloud ${cpu} CPU-s (wall ${wall}), peak RSS ${rss} MB;" \
      "InterfaceCOLMAP ${icpu} CPU-s"
    echo "temple: samples=$samples in_bbox=$(kv in_bbox "$OUT/temple/stats.txt")" \
      "correct=$correct (in box +5 mm and consistent within 0.5 %)" \
      "correct_per_cpu_s=$(echo "$correct / $cpu" | bc -l | xargs printf %.0f)"
    echo "temple: fused cloud $(grep -a -m1 'element vertex' "$OUT/temple/scene_dense.ply" | awk '{print $3}') points"
  } | tee "$OUT/temple/summary.txt"
fi
if [ -z "$ONLY" ] || [ "$ONLY" = fountain ]; then
  openmvs fountain "$F/colmap_sift_gt" "$F/images"
  W="$OUT/fountain/wild"
  CLOUD_ARGS=()
  [ "$CLOUD" = 1 ] && CLOUD_ARGS=(--cloud "$OUT/fountain/scene_dense.ply")
  "$WILD_MVS_BIN/wild_mvs" eval depth --est "$W" --dataset "$F" \
    --rel-thresholds 0.01,0.005,0.02,0.05 \
    --json "$OUT/fountain/eval_depth.json" ${CLOUD_ARGS[@]+"${CLOUD_ARGS[@]}"} \
    | tee "$OUT/fountain/eval_depth.txt" >&2
  "$WILD_MVS_BIN/bench_depth_stats" "$F/colmap_sift_gt" "$F/images" "$W" \
    --gt "$F" --consistency 0.01 | tee "$OUT/fountain/stats.txt" >&2
  if [ "$CLOUD" = 1 ]; then
    GT="${GT_CLOUD:-$OUT/gt_cloud_s2_v0.005.ply}"
    [ -f "$GT" ] || "$WILD_MVS_BIN/wild_mvs" eval make-gt-cloud --dataset "$F" \
      --stride 2 --voxel 0.005 "$GT"
    "$WILD_MVS_BIN/wild_mvs" eval cloud "$OUT/fountain/scene_dense.ply" "$GT" \
      --tau 0.01,0.02,0.05 --json "$OUT/fountain/eval_cloud.json" \
      | tee "$OUT/fountain/eval_cloud.txt" >&2
  fi
  read -r cpu rss wall < <(time_field "$OUT/fountain/densify.time")
  read -r icpu _ _ < <(time_field "$OUT/fountain/interface.time")
  python3 - "$OUT/fountain/eval_depth.json" "$cpu" "$rss" "$wall" "$icpu" <<'EOF' | tee "$OUT/fountain/summary.txt"
import json, sys
j = json.load(open(sys.argv[1]))
cpu, rss, wall, icpu = float(sys.argv[2]), sys.argv[3], sys.argv[4], sys.argv[5]
print(f"fountain: DensifyPointCloud {cpu:.1f} CPU-s (wall {wall}), peak RSS {rss} MB; "
      f"InterfaceCOLMAP {icpu} CPU-s")
correct = round(j["relative_accuracy"][0] * j["evaluated"])
print(f"fountain: samples={j['estimated']} gt_pixels={j['gt_valid']} "
      f"with_estimate={j['completeness']:.4f} "
      f"within_1pct={j['relative_accuracy'][0]:.4f} "
      f"within_0.5pct={j['relative_accuracy'][1]:.4f} "
      f"without_gt={j['outside_gt'] / max(1, j['estimated']):.4f} "
      f"gt_pixels_correct={j['relative_completeness'][0]:.4f} "
      f"median_abs_m={j['median_abs_error']:.5f} correct={correct} "
      f"correct_per_cpu_s={correct / cpu:.0f}"
      + (f" cloud_represented={j['cloud_represented']:.4f}" if "cloud_represented" in j else ""))
EOF
fi
echo "(outputs in $OUT; summaries in $OUT/*/summary.txt)" >&2
