#!/usr/bin/env bash
# The benchmark set in one command (not a test): builds what it needs,
# runs every benchmark and writes docs/RESULTS.md (machine, commit, date;
# one table per benchmark; plots docs/results_*.png) and README's results
# block (between <!-- results:begin --> and <!-- results:end -->) from
# the same run. docs/METHODS.md says how each figure is measured.
#   speed     bench/run_bench.sh --only temple: depth stage on
#             data/templeSparseRing, correct samples per CPU-s, median of 3;
#   fountain  bench/run_fountain.sh: fountain-P11 at 1536x1024 against its
#             ground-truth depth (coverage, within 1 %, off > 5 %,
#             background) and the fused cloud's F at 1 / 2 / 5 cm;
#   photos    bench/run_photos.sh: fountain-P11 from its photos alone
#             (`wild_mvs photos`, Debian's colmap) against the same
#             reconstruction on the ground-truth cameras, F at 1 / 2 / 5 cm
#             after a similarity alignment by the camera centres; needs
#             colmap, else not run;
#   families  bench/run_families.sh: the rendered scene families with
#             exact ground truth (relief, weak, courtyard), report seeds;
#   ablation  bench/run_ablation.sh: the same families at 320x240 with each
#             mechanism of the method switched off in turn and each
#             threshold moved one step (the wide-window ones on fountain-P11,
#             the tracker's on the same families without sparse points);
#             written to docs/ABLATION.md, not RESULTS.md; it takes longer
#             than the rest together, so `--skip ablation` and a separate
#             `bench/run_ablation.sh --out OUT/ablation` are the usual way;
#   scale     bench/run_scale.sh: CPU-s per view and peak RSS against the
#             number of views (100 / 250 / 500);
#   live      bench/run_live.sh: the depth and fusion nodes on a bag of a
#             rendered scene against `wild_mvs reconstruct` on the same
#             images (relief and courtyard light, seed 101); needs the ROS
#             build in build/ (scripts/run_tests.sh makes it), else not run.
# Peers: with OPENMVS_BIN (the folder of OpenMVS's InterfaceCOLMAP and
# DensifyPointCloud) OpenMVS runs beside wild_mvs on templeSparseRing
# (bench/run_openmvs.sh), with MVE_BIN (the folder of MVE's dmrecon) MVE
# runs beside it on templeSparseRing and fountain-P11 (bench/run_mve.sh),
# full setting only; otherwise RESULTS.md shows their recorded figures
# (bench/peers/*.tsv), marked "recorded, not run here".
#
# Usage: bench/run_all.sh [--quick] [--skip LIST] [--threads N] [--out DIR]
#                         [--skip-build]
#   --quick      smaller sizes and one run each (temple 320 px, fountain
#                384 px, rendered scenes at 320x240 with one seed,
#                collections of 10 / 20 / 40 views at 160 px): minutes
#                instead of hours; RESULTS.md says so at the top
#   --skip LIST  comma-separated sections not to run (speed, fountain,
#                photos, families, ablation, scale, live); RESULTS.md lists
#                them as not run
#   --out DIR    raw outputs (default bench/out/all-<UTC time>, ignored by git)
# Environment: WILD_MVS_DATASETS (default ../shared/datasets of the repo;
# fountain needs it, temple uses its GT model when present), BUILD_DIR
# (default build-bench), OPENMVS_BIN, MVE_BIN.
# Installs what it needs (scripts/install_deps.sh --no-ros --tests --bench: the
# build dependencies, time, bc, python3-matplotlib) unless --skip-build.
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
QUICK=0
SKIP=""
THREADS=2
OUT=""
BUILD=1
ARGS=("$@")
while [ $# -gt 0 ]; do
  case "$1" in
    --quick) QUICK=1; shift ;;
    --skip) SKIP="$2"; shift 2 ;;
    --threads) THREADS="$2"; shift 2 ;;
    --out) OUT="$2"; shift 2 ;;
    --skip-build) BUILD=0; shift ;;
    -h|--help) sed -n '2,/^set -euo/p' "$0" | sed '$d'; exit 0 ;;
    *) echo "run_all.sh: unknown option $1 (--help)" >&2; exit 2 ;;
  esac
