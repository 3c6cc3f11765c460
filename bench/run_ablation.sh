#!/usr/bin/env bash
# Does each mechanism and each threshold earn its place? (not a test;
# docs/METHODS.md, "Benchmark protocol"). Runs bench/run_families.sh with the
# default options, then once per switch of the method with that switch off
# (`--ablation.NAME false`, core/ablation.h), then once per move of a
# numeric option one step away from its default (`--KEY VALUE`), on the same
# rendered scenes. Writes OUT/default.tsv, OUT/no_NAME.tsv and
# OUT/set_KEY_VALUE.tsv (run_families.sh's table), and OUT/meta.tsv (the
# machine and the code). `bench/make_results.py` writes docs/ABLATION.md from
# them (OUT is then the folder ablation/ of its argument) and shows them
# side by side: a mechanism whose absence, or a value, that is at
# least as good on every family, in coverage within 1 % and in estimates off
# by more than 5 % (for fusion options: the cloud's F-scores), is one the
# policy deletes or makes the default (after the same result on other
# seeds). Moves of consistency.* and fusion.* start from the default run's
# raw depth maps (run_families.sh --from): the matching is the same.
# The wide_* thresholds apply only to images of 1200 px and more: they are
# moved on fountain-P11 at 1536 px instead (bench/run_fountain.sh into
# OUT/fountain_default and OUT/fountain_set_KEY_VALUE; skipped with a note
# when the datasets are absent). A table that already has its family means
# (or a fountain.tsv) in OUT is not run again (delete it to redo it).
# The tracker's thresholds matter only where the tool makes its own tracks:
# they are moved on the same families rendered without sparse points
# (run_families.sh --points 0, `--stages sparse,depth,fuse,mesh`), against
# that setting's own default run (OUT/tracker_default.tsv,
# OUT/tracker_set_KEY_VALUE.tsv).
#
# Usage: bench/run_ablation.sh [--seeds report|S1,S2..] [--size 320]
#          [--families "relief weak courtyard"] [--switches "a b ..|none"]
#          [--moves "KEY=VALUE ..|none"] [--wide-moves "KEY=VALUE ..|none"]
#          [--tracker-moves "KEY=VALUE ..|none"]
#          [--threads 2] [--out DIR] [--skip-build]
# Defaults: report seeds, images 320x240, every switch, the moves below.
# A switch or a move of a matching option costs the time of one family run
# (about 3 min on 2 idle cores); a move of a filter or fusion option a
# fifth of it.
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
SEEDS=report
SIZE=320
FAMILIES="relief weak courtyard"
SWITCHES=""  # default: every switch the tool registers under ablation.
# One step to each side of the default (one where the default is at the end
# of the range or the other side is not a value anyone would choose). The
# wide_* thresholds apply only to images of 1200 px and more (not these).
MOVES="mvs.local.min_ncc=0.2 mvs.local.min_ncc=0.4
  mvs.mpgc.drop_ncc=0.3 mvs.mpgc.drop_ncc=0.5
  mvs.mpgc.min_active_views=2 mvs.mpgc.min_active_views=4
  mvs.local.num_active=3 mvs.local.num_active=5
  mvs.global.num_neighbors=6 mvs.global.num_neighbors=14
  mvs.mpgc.window=3 mvs.mpgc.window=7
  mvs.mpgc.explain_margin=0.1
  mvs.mpgc.explain_below_ncc=0.7 mvs.mpgc.explain_below_ncc=0.9
  mvs.mpgc.bilateral_sigma_color=6 mvs.mpgc.bilateral_sigma_color=24
  mvs.mpgc.bilateral_sigma_space=3 mvs.mpgc.bilateral_sigma_space=12
  mvs.mpgc.bilateral_min_weight=0.25 mvs.mpgc.bilateral_min_weight=0.75
  mvs.growing.revisit_margin=0 mvs.growing.revisit_margin=0.2
  mvs.sweep.below_seeds=1 mvs.sweep.below_seeds=100
  consistency.min_consistent=2
  consistency.max_reprojection_px=0.5 consistency.max_reprojection_px=2
  consistency.max_relative_depth=0.005 consistency.max_relative_depth=0.02
  consistency.free_space_margin=0.005 consistency.free_space_margin=0.02
  fusion.min_support=2 fusion.min_support=4
  fusion.depth_tolerance=0.005 fusion.depth_tolerance=0.02
  fusion.reprojection_tolerance_px=1 fusion.reprojection_tolerance_px=4
  fusion.normal_tolerance_deg=10 fusion.normal_tolerance_deg=40"
