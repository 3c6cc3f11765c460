#!/usr/bin/env bash
# Quality benchmark on fountain-P11 (not a test): `wild_mvs reconstruct`
# (depth maps and fused cloud, default options) of all 11 views at a working
# size (default 1536x1024), scored against the dataset's ground-truth depth
# (docs/METHODS.md):
#   depth maps (`wild_mvs eval depth --dataset`, pooled over the views):
#     coverage (GT pixels with an estimate), within 1 % (of the estimates
#     with GT), off > 5 %, background (estimates without GT, of all
#     estimates), median absolute error;
#   fused cloud (`wild_mvs eval cloud` against a cloud made from the GT
#     depth, every 2nd pixel at full resolution, both thinned to 5 mm
#     voxels): precision, recall and F at 1, 2 and 5 cm;
#   whole-process CPU seconds (user + sys) and peak RSS of the reconstruct.
#
#   bench/run_fountain.sh [--size PX] [--threads N] [--out DIR]
#                         [-- EXTRA reconstruct ARGS]
# Writes DIR/fountain.tsv (one row; DIR default bench/out/fountain) and
# prints it. The GT cloud is made once and kept in DIR.
# Environment: WILD_MVS_DATASETS (default ../shared/datasets of the repo),
# BUILD_DIR (default build-bench; holds bin/wild_mvs).
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
DATASETS="${WILD_MVS_DATASETS:-$ROOT/../shared/datasets}"
BIN="${BUILD_DIR:-$ROOT/build-bench}/bin"
SIZE=1536
THREADS=2
OUT="$ROOT/bench/out/fountain"
EXTRA=()
while [ $# -gt 0 ]; do
  case "$1" in
    --size) SIZE="$2"; shift 2 ;;
    --threads) THREADS="$2"; shift 2 ;;
    --out) OUT="$2"; shift 2 ;;
    -h|--help) sed -n '2,22p' "$0"; exit 0 ;;
    --) shift; EXTRA=("$@"); break ;;
    *) echo "run_fountain.sh: unknown option $1 (--help)" >&2; exit 2 ;;
  esac
done
F="$DATASETS/strecha_fountain-P11"
[ -d "$F/colmap_sift_gt" ] || { echo "run_fountain.sh: no $F/colmap_sift_gt (set WILD_MVS_DATASETS)" >&2; exit 1; }
[ -x "$BIN/wild_mvs" ] || { echo "run_fountain.sh: no $BIN/wild_mvs (build first or set BUILD_DIR)" >&2; exit 1; }
[ -x /usr/bin/time ] || { echo "run_fountain.sh: needs /usr/bin/time (apt-get install time)" >&2; exit 1; }
mkdir -p "$OUT"
run="$OUT/run_$SIZE"
rm -rf "$run"
echo "== fountain-P11 at $SIZE px: wild_mvs reconstruct --stages depth,fuse" >&2
/usr/bin/time -f '%U %S %M' -o "$OUT/time_$SIZE.txt" \
  "$BIN/wild_mvs" reconstruct "$F" "$run" --model "$F/colmap_sift_gt" --images "$F/images" \
  --max-image-size "$SIZE" --stages depth,fuse --threads "$THREADS" \
  ${EXTRA[@]+"${EXTRA[@]}"} >"$OUT/reconstruct_$SIZE.log" 2>&1 ||
  { tail -20 "$OUT/reconstruct_$SIZE.log" >&2; echo "run_fountain.sh: reconstruct failed" >&2; exit 1; }
"$BIN/wild_mvs" eval depth --est "$run" --dataset "$F" \
  --rel-thresholds 0.01,0.005,0.05 --json "$run/eval_depth.json" >/dev/null
GT="$OUT/gt_cloud_s2_v0.005.ply"
[ -f "$GT" ] || "$BIN/wild_mvs" eval make-gt-cloud --dataset "$F" --stride 2 --voxel 0.005 "$GT" >&2
"$BIN/wild_mvs" eval cloud "$run/fused.ply" "$GT" --tau 0.01,0.02,0.05 --voxel 0.005 \
  --json "$run/eval_cloud.json" >/dev/null
read -r user sys rss <"$OUT/time_$SIZE.txt"
python3 - "$run" "$SIZE" "$user" "$sys" "$rss" >"$OUT/fountain.tsv" <<'PY'
import json, sys
run, size, user, sys_s, rss = sys.argv[1:]
d = json.load(open(run + "/eval_depth.json"))
c = json.load(open(run + "/eval_cloud.json"))
acc = d["relative_accuracy"]
est = d["estimated"]
print("size\tsamples\tcoverage\twithin1%\twithin0.5%\toff>5%\tbackground\tmedian_abs_mm"
      "\tF@1cm\tF@2cm\tF@5cm\tcloud_pts\tcpu_s\trss_mb")
print("\t".join([size, str(est), "%.4f" % d["completeness"], "%.4f" % acc[0],
                 "%.4f" % acc[1], "%.4f" % (1 - acc[2]),
                 "%.4f" % (d["outside_gt"] / est if est else 0),
                 "%.1f" % (1000 * d["median_abs_error"])] +
                ["%.4f" % x for x in c["fscore"]] +
                [str(c["reconstruction_points"]), "%.1f" % (float(user) + float(sys_s)),
                 "%.0f" % (int(rss) / 1024)]))
PY
column -t -s $'\t' "$OUT/fountain.tsv"