done
for s in ${SKIP//,/ }; do
  case "$s" in speed | fountain | photos | families | ablation | scale | live) ;; *)
    echo "run_all.sh: --skip takes speed, fountain, photos, families, ablation, scale, live; not '$s'" >&2; exit 2 ;;
  esac
done
skipped() { [[ ",$SKIP," == *",$1,"* ]]; }
# shellcheck source=run_meta.sh
source "$ROOT/bench/run_meta.sh"
[ "$BUILD" = 0 ] || bash "$ROOT/scripts/install_deps.sh" --no-ros --tests --bench
for tool in /usr/bin/time bc; do
  command -v "$tool" >/dev/null || { echo "run_all.sh: needs $tool (apt-get install time bc)" >&2; exit 1; }
done
PY=python3
[ -x /usr/bin/python3 ] && PY=/usr/bin/python3  # Debian's, with python3-matplotlib
"$PY" -c 'import matplotlib' 2>/dev/null ||
  { echo "run_all.sh: needs matplotlib (apt-get install python3-matplotlib)" >&2; exit 1; }
DATASETS="${WILD_MVS_DATASETS:-$ROOT/../shared/datasets}"
if ! skipped fountain && [ ! -d "$DATASETS/strecha_fountain-P11" ]; then
  echo "run_all.sh: no $DATASETS/strecha_fountain-P11 (set WILD_MVS_DATASETS or --skip fountain)" >&2
  exit 1
fi
# The code measured: the tree as the run starts (edits made while it runs
# are not in its binaries); a tree changed by the end is said too.
CODE_META="$(run_meta_code "$ROOT")"
[ -n "$OUT" ] || OUT="$ROOT/bench/out/all-$(date -u +%Y%m%dT%H%M%S)"
mkdir -p "$OUT"
OUT="$(cd "$OUT" && pwd)"

export BUILD_DIR="${BUILD_DIR:-$ROOT/build-bench}"
FAMILIES_SCRIPT="$ROOT/bench/run_families.sh"
if [ "$BUILD" = 1 ]; then
  # shellcheck source=../scripts/common.sh
  source "$ROOT/scripts/common.sh"
  mkdir -p "$BUILD_DIR"
  wild_mvs_configure -DWILD_MVS_WITH_ROS=OFF -DWILD_MVS_BUILD_TESTS=ON
  cmake --build "$BUILD_DIR" -j"${JOBS:-2}" --target wild_mvs bench_depth_stats \
    make_scene make_collection
fi

if [ "$QUICK" = 1 ]; then
  RUNS=1 TEMPLE_SIZE=320 FOUNTAIN_SIZE=384 VIEWS=8 SCENE_SIZE=320x240 FAMILY_SEEDS=101
  SCALE_SIZES=10,20,40 SCALE_PX=160
else
  RUNS=3 TEMPLE_SIZE=0 FOUNTAIN_SIZE=1536 VIEWS=12 SCENE_SIZE=640x480 FAMILY_SEEDS=report
  SCALE_SIZES=100,250,500 SCALE_PX=240
fi

# A section that fails is reported as failed in RESULTS.md; the others run.
FAILED=""
failed() {
  echo "run_all.sh: the $1 benchmark failed (see above)" >&2
  FAILED="$FAILED${FAILED:+,}$1"
}
if ! skipped speed; then
  bash "$ROOT/bench/run_bench.sh" --skip-build --only temple --runs "$RUNS" \
    --threads "$THREADS" --temple-size "$TEMPLE_SIZE" --results "$OUT/speed" || failed speed
fi
if ! skipped fountain; then
  bash "$ROOT/bench/run_fountain.sh" --size "$FOUNTAIN_SIZE" --threads "$THREADS" \
    --out "$OUT/fountain" || failed fountain
fi
PHOTOS_NOTE=""
if ! skipped photos; then
  if ! command -v colmap >/dev/null; then
    PHOTOS_NOTE="Not run: needs colmap (apt-get install colmap)."
  else
    GT_ARGS=()
    [ -f "$OUT/fountain/run_$FOUNTAIN_SIZE/fused.ply" ] &&
      GT_ARGS=(--gt-run "$OUT/fountain/run_$FOUNTAIN_SIZE")
    bash "$ROOT/bench/run_photos.sh" --size "$FOUNTAIN_SIZE" --threads "$THREADS" \
      --out "$OUT/photos" ${GT_ARGS[@]+"${GT_ARGS[@]}"} || failed photos
  fi
