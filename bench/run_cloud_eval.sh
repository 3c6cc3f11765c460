#!/bin/bash
# Scores a reconstruct folder's fused cloud and mesh vertices against a
# ground-truth cloud made from the dataset's ground-truth depth maps, and
# prints one table (fountain-P11's cloud figures, docs/METHODS.md).
#
#   bench/run_cloud_eval.sh [--bin WILD_MVS] [--tau LIST] [--gt GT.ply]
#                           [--gt-stride N] [--gt-voxel V] [--reconstruct ARGS]
#                           DATASET OUT
#
# --reconstruct "ARGS": first run `wild_mvs reconstruct DATASET OUT ARGS`
#   (resumable: views already done are skipped), e.g.
#   --reconstruct "--max-image-size 1536 --threads 2".
# --gt GT.ply: the ground-truth cloud; made with `wild_mvs eval
#   make-gt-cloud --dataset DATASET --stride N --voxel V` when missing
#   (default OUT/../gt_cloud_sN_vV.ply; stride 2 of the dataset's full
#   resolution, 5 mm voxels).
# Writes OUT/eval_cloud.json and OUT/eval_mesh.json. Rows: accuracy = the
# distance within which 90 % of the reconstructed points lie; completeness
# = the distance within which 90 % of the GT points have a reconstructed
# point; then precision, recall (= completeness at tau) and F per tau.
#
# Example (fountain-P11 at half resolution):
#   bench/run_cloud_eval.sh --reconstruct "--max-image-size 1536" \
#     ../shared/datasets/strecha_fountain-P11 /tmp/fountain_1536
set -euo pipefail

ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
BIN="${WILD_MVS:-$ROOT/build/bin/wild_mvs}"
TAU=0.01,0.02,0.05
GT=""
STRIDE=2
VOXEL=0.005
RECON=""
POS=()
while [[ $# -gt 0 ]]; do
  case "$1" in
    --bin) BIN="$2"; shift 2 ;;
    --tau) TAU="$2"; shift 2 ;;
    --gt) GT="$2"; shift 2 ;;
    --gt-stride) STRIDE="$2"; shift 2 ;;
    --gt-voxel) VOXEL="$2"; shift 2 ;;
    --reconstruct) RECON="$2"; shift 2 ;;
    -h|--help) awk 'NR > 1 && /^#/ { sub(/^# ?/, ""); print; next } NR > 1 { exit }' "$0"; exit 0 ;;
    -*) echo "run_cloud_eval.sh: unknown option $1" >&2; exit 2 ;;
    *) POS+=("$1"); shift ;;
  esac
done
[[ ${#POS[@]} -eq 2 ]] || { echo "usage: $0 [options] DATASET OUT (--help)" >&2; exit 2; }
DATASET="${POS[0]}"
OUT="${POS[1]}"
[[ -x "$BIN" ]] || { echo "run_cloud_eval.sh: $BIN is not executable (build first)" >&2; exit 1; }

if [[ -n "$RECON" ]]; then
  # shellcheck disable=SC2086  # ARGS is a list of flags
  /usr/bin/time -f "reconstruct: %e s wall, %U s user, %S s sys, peak RSS %M KB" \
    "$BIN" reconstruct "$DATASET" "$OUT" $RECON
fi
for f in fused.ply mesh.ply; do
  [[ -f "$OUT/$f" ]] || { echo "run_cloud_eval.sh: $OUT/$f is missing" >&2; exit 1; }
done
if [[ -z "$GT" ]]; then
  GT="$(dirname "$OUT")/gt_cloud_s${STRIDE}_v${VOXEL}.ply"
fi
if [[ ! -f "$GT" ]]; then
  "$BIN" eval make-gt-cloud --dataset "$DATASET" --stride "$STRIDE" --voxel "$VOXEL" "$GT"
fi
for what in cloud mesh; do
  ply="$OUT/fused.ply"
  [[ "$what" == mesh ]] && ply="$OUT/mesh.ply"
  "$BIN" eval cloud "$ply" "$GT" --tau "$TAU" --json "$OUT/eval_$what.json" >/dev/null
done

python3 - "$OUT" "$GT" <<'EOF'
import json, sys
out, gt = sys.argv[1], sys.argv[2]
rows = {w: json.load(open(f"{out}/eval_{w}.json")) for w in ("cloud", "mesh")}
def cm(x):
    return "inf" if x is None else f"{100 * x:.2f}"
print(f"ground truth: {gt} ({rows['cloud']['gt_points']} points)")
print(f"{'':6} {'points':>9} {'acc90 cm':>9} {'comp90 cm':>10} {'tau cm':>7} "
      f"{'precision':>10} {'recall':>8} {'F':>7}")
for w, r in rows.items():
    for k, tau in enumerate(r["taus"]):
        head = (f"{w:6} {r['reconstruction_points']:9d} {cm(r['accuracy']):>9} "
                f"{cm(r['completeness_distance']):>10}") if k == 0 else " " * 37
        print(f"{head} {100 * tau:7.1f} {100 * r['precision'][k]:9.1f}% "
              f"{100 * r['recall'][k]:7.1f}% {100 * r['fscore'][k]:6.1f}%")
EOF
