#!/usr/bin/env bash
# The benchmark protocol is bench/run_families.sh (docs/METHODS.md: three
# scene families, tuning and report seeds); this script keeps the older
# courtyard table with its extra columns (seed 5).
# Accuracy benchmark (not a test). Renders the evaluation scenes
# of bench/scenes/make_scene.cpp (constant light, changing light, clutter,
# scale; exact ground truth, a sky), runs `wild_mvs reconstruct` (depth,
# fusion, mesh) on each with the given options, and scores:
#   depth maps (pooled over views, `wild_mvs eval depth`): completeness
#     (fraction of ground-truth pixels with an estimate within 1 % of the
#     truth), fraction of the estimates within 0.5 % / 1 %, off by more
#     than 5 %, estimates where there is no surface (sky) among all
#     estimates, median relative error, and the fraction of the samples
#     within 1 % that the fused cloud represents (a point within two pixel
#     footprints);
#   fused cloud (`wild_mvs eval cloud`, against a cloud from the ground-truth
#     depth, both thinned to 5 mm voxels): precision / recall / F at 1, 2
#     and 5 cm;
#   whole-process CPU seconds (user + sys of `reconstruct`, /usr/bin/time)
#     and peak RSS.
# Usage: bench/run_accuracy.sh [--out DIR] [--kinds "constant light ..."]
#          [--views N] [--size WxH] [--points P] [--threads N] [--skip-build]
#          [--tag NAME] [-- EXTRA reconstruct ARGS]
# --size WxH: the rendered images' size (default 640x480). DIR defaults to
# bench/out/accuracy (ignored by git); rendered scenes are kept and reused.
# --points P: sparse points of the rendered scenes (default 1500 with exact
# visibility); 0 = none, reconstruct computes tracks from the images first.
# Prints one table row per scene (and writes DIR/TAG.tsv).
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
OUT="$ROOT/bench/out/accuracy"
SIZE=640x480
KINDS="constant light clutter scale"
VIEWS=12
POINTS=1500
THREADS=2
BUILD=1
TAG=run
EXTRA=()
while [ $# -gt 0 ]; do
  case "$1" in
    --out) OUT="$2"; shift 2 ;;
    --kinds) KINDS="$2"; shift 2 ;;
    --views) VIEWS="$2"; shift 2 ;;
    --size) SIZE="$2"; shift 2 ;;
    --points) POINTS="$2"; shift 2 ;;
    --threads) THREADS="$2"; shift 2 ;;
    --skip-build) BUILD=0; shift ;;
    --tag) TAG="$2"; shift 2 ;;
    --) shift; EXTRA=("$@"); break ;;
    *) echo "run_accuracy.sh: unknown option $1" >&2; exit 2 ;;
  esac
done
export BUILD_DIR="${BUILD_DIR:-$ROOT/build-bench}"
if [ "$BUILD" = 1 ]; then
  mkdir -p "$BUILD_DIR"
  # shellcheck source=../scripts/common.sh
  source "$ROOT/scripts/common.sh"
  wild_mvs_configure -DWILD_MVS_WITH_ROS=OFF
  cmake --build "$BUILD_DIR" -j"${JOBS:-2}" --target wild_mvs make_scene >/dev/null
fi
[[ "$SIZE" =~ ^([0-9]+)x([0-9]+)$ ]] || { echo "run_accuracy.sh: --size takes WxH, not '$SIZE'" >&2; exit 2; }
WIDTH=${BASH_REMATCH[1]}
HEIGHT=${BASH_REMATCH[2]}
BIN="$BUILD_DIR/bin"
mkdir -p "$OUT"
TSV="$OUT/$TAG.tsv"
printf 'scene\tcomplete@1%%\twithin0.5%%\twithin1%%\toff>5%%\tsky\tmedian_rel\trepresented\tF@1cm\tF@2cm\tF@5cm\tP@1cm\tR@1cm\tcloud_pts\tcpu_s\trss_mb\n' >"$TSV"
for kind in $KINDS; do
  scene="$OUT/scenes/${kind}_${VIEWS}_$SIZE"
  [ "$POINTS" = 1500 ] || scene="${scene}_p$POINTS"
  if [ ! -f "$scene/sparse/points3D.txt" ]; then
    "$BIN/make_scene" "$kind" "$scene" --views "$VIEWS" --points "$POINTS" \
      --width "$WIDTH" --height "$HEIGHT" >&2
  fi
  gt="$scene/gt_cloud.ply"
  [ -f "$gt" ] || "$BIN/wild_mvs" eval make-gt-cloud --dataset "$scene" \
    --gt-dir "$scene/gt_depth" --stride 2 --voxel 0.005 "$gt" >&2
  run="$OUT/$TAG/$kind"
  rm -rf "$run"
  /usr/bin/time -f '%U %S %M' -o "$OUT/time.txt" \
    "$BIN/wild_mvs" reconstruct "$scene" "$run" --threads "$THREADS" \
    ${EXTRA[@]+"${EXTRA[@]}"} 2>"$OUT/$TAG.$kind.log"
  read -r user sys rss <"$OUT/time.txt"
  "$BIN/wild_mvs" eval depth --est "$run" --gt-dir "$scene/gt_depth" \
    --rel-thresholds 0.01,0.005,0.05 --cloud "$run/fused.ply" \
    --json "$run/eval_depth.json" >/dev/null
  "$BIN/wild_mvs" eval cloud "$run/fused.ply" "$gt" --tau 0.01,0.02,0.05 \
    --voxel 0.005 --json "$run/eval_cloud.json" >/dev/null
  python3 - "$run" "$kind" "$user" "$sys" "$rss" >>"$TSV" <<'PY'
import json, sys
run, kind, user, sys_s, rss = sys.argv[1:]
d = json.load(open(run + "/eval_depth.json"))
c = json.load(open(run + "/eval_cloud.json"))
acc = d["relative_accuracy"]; comp = d["relative_completeness"]
est = d["estimated"]
sky = d["outside_gt"] / est if est else 0
f = c["fscore"]
p = c.get("precision", []); r = c.get("recall", [])
print("\t".join([kind, "%.3f" % comp[0], "%.3f" % acc[1], "%.3f" % acc[0],
                 "%.4f" % (1 - acc[2]), "%.4f" % sky,
                 "%.5f" % d["median_rel_error"],
                 "%.3f" % d.get("cloud_represented", float("nan"))] +
                ["%.3f" % x for x in f] + ["%.3f" % p[0], "%.3f" % r[0]] +
                [str(c["reconstruction_points"]),
                 "%.1f" % (float(user) + float(sys_s)),
                 "%.0f" % (int(rss) / 1024)]))
PY
  tail -1 "$TSV" >&2
done
column -t -s $'\t' "$TSV"