WIDE_MOVES="mvs.local.wide_min_ncc=0.06 mvs.local.wide_min_ncc=0.2
  mvs.mpgc.wide_drop_ncc=0.12 mvs.mpgc.wide_drop_ncc=0.32"
# tracker.features.max_image_size (2000 px) does not act on these sizes.
TRACKER_MOVES="tracker.features.max_features=2000 tracker.features.max_features=8000
  tracker.max_neighbors=6 tracker.max_neighbors=10
  tracker.max_reprojection_error=1 tracker.max_reprojection_error=4
  tracker.min_triangulation_angle_deg=1 tracker.min_triangulation_angle_deg=4
  tracker.min_track_length=3"
THREADS=2
OUT="$ROOT/build-bench/ablation"
BUILD_ARG=()
while [ $# -gt 0 ]; do
  case "$1" in
    --seeds) SEEDS="$2"; shift 2 ;;
    --size) SIZE="$2"; shift 2 ;;
    --families) FAMILIES="$2"; shift 2 ;;
    --switches) SWITCHES="$2"; shift 2 ;;
    --moves) MOVES="$2"; shift 2 ;;
    --wide-moves) WIDE_MOVES="$2"; shift 2 ;;
    --tracker-moves) TRACKER_MOVES="$2"; shift 2 ;;
    --threads) THREADS="$2"; shift 2 ;;
    --out) OUT="$2"; shift 2 ;;
    --skip-build) BUILD_ARG=(--skip-build); shift ;;
    -h|--help) sed -n '2,/^set -euo/p' "$0" | sed '$d; s/^# \{0,1\}//'; exit 0 ;;
    *) echo "run_ablation.sh: unknown option $1 (see --help)" >&2; exit 2 ;;
  esac
done
mkdir -p "$OUT"
OUT=$(cd "$OUT" && pwd)
if [ -f "$OUT/setting.tsv" ]; then  # tables of another setting are not reused
  was=$(awk -F'\t' '$1 == "size" || $1 == "seeds" { printf "%s ", $2 }' "$OUT/setting.tsv")
  [ "$was" = "$SIZE $SEEDS " ] || {
    echo "run_ablation.sh: $OUT holds tables of size/seeds $was; use another --out" >&2
    exit 2
  }
fi
# Nor tables of other code: OUT/meta.tsv records the machine and the code
# (bench/run_meta.sh) of the first table; a later call on other code (src,
# include, CMakeLists.txt) stops. Its date and load are those of the last
# call.
# shellcheck source=run_meta.sh
source "$ROOT/bench/run_meta.sh"
CODE_NOW=$(run_meta_code "$ROOT")
if [ -f "$OUT/meta.tsv" ]; then
  code_was=$(awk -F'\t' '$1 == "code" { print $2 }' "$OUT/meta.tsv")
  code_now=$(awk -F'\t' '$1 == "code" { print $2 }' <<<"$CODE_NOW")
  [ "$code_was" = "$code_now" ] && [[ "$code_now" != *+changes ]] || {
    echo "run_ablation.sh: $OUT holds tables of other code ($code_was, now $code_now); use another --out" >&2
    exit 2
  }
  META_HEAD=$(awk -F'\t' '$1 != "date" && $1 != "load"' "$OUT/meta.tsv")
else
  META_HEAD=$(printf 'key\tvalue\n'; run_meta_machine; printf '%s\n' "$CODE_NOW")
fi
printf '%s\n' "$META_HEAD" >"$OUT/meta.tsv"
run_meta_now >>"$OUT/meta.tsv"
done_already() {  # the table exists with its family means
  [ -f "$OUT/$1.tsv" ] && grep -q $'\tMEAN\t' "$OUT/$1.tsv"
}
run() {
  bash "$ROOT/bench/run_families.sh" ${BUILD_ARG[@]+"${BUILD_ARG[@]}"} \
    --seeds "$SEEDS" --size "$SIZE" --families "$FAMILIES" \
    --threads "$THREADS" --out "$OUT" "$@" >&2
  # The binaries exist after the first run.
  BUILD_ARG=(--skip-build)
}
done_already default || run --tag default
REGISTERED=$("${BUILD_DIR:-$ROOT/build-bench}/bin/wild_mvs" reconstruct --dump-config |
  awk '/^ablation:/ { on = 1; next } /^[^ #]/ { on = 0 }
       on && /^  [a-z_]+:/ { sub(":", "", $1); print $1 }')
[ -n "$REGISTERED" ] || { echo "run_ablation.sh: no ablation switches found" >&2; exit 1; }
case "$SWITCHES" in "") SWITCHES=$REGISTERED ;; none) SWITCHES="" ;; esac
[ "$MOVES" != none ] || MOVES=""
for s in $SWITCHES; do
  done_already "no_$s" || run --tag "no_$s" -- "--ablation.$s" false
