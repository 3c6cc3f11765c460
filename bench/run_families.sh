#!/usr/bin/env bash
# The benchmark of docs/METHODS.md ("Benchmark protocol"; not a test): renders
# each (family, seed) scene of bench/scenes (make_scene), runs
# `wild_mvs reconstruct` with the default options (plus EXTRA arguments
# after --, for A/B runs), scores it and prints one table: a row per scene
# and a mean row per family. Also writes OUT/TAG.tsv.
#
# Families (bench/scenes/families.h): relief, weak, courtyard (= the kinds
# constant light clutter scale; a single make_scene kind may be named too).
# Seeds: tune = 1 2 (look at these while changing the method), report =
# 101 102 (the numbers a default change is judged by), all = both, or a
# comma-separated list.
#
# Columns (depth maps pooled over the views, `wild_mvs eval depth`):
#   coverage   fraction of all ground-truth pixels with an estimate;
#   cmp@1%     fraction of all ground-truth pixels with an estimate within
#              1 % of the true depth;
#   in1%       fraction of the estimates within 1 % of the truth;
#   off>5%     fraction of the estimates off by more than 5 %;
#   sky        estimates where there is no surface, among all estimates;
# fused cloud (`wild_mvs eval cloud` of fused.ply, not thinned, against the
# scene's ground-truth surface samples gt_surface.ply: every visible
# surface, 5 mm voxels, one-view occluders excluded):
#   F@1cm F@5cm  F-score at 1 and 5 cm;
# whole `reconstruct` process (/usr/bin/time): cpu_s = user + sys seconds,
# rss_mb = peak resident memory.
#
# Usage: bench/run_families.sh [--seeds tune|report|all|S1,S2..]
#          [--families "relief weak courtyard"] [--size 640] [--views N]
#          [--points P] [--noise SIGMA] [--threads 2] [--out DIR] [--tag NAME]
#          [--from TAG] [--skip-build | --build] [-- EXTRA reconstruct ARGS]
# --size W: images W x 3W/4. --views N: instead of the family's own count
# (14 relief / weak, 12 courtyard). --noise SIGMA: image noise of the relief
# and weak families (make_scene --noise; default: the family's, 0.01). The binaries come from
# BUILD_DIR (default build-bench/): built (wild_mvs, make_scene only) when
# missing, rebuilt with --build, never with --skip-build. Rendered scenes are
# kept in OUT/scenes and reused. --from TAG: each run starts from the raw
# depth maps of OUT/TAG (a finished run of the same scenes), so only the
# consistency filter, fusion and meshing run again: for options of those
# steps (the cpu_s column then counts only them).
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
OUT="$ROOT/build-bench/families"
FAMILIES="relief weak courtyard"
SEEDS=tune
SIZE=640
VIEWS=""
POINTS=1500
NOISE=""
THREADS=2
BUILD=missing
TAG=""
FROM=""
EXTRA=()
usage() { sed -n '2,/^set -euo/p' "$0" | sed '$d; s/^# \{0,1\}//'; }
while [ $# -gt 0 ]; do
  case "$1" in
    --seeds) SEEDS="$2"; shift 2 ;;
    --families) FAMILIES="$2"; shift 2 ;;
    --size) SIZE="$2"; shift 2 ;;
    --views) VIEWS="$2"; shift 2 ;;
    --points) POINTS="$2"; shift 2 ;;
    --noise) NOISE="$2"; shift 2 ;;
    --threads) THREADS="$2"; shift 2 ;;
    --out) OUT="$2"; shift 2 ;;
    --tag) TAG="$2"; shift 2 ;;
    --from) FROM="$2"; shift 2 ;;
    --skip-build) BUILD=never; shift ;;
    --build) BUILD=always; shift ;;
    -h|--help) usage; exit 0 ;;
    --) shift; EXTRA=("$@"); break ;;
    *) echo "run_families.sh: unknown option $1 (see --help)" >&2; exit 2 ;;
  esac
done
case "$SEEDS" in
  tune) SEED_LIST="1 2" ;;
  report) SEED_LIST="101 102" ;;
  all) SEED_LIST="1 2 101 102" ;;
  *[!0-9,]*|"") echo "run_families.sh: --seeds $SEEDS: tune, report, all or numbers" >&2; exit 2 ;;
  *) SEED_LIST="${SEEDS//,/ }" ;;
esac
[[ "$SIZE" =~ ^[0-9]+$ ]] && [ "$SIZE" -ge 64 ] ||
  { echo "run_families.sh: --size $SIZE must be a width >= 64" >&2; exit 2; }
HEIGHT=$((SIZE * 3 / 4))
# Scenes: "family kind" pairs.
SCENES=()
for f in $FAMILIES; do
  case "$f" in
    courtyard) for k in constant light clutter scale; do SCENES+=("courtyard $k"); done ;;
    relief|weak) SCENES+=("$f $f") ;;
    constant|light|clutter|scale|exposure|gamma|vignetting|sun) SCENES+=("courtyard $f") ;;
    *) echo "run_families.sh: unknown family $f (relief weak courtyard, or a courtyard kind)" >&2; exit 2 ;;
  esac