fi
FAMILIES_NOTE=""
if ! skipped families; then
  mkdir -p "$OUT/families"
  if [ -f "$FAMILIES_SCRIPT" ]; then
    # Each family with its own number of views (fewer views leave parts of
    # the relief and weak scenes seen by too few views).
    if bash "$FAMILIES_SCRIPT" --skip-build --seeds "$FAMILY_SEEDS" --size "${SCENE_SIZE%x*}" \
      --threads "$THREADS" --out "$OUT/families_work" --tag default; then
      # One table per family (the family column dropped).
      awk -F'\t' -v dir="$OUT/families" 'NR == 1 { h = $0; sub(/^[^\t]*\t/, "", h); next }
      { f = dir "/" $1 ".tsv"; if (!(f in seen)) { print h > f; seen[f] = 1 }
        line = $0; sub(/^[^\t]*\t/, "", line); print line > f }' \
        "$OUT/families_work/default.tsv"
    else
      failed families
    fi
    FAMILIES_NOTE="\`bench/run_families.sh --seeds $FAMILY_SEEDS\` (docs/METHODS.md, \"Benchmark protocol\"): one table per family, a row per scene and seed, and a MEAN row (its seed column: the number of scenes); images $SCENE_SIZE. Coverage = ground-truth pixels with an estimate; coverage within 1 % = with an estimate within 1 %; sky = estimates where there is no surface; F against the scene's ground-truth surface samples."
  else
    bash "$ROOT/bench/run_accuracy.sh" --skip-build --views "$VIEWS" --size "$SCENE_SIZE" \
      --threads "$THREADS" --out "$OUT/accuracy" --tag courtyard &&
      cp "$OUT/accuracy/courtyard.tsv" "$OUT/families/courtyard.tsv" || failed families
    FAMILIES_NOTE="\`bench/run_accuracy.sh\`: the courtyard scene (ground, wall, boxes, a pillar, spheres under a sky) in four kinds: constant light; changing light (exposure, white balance, gamma, vignetting, sun direction); clutter (an occluder seen by one view only, every other view); scale (camera distances over a 3.75x range); $VIEWS views at $SCENE_SIZE, whole \`reconstruct\` (depth, filter, fusion, mesh). Coverage within 1 % = ground-truth pixels with an estimate within 1 %; sky = estimates where there is no surface."
  fi
fi
if ! skipped ablation; then
  ABLATION_ARGS=(--seeds report)
  [ "$QUICK" = 0 ] || ABLATION_ARGS=(--seeds 101 --wide-moves none)
  bash "$ROOT/bench/run_ablation.sh" --skip-build "${ABLATION_ARGS[@]}" \
    --threads "$THREADS" --out "$OUT/ablation" || failed ablation
fi
SCALE_ARGS="--sizes $SCALE_SIZES --max-image-size $SCALE_PX --threads $THREADS"
if ! skipped scale; then
  # shellcheck disable=SC2086  # a list of flags
  bash "$ROOT/bench/run_scale.sh" $SCALE_ARGS --work "$OUT/scale_work" \
    --results "$OUT/scale" || failed scale
fi
LIVE_NOTE=""
if ! skipped live; then
  if [ -x "$ROOT/devel/lib/wild_mvs/bench_live_depth_maps" ]; then
    BUILD_DIR="$ROOT/build" bash "$ROOT/bench/run_live.sh" --skip-build \
      --families "relief courtyard" --seeds 101 --size "${SCENE_SIZE%x*}" \
      --out "$OUT/live" || failed live
  else
    LIVE_NOTE="Not run: needs the ROS build in build/ (bash scripts/run_tests.sh makes it)."
  fi
fi

# Peers beside wild_mvs, where their binaries are given (full setting only:
# their recorded figures are at the full sizes). Each adds its rows to
# OUT/peers/speed_temple.tsv and fountain.tsv (add_peer_rows).
add_peer_rows() {  # SRC_TSV DST_TSV: SRC's rows (and header if DST is new)
  if [ -f "$2" ]; then tail -n +2 "$1" >>"$2"; else cp "$1" "$2"; fi
}
if [ -n "${MVE_BIN:-}" ] && [ "$QUICK" = 0 ]; then
  mkdir -p "$OUT/peers"
  if MVE_BIN="$MVE_BIN" WILD_MVS_BIN="$BUILD_DIR/bin" bash "$ROOT/bench/run_mve.sh" \
    --threads "$THREADS" --out "$OUT/mve"; then
    for t in speed_temple fountain; do
      add_peer_rows "$OUT/mve/peers/$t.tsv" "$OUT/peers/$t.tsv"
    done
  else
    echo "run_all.sh: bench/run_mve.sh failed; RESULTS.md shows MVE's recorded figures" >&2
  fi