done
for m in $MOVES; do
  key=${m%%=*} value=${m#*=}
  [ "$key" != "$m" ] && [ -n "$value" ] ||
    { echo "run_ablation.sh: move $m is not KEY=VALUE" >&2; exit 2; }
  from=()
  case "$key" in consistency.*|fusion.*) from=(--from default) ;; esac
  done_already "set_${key}_$value" ||
    run --tag "set_${key}_$value" ${from[@]+"${from[@]}"} -- "--$key" "$value"
done
[ "$TRACKER_MOVES" != none ] || TRACKER_MOVES=""
OWN_TRACKS=(--points 0 -- --stages sparse,depth,fuse,mesh)
if [ -n "$TRACKER_MOVES" ]; then
  done_already tracker_default || run --tag tracker_default "${OWN_TRACKS[@]}"
  for m in $TRACKER_MOVES; do
    key=${m%%=*} value=${m#*=}
    [ "$key" != "$m" ] && [ -n "$value" ] ||
      { echo "run_ablation.sh: move $m is not KEY=VALUE" >&2; exit 2; }
    done_already "tracker_set_${key}_$value" ||
      run --tag "tracker_set_${key}_$value" "${OWN_TRACKS[@]}" "--$key" "$value"
  done
fi
[ "$WIDE_MOVES" != none ] || WIDE_MOVES=""
DATASETS="${WILD_MVS_DATASETS:-$ROOT/../shared/datasets}"
if [ -n "$WIDE_MOVES" ] && [ ! -d "$DATASETS/strecha_fountain-P11" ]; then
  echo "run_ablation.sh: no fountain-P11 in $DATASETS: the wide_* moves are not run" >&2
  WIDE_MOVES=""
fi
fountain() {  # TAG [EXTRA reconstruct ARGS]
  local tag="$1"
  shift
  [ ! -f "$OUT/fountain_$tag/fountain.tsv" ] || return 0
  mkdir -p "$OUT/fountain_$tag"
  # The ground-truth cloud is the same for every run: made once.
  [ ! -f "$OUT/fountain_default/gt_cloud_s2_v0.005.ply" ] || [ "$tag" = default ] ||
    ln -sf "$OUT/fountain_default/gt_cloud_s2_v0.005.ply" "$OUT/fountain_$tag/"
  bash "$ROOT/bench/run_fountain.sh" --size 1536 --threads "$THREADS" \
    --out "$OUT/fountain_$tag" -- "$@" >&2
}
if [ -n "$WIDE_MOVES" ]; then
  fountain default
  for m in $WIDE_MOVES; do
    key=${m%%=*} value=${m#*=}
    fountain "set_${key}_$value" "--$key" "$value"
  done
fi
# What OUT holds (also from earlier calls): the switches in the tool's order,
# the moves in the order they were first run.
held_switches=""
for s in $REGISTERED; do
  ! done_already "no_$s" || held_switches+="${held_switches:+ }$s"
done
move_done() { done_already "set_$1"; }
tracker_done() { done_already "tracker_set_$1"; }
fountain_done() { [ -f "$OUT/fountain_set_$1/fountain.tsv" ]; }
held_of() {  # SETTING_KEY DONE_FN MOVES..: those recorded or given whose table exists
  local key="$1" done_fn="$2" held="" m earlier=""
  shift 2
  [ ! -f "$OUT/setting.tsv" ] ||
    earlier=$(awk -F'\t' -v k="$key" '$1 == k { print $2 }' "$OUT/setting.tsv")
  for m in $earlier "$@"; do
    case " $held " in *" $m "*) continue ;; esac
    ! "$done_fn" "${m%%=*}_${m#*=}" || held+="${held:+ }$m"
  done
  echo "$held"
}
# shellcheck disable=SC2086  # the move lists split on purpose
held_moves=$(held_of moves move_done $MOVES)
# shellcheck disable=SC2086
held_wide=$(held_of wide_moves fountain_done $WIDE_MOVES)
# shellcheck disable=SC2086
held_tracker=$(held_of tracker_moves tracker_done $TRACKER_MOVES)
printf 'key\tvalue\nsize\t%s\nseeds\t%s\nswitches\t%s\nmoves\t%s\nwide_moves\t%s\ntracker_moves\t%s\n' \
  "$SIZE" "$SEEDS" "$held_switches" "$held_moves" "$held_wide" "$held_tracker" \
  >"$OUT/setting.tsv"
{ printf '%s\n' "$META_HEAD"; run_meta_now; } >"$OUT/meta.tsv"
echo "run_ablation.sh: tables in $OUT" >&2