done
if [ -z "$TAG" ]; then
  TAG=default
  [ ${#EXTRA[@]} -eq 0 ] || TAG=$(printf '%s_' "${EXTRA[@]}" | tr -c 'A-Za-z0-9._-' '_' | sed 's/^_*//; s/_*$//')
fi

export BUILD_DIR="${BUILD_DIR:-$ROOT/build-bench}"
BIN="$BUILD_DIR/bin"
if [ "$BUILD" = always ] || { [ "$BUILD" = missing ] && { [ ! -x "$BIN/wild_mvs" ] || [ ! -x "$BIN/make_scene" ]; }; }; then
  mkdir -p "$BUILD_DIR"
  # shellcheck source=../scripts/common.sh
  source "$ROOT/scripts/common.sh"
  if [ ! -f "$BUILD_DIR/CMakeCache.txt" ]; then
    cmake -S "$ROOT" -B "$BUILD_DIR" -DCMAKE_BUILD_TYPE=Release "${CCACHE_ARGS[@]}" \
      -DWILD_MVS_WITH_ROS=OFF -DPYTHON_EXECUTABLE=/usr/bin/python3 \
      -DPython3_EXECUTABLE=/usr/bin/python3 >"$BUILD_DIR.cmake.log" 2>&1 ||
      { cat "$BUILD_DIR.cmake.log" >&2; exit 1; }
  fi
  cmake --build "$BUILD_DIR" -j"${JOBS:-2}" --target wild_mvs make_scene >&2
fi
for b in wild_mvs make_scene; do
  [ -x "$BIN/$b" ] || { echo "run_families.sh: $BIN/$b missing (drop --skip-build)" >&2; exit 1; }
done

mkdir -p "$OUT/scenes" "$OUT/$TAG"
TSV="$OUT/$TAG.tsv"
printf 'family\tscene\tseed\tcoverage\tcmp@1%%\tin1%%\toff>5%%\tsky\tF@1cm\tF@5cm\tcpu_s\trss_mb\n' >"$TSV"
for seed in $SEED_LIST; do
  for entry in "${SCENES[@]}"; do
    read -r family kind <<<"$entry"
    views_arg=()
    [ -z "$VIEWS" ] || views_arg=(--views "$VIEWS")
    noise_arg=()
    [ "$family" = courtyard ] || [ -z "$NOISE" ] || noise_arg=(--noise "$NOISE")
    scene="$OUT/scenes/${kind}_s${seed}_${SIZE}${VIEWS:+_v$VIEWS}_p$POINTS${NOISE:+_n$NOISE}"
    if [ ! -f "$scene/gt_surface.ply" ]; then
      rm -rf "$scene"
      "$BIN/make_scene" "$kind" "$scene" --seed "$seed" --width "$SIZE" \
        --height "$HEIGHT" --points "$POINTS" ${views_arg[@]+"${views_arg[@]}"} \
        ${noise_arg[@]+"${noise_arg[@]}"} >&2
    fi
    run="$OUT/$TAG/${kind}_s$seed"
    rm -rf "$run"
    if [ -n "$FROM" ]; then
      [ -d "$OUT/$FROM/${kind}_s$seed/raw" ] ||
        { echo "run_families.sh: --from $FROM: $OUT/$FROM/${kind}_s$seed/raw missing" >&2; exit 1; }
      mkdir -p "$run"
      cp -r "$OUT/$FROM/${kind}_s$seed/raw" "$run/raw"
    fi
    log="$OUT/$TAG/${kind}_s$seed.log"
    if ! /usr/bin/time -f '%U %S %M' -o "$OUT/$TAG/time.txt" \
      "$BIN/wild_mvs" reconstruct "$scene" "$run" --threads "$THREADS" \
      ${EXTRA[@]+"${EXTRA[@]}"} >"$log" 2>&1; then
      echo "run_families.sh: reconstruct failed on $scene (see $log)" >&2
      exit 1
    fi
    read -r user sys rss <"$OUT/$TAG/time.txt"
    "$BIN/wild_mvs" eval depth --est "$run" --gt-dir "$scene/gt_depth" \
      --rel-thresholds 0.01,0.05 --json "$run/eval_depth.json" >/dev/null
    "$BIN/wild_mvs" eval cloud "$run/fused.ply" "$scene/gt_surface.ply" \
      --tau 0.01,0.05 --json "$run/eval_cloud.json" >/dev/null
    python3 - "$run" "$family" "$kind" "$seed" "$user" "$sys" "$rss" >>"$TSV" <<'PY'
import json, sys
run, family, kind, seed, user, sys_s, rss = sys.argv[1:]
d = json.load(open(run + "/eval_depth.json"))
c = json.load(open(run + "/eval_cloud.json"))
acc = d["relative_accuracy"]; comp = d["relative_completeness"]
est = d["estimated"]
print("\t".join([family, kind, seed, "%.3f" % d["completeness"],
                 "%.3f" % comp[0], "%.3f" % acc[0], "%.4f" % (1 - acc[1]),
                 "%.4f" % (d["outside_gt"] / est if est else 0)] +
                ["%.3f" % f for f in c["fscore"]] +
                ["%.1f" % (float(user) + float(sys_s)),
                 "%.0f" % (int(rss) / 1024)]))
PY
    tail -1 "$TSV" >&2
  done
done
# Mean rows per family, then the table.
python3 - "$TSV" <<'PY' >>"$TSV"
import sys
rows = [l.rstrip("\n").split("\t") for l in open(sys.argv[1])][1:]
fams = []
for r in rows:
    if r[0] not in fams: fams.append(r[0])
for f in fams:
    rs = [r for r in rows if r[0] == f]
    cols = list(zip(*[r[3:] for r in rs]))
    means = []
    for k, col in enumerate(cols):
        m = sum(float(x) for x in col) / len(col)
        means.append("%.4f" % m if k in (3, 4) else
                     "%.1f" % m if k == 7 else "%.0f" % m if k == 8 else "%.3f" % m)
    print("\t".join([f, "MEAN", "%d" % len(rs)] + means))
PY
column -t -s $'\t' "$TSV"
echo "(MEAN rows: seed column = number of scenes; $TSV)"