fi
if [ -n "${OPENMVS_BIN:-}" ] && [ "$QUICK" = 0 ]; then
  WILD_MVS_BIN="$BUILD_DIR/bin" bash "$ROOT/bench/run_openmvs.sh" --threads "$THREADS" \
    --out "$OUT/openmvs" --cloud
  "$PY" - "$OUT/openmvs" "$THREADS" <<'PY'
import os, re, sys
src, threads = sys.argv[1:]
def kv(line):
    return dict(re.findall(r"(\w[\w.]*)=([^\s]+)", line))
t = open(os.path.join(src, "temple", "summary.txt")).read().splitlines()
cpu = re.search(r"DensifyPointCloud ([\d.]+) CPU-s", t[0]).group(1)
rss = re.search(r"peak RSS (\d+) MB", t[0]).group(1)
s = kv(t[1])
os.makedirs(os.path.join(src, "peers"), exist_ok=True)
with open(os.path.join(src, "peers", "speed_temple.tsv"), "w") as f:
    f.write("system\tsize\tcpu_s\tsamples\tcorrect\tcorrect_per_cpu_s\tpeak_rss_mb\tsource\n")
    f.write(f"OpenMVS DensifyPointCloud\t640\t{cpu}\t{s['samples']}\t{s['correct']}\t"
            f"{s['correct_per_cpu_s']}\t{rss}\t"
            f"bench/run_openmvs.sh, default options, {threads} threads, one run\n")
PY
  mkdir -p "$OUT/peers"
  add_peer_rows "$OUT/openmvs/peers/speed_temple.tsv" "$OUT/peers/speed_temple.tsv"
fi

{
  printf 'key\tvalue\n'
  printf 'command\tbench/run_all.sh%s\n' "$(printf ' %s' "${ARGS[@]+"${ARGS[@]}"}")"
  printf 'mode\t%s\n' "$([ "$QUICK" = 1 ] && echo quick || echo full)"
  run_meta_machine
  if [ "$(run_meta_code "$ROOT")" = "$CODE_META" ]; then
    printf '%s\n' "$CODE_META"
  else
    printf '%s\n' "$CODE_META" | sed '/^commit/s/$/ (src or include edited during the run)/'
  fi
  run_meta_now
  printf 'threads\t%s\n' "$THREADS"
  if [ "$QUICK" = 1 ]; then
    printf 'setting\tquick: temple 320 px, 1 run; fountain 384 px; rendered scenes at %s, seed %s; collections of %s views at %s px\n' \
      "$SCENE_SIZE" "$FAMILY_SEEDS" "$SCALE_SIZES" "$SCALE_PX"
  else
    printf 'setting\tfull: temple 640 px, median of 3; fountain 1536 px; rendered scenes at %s, %s seeds; collections of %s views at %s px\n' \
      "$SCENE_SIZE" "$FAMILY_SEEDS" "$SCALE_SIZES" "$SCALE_PX"
  fi
  printf 'temple_size\t%s\n' "$([ "$TEMPLE_SIZE" = 0 ] && echo 640 || echo "$TEMPLE_SIZE")"
  printf 'skipped\t%s\n' "$SKIP"
  printf 'failed\t%s\n' "$FAILED"
  printf 'families_note\t%s\n' "$FAMILIES_NOTE"
  printf 'scale_args\t%s\n' "$SCALE_ARGS"
  printf 'live_note\t%s\n' "$LIVE_NOTE"
  printf 'photos_note\t%s\n' "$PHOTOS_NOTE"
  printf 'scene_size\t%s\n' "$SCENE_SIZE"
} >"$OUT/meta.tsv"
"$PY" "$ROOT/bench/make_results.py" "$OUT" "$ROOT"
echo "run_all.sh: wrote docs/RESULTS.md, docs/results_*.png and README's results block (raw outputs in $OUT)" >&2
