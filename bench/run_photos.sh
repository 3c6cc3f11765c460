#!/usr/bin/env bash
# Photos only against the ground-truth cameras on fountain-P11 (not a test;
# docs/METHODS.md, "Photos only"): `wild_mvs photos` on the 11 photos alone
# (Debian's colmap on the CPU finds the cameras, then wild_mvs reconstruct),
# once with intrinsics per photo (the default) and once with
# --single-camera, and the same reconstruction on the dataset's
# ground-truth cameras. A photos run's cloud is in COLMAP's arbitrary frame: bench/align_cloud.py
# maps it onto the ground truth with the similarity transform that best
# aligns its camera centres to the true ones (least squares, Umeyama); then
# both clouds are scored against the ground-truth cloud (`wild_mvs eval
# cloud`, 5 mm voxels): precision, recall and F at 1, 2 and 5 cm.
#
#   bench/run_photos.sh [--size PX] [--threads N] [--out DIR] [--gt-run DIR]
# --size: working size, longest side in pixels (default 1536);
# --gt-run DIR: bench/run_fountain.sh's finished run at the same size (its
#   DIR/run_PX), instead of making one here in DIR/fountain.
# Writes DIR/photos.tsv (DIR default bench/out/photos): one row per run,
# and prints it.
# Environment: WILD_MVS_DATASETS (default ../shared/datasets of the repo),
# BUILD_DIR (default build-bench; holds bin/wild_mvs). Needs colmap.
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
DATASETS="${WILD_MVS_DATASETS:-$ROOT/../shared/datasets}"
BIN="${BUILD_DIR:-$ROOT/build-bench}/bin"
SIZE=1536
THREADS=2
OUT="$ROOT/bench/out/photos"
GT_RUN=""
while [ $# -gt 0 ]; do
  case "$1" in
    --size) SIZE="$2"; shift 2 ;;
    --threads) THREADS="$2"; shift 2 ;;
    --out) OUT="$2"; shift 2 ;;
    --gt-run) GT_RUN="$2"; shift 2 ;;
    -h|--help) sed -n '2,20p' "$0"; exit 0 ;;
    *) echo "run_photos.sh: unknown option $1 (--help)" >&2; exit 2 ;;
  esac
done
F="$DATASETS/strecha_fountain-P11"
[ -d "$F/colmap_sift_gt" ] || { echo "run_photos.sh: no $F/colmap_sift_gt (set WILD_MVS_DATASETS)" >&2; exit 1; }
[ -x "$BIN/wild_mvs" ] || { echo "run_photos.sh: no $BIN/wild_mvs (build first or set BUILD_DIR)" >&2; exit 1; }
command -v colmap >/dev/null || { echo "run_photos.sh: needs colmap (apt-get install colmap)" >&2; exit 1; }
[ -x /usr/bin/time ] || { echo "run_photos.sh: needs /usr/bin/time (apt-get install time)" >&2; exit 1; }
PY=python3
[ -x /usr/bin/python3 ] && PY=/usr/bin/python3  # Debian's, with python3-numpy
mkdir -p "$OUT"
OUT="$(cd "$OUT" && pwd)"

# The photos alone, twice: with COLMAP's intrinsics per photo (the
# default, for photos from several cameras) and with one shared set
# (--single-camera: the 11 photos come from one camera with a fixed zoom).
# The photo folder holds the 11 JPEGs (and K.txt, which is not a photo);
# nothing else of the dataset is read.
for mode in per_photo single; do
  photos="$OUT/photos_${mode}_$SIZE"
  rm -rf "$photos"
  flags=()
  [ "$mode" = single ] && flags=(--single-camera)
  echo "== fountain-P11 photos only ($mode) at $SIZE px: wild_mvs photos ${flags[*]+"${flags[*]}"}" >&2
  /usr/bin/time -f '%U %S %M' -o "$OUT/time_${mode}_$SIZE.txt" \
    "$BIN/wild_mvs" photos "$F/images" "$photos" --max-image-size "$SIZE" \
    --threads "$THREADS" ${flags[@]+"${flags[@]}"} >"$OUT/photos_${mode}_$SIZE.log" 2>&1 ||
    { tail -20 "$OUT/photos_${mode}_$SIZE.log" >&2; echo "run_photos.sh: wild_mvs photos failed" >&2; exit 1; }
done

# The ground-truth cameras: bench/run_fountain.sh's run (its reconstruct,
# ground-truth cloud, cloud scores and CPU time), made here unless given.
if [ -z "$GT_RUN" ]; then
  bash "$ROOT/bench/run_fountain.sh" --size "$SIZE" --threads "$THREADS" --out "$OUT/fountain" >/dev/null
  GT_RUN="$OUT/fountain/run_$SIZE"
fi
GT_DIR="$(cd "$GT_RUN/.." && pwd)"
for f in "$GT_RUN/fused.ply" "$GT_RUN/eval_cloud.json" "$GT_DIR/gt_cloud_s2_v0.005.ply"; do
  [ -f "$f" ] || { echo "run_photos.sh: no $f (not a bench/run_fountain.sh run)" >&2; exit 1; }
done
GT="$GT_DIR/gt_cloud_s2_v0.005.ply"
cp "$GT_RUN/eval_cloud.json" "$OUT/eval_gt_$SIZE.json"
[ ! -f "$GT_DIR/time_$SIZE.txt" ] || cp "$GT_DIR/time_$SIZE.txt" "$OUT/time_gt_$SIZE.txt"
for mode in per_photo single; do
  photos="$OUT/photos_${mode}_$SIZE"
  "$PY" "$ROOT/bench/align_cloud.py" "$GT_RUN/cameras" "$photos/cameras" \
    "$photos/fused.ply" "$OUT/aligned_${mode}_$SIZE.ply" >"$OUT/align_${mode}_$SIZE.json"
  "$BIN/wild_mvs" eval cloud "$OUT/aligned_${mode}_$SIZE.ply" "$GT" --tau 0.01,0.02,0.05 \
    --voxel 0.005 --json "$OUT/eval_${mode}_$SIZE.json" >/dev/null
done
"$PY" - "$OUT" "$SIZE" >"$OUT/photos.tsv" <<'PY'
import json, re, sys
out, size = sys.argv[1:]
print("cameras\tsize\tregistered\tcentre_rms_mm\tcloud_pts\tF@1cm\tF@2cm\tF@5cm\tcpu_s")
for mode, label in (("gt", "ground truth"), ("per_photo", "photos only, intrinsics per photo"),
                    ("single", "photos only, --single-camera")):
    c = json.load(open(f"{out}/eval_{mode}_{size}.json"))
    try:
        user, sys_s, _ = open(f"{out}/time_{mode}_{size}.txt").read().split()
        cpu = "%.0f" % (float(user) + float(sys_s))
    except (OSError, ValueError):
        cpu = "-"
    registered, rms = "11/11", "0"
    if mode != "gt":
        log = open(f"{out}/photos_{mode}_{size}.log").read()
        m = re.search(r"(\d+) of (\d+) photos registered", log)
        registered = f"{m.group(1)}/{m.group(2)}" if m else "?"
        rms = "%.1f" % (1000 * json.load(open(f"{out}/align_{mode}_{size}.json"))["centre_rms"])
    print("\t".join([label, size, registered, rms, str(c["reconstruction_points"])] +
                    ["%.4f" % x for x in c["fscore"]] + [cpu]))
PY
column -t -s $'\t' "$OUT/photos.tsv"
