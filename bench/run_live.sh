#!/usr/bin/env bash
# Live against offline on the same images: a rendered scene with exact
# ground truth is reconstructed by `wild_mvs reconstruct` and, written as a
# bag (`wild_mvs to-bag`, one frame per view, --rate views per second; a
# list "1 0.25" plays it at each rate),
# played through the depth and fusion nodes (launch/reconstruct_bag.launch,
# default parameters, its depth views recorded). Both are scored against the
# ground truth: the published depth maps (revisions 0, 1 and final,
# bench_live_depth_maps) and the offline maps with
# `wild_mvs eval depth`, the fused clouds with `wild_mvs eval cloud`.
#
#   bench/run_live.sh [--families "relief courtyard"] [--seeds 101]
#                     [--size 640] [--rate "1 0.25"] [--out DIR] [--skip-build]
#                     [--sparse tracker|topic] [--robot]
#
# --sparse: where the depth node's sparse points come from: its own
# incremental tracker (default, as a robot runs it), or the dataset's
# sparse model written into the bag (/sparse_points, sparse_source:=topic),
# the points the offline run uses: then the two differ only in the pipeline.
# With the tracker, the offline tool also runs on the images without the
# dataset's points ("offline, own tracks": it computes its own SIFT tracks,
# as the live tracker does).
# --robot: the bag as a robot records it (`to-bag --frames-per-view 3
# --body-frame base_link --start-time EPOCH`): a 30 Hz camera lingering 3
# frames on each view, epoch stamps, /tf world -> base_link at 100 Hz and the
# camera extrinsic on /tf_static.
#
# Needs the ROS build (scripts/common.sh's BUILD_DIR, default build/). Runs
# its own roscore on a free port. Prints one row per scene and run and
# writes OUT/live.tsv and OUT/meta.tsv (the command, the code, the date:
# bench/make_results.py names them when run_all.sh skipped this section and
# it ran into OUT/live afterwards); first_s: seconds from an image to its keyframe's
# first depth view (median/max, the bag's clock), revised_after: newer
# keyframes that got their first depth view before a keyframe's revision 1
# (its row) or final revision (median/max). Runs at a rate other than 1
# are named with it ("live final revisions, 0.25 views/s").
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
COMMAND="bench/run_live.sh"
for arg in "$@"; do
  case "$arg" in *' '*) COMMAND+=" \"$arg\"" ;; *) COMMAND+=" $arg" ;; esac
done
OUT="$ROOT/bench/out/live"
FAMILIES="relief courtyard"
SEEDS=101
SIZE=640
RATE="1 0.25"
SPARSE=tracker
ROBOT=()
BUILD=missing
usage() { sed -n '2,/^set -euo/p' "$0" | sed '$d; s/^# \{0,1\}//'; }
while [ $# -gt 0 ]; do
  case "$1" in
    --families) FAMILIES="$2"; shift 2 ;;
    --seeds) SEEDS="$2"; shift 2 ;;
    --size) SIZE="$2"; shift 2 ;;
    --rate) RATE="$2"; shift 2 ;;
    --out) OUT="$2"; shift 2 ;;
    --sparse) SPARSE="$2"; shift 2 ;;
    --robot) ROBOT=(--frames-per-view 3 --body-frame base_link
                    --start-time 1764800000.123456); shift ;;
    --skip-build) BUILD=never; shift ;;
    -h|--help) usage; exit 0 ;;
    *) echo "run_live.sh: unknown option $1 (see --help)" >&2; exit 2 ;;
  esac
done
case "$SPARSE" in tracker|topic) ;; *)
  echo "run_live.sh: --sparse $SPARSE must be tracker or topic" >&2; exit 2 ;;
esac
source "$ROOT/scripts/common.sh"
DEVEL="$BUILD_DIR/../devel"
[ -d "$DEVEL" ] || DEVEL="$ROOT/devel"
if [ "$BUILD" = missing ]; then
  wild_mvs_build >&2
  cmake --build "$BUILD_DIR" -j"$JOBS" --target bench_live_depth_maps >&2
fi
BIN="$DEVEL/lib/wild_mvs"
for b in wild_mvs make_scene wild_mvs_to_bag bench_live_depth_maps; do
  [ -x "$BIN/$b" ] || { echo "run_live.sh: $BIN/$b missing (drop --skip-build)" >&2; exit 1; }
done
set +u
source "$DEVEL/setup.bash"
set -u
PORT=$((20000 + RANDOM % 20000))
export ROS_MASTER_URI="http://localhost:$PORT"
export ROS_HOME="$OUT/ros_home"
mkdir -p "$OUT" "$ROS_HOME"

noise_of() { case "$1" in relief|weak) echo 0.01 ;; *) echo "" ;; esac; }
kinds_of() {
  case "$1" in
    courtyard) echo light ;;
    relief|weak) echo "$1" ;;
    *) echo "$1" ;;
  esac
}

score() {  # RUN_DIR SCENE_DIR -> "coverage in1 off5"
  "$BIN/wild_mvs" eval depth --est "$1" --gt-dir "$2/gt_depth" \
    --rel-thresholds 0.01,0.05 --json "$1/eval_depth.json" >/dev/null
  /usr/bin/python3 - "$1/eval_depth.json" <<'PY'
import json, sys
d = json.load(open(sys.argv[1]))
a = d["relative_accuracy"]
print("%.3f %.3f %.2f%%" % (d["completeness"], a[0], 100 * (1 - a[1])))
PY
}
fscore() {  # CLOUD SCENE_DIR -> "F@1cm F@5cm"
  "$BIN/wild_mvs" eval cloud "$1" "$2/gt_surface.ply" --tau 0.01,0.05 \
    --json "$1.eval.json" >/dev/null
  /usr/bin/python3 -c "import json,sys; c=json.load(open(sys.argv[1])); print(' '.join('%.3f' % f for f in c['fscore']))" "$1.eval.json"
}

TSV="$OUT/live.tsv"
printf 'scene\tseed\trun\tviews\tcoverage\tin1%%\toff>5%%\tF@1cm\tF@5cm\tcpu_s\tfirst_s\trevised_after\n' >"$TSV"
for family in $FAMILIES; do
  for seed in ${SEEDS//,/ }; do
    kind=$(kinds_of "$family")
    noise=$(noise_of "$family")
    scene="$OUT/scenes/${kind}_s${seed}_$SIZE"
    if [ ! -f "$scene/gt_surface.ply" ]; then
      rm -rf "$scene"
      "$BIN/make_scene" "$kind" "$scene" --seed "$seed" --width "$SIZE" \
        --height $((SIZE * 3 / 4)) ${noise:+--noise "$noise"} >&2
    fi
    nviews=$(ls "$scene/gt_depth" | wc -l)
    run="$OUT/${kind}_s$seed"
    rm -rf "$run"
    mkdir -p "$run"
    # Offline.
    /usr/bin/time -f '%U %S' -o "$run/offline.time" \
      "$BIN/wild_mvs" reconstruct "$scene" "$run/offline" --threads 2 \
      >"$run/offline.log" 2>&1
    read -r u s <"$run/offline.time"
    off=$(score "$run/offline" "$scene")
    f=$(fscore "$run/offline/fused.ply" "$scene")
    n=$(ls "$run/offline/depth" | grep -c '\.pfm$')
    printf '%s\t%s\toffline\t%s/%s\t%s\t%s\t%.1f\t-\t-\n' "$kind" "$seed" "$n" "$nviews" \
      "${off// /	}" "${f// /	}" "$(echo "$u + $s" | bc)" >>"$TSV"
    # Offline on the same images without the dataset's sparse points: the
    # tool computes its own tracks (SIFT), as the live tracker does.
    if [ "$SPARSE" = tracker ]; then
      bare="$OUT/scenes/${kind}_s${seed}_${SIZE}_no_points"
      if [ ! -f "$bare/sparse/points3D.txt" ]; then
        rm -rf "$bare"
        mkdir -p "$bare/sparse"
        cp -r "$scene/images" "$bare/images"
        cp "$scene/sparse/cameras.txt" "$bare/sparse/"
        # images.txt without its observations, no points.
        awk '/^#/ {print; next} {n++; print (n % 2 ? $0 : "")}' \
          "$scene/sparse/images.txt" >"$bare/sparse/images.txt"
        echo "# no points" >"$bare/sparse/points3D.txt"
      fi
      /usr/bin/time -f '%U %S' -o "$run/offline_own.time" \
        "$BIN/wild_mvs" reconstruct "$bare" "$run/offline_own" --threads 2 \
        --stages sparse,depth,fuse,mesh >"$run/offline_own.log" 2>&1
      read -r u s <"$run/offline_own.time"
      off=$(score "$run/offline_own" "$scene")
      f=$(fscore "$run/offline_own/fused.ply" "$scene")
      n=$(ls "$run/offline_own/depth" | grep -c '\.pfm$')
      printf '%s\t%s\toffline, own tracks\t%s/%s\t%s\t%s\t%.1f\t-\t-\n' "$kind" "$seed" \
        "$n" "$nviews" "${off// /	}" "${f// /	}" "$(echo "$u + $s" | bc)" >>"$TSV"
    fi
    # Live, at each rate.
    for rate in $RATE; do
      lr="$run/live_$rate"
      suffix=""
      [ "$rate" = 1 ] || suffix=", $rate views/s"
      mkdir -p "$lr"
      points=()
      [ "$SPARSE" = topic ] && points=(--with-points)
      "$BIN/wild_mvs_to_bag" "$scene" "$lr/scene.bag" --rate "$rate" \
        ${points[@]+"${points[@]}"} ${ROBOT[@]+"${ROBOT[@]}"} >"$lr/bag.log" 2>&1
      # The bag's clock (/clock, which the recorder stamps with) stops at its
      # last message: a last, unused message 5 s after the last view keeps it
      # running while the last keyframes are matched, so that their latency
      # is measured, not cut off.
      /usr/bin/python3 - "$lr/scene.bag" <<'PY'
import sys
import rosbag
import rospy
from std_msgs.msg import String
with rosbag.Bag(sys.argv[1], "a") as bag:
    bag.write("/bench/clock_tail", String(data="keeps the clock running"),
              rospy.Time.from_sec(bag.get_end_time() + 5.0))
PY
      roscore -p "$PORT" >"$lr/roscore.log" 2>&1 &
      core=$!
      sleep 3
      /usr/bin/time -f '%U %S' -o "$lr/live.time" \
        roslaunch wild_mvs reconstruct_bag.launch bag:="$lr/scene.bag" \
        output:="$lr/live_fused.ply" record:="$lr/live.bag" \
        sparse_source:="$SPARSE" >"$lr/live.log" 2>&1 || true
      kill "$core" 2>/dev/null || true
      wait "$core" 2>/dev/null || true
      read -r u s <"$lr/live.time"
      cpu=$(echo "$u + $s" | bc)
      for which in first 1 final; do
        flag=()
        [ "$which" = first ] && flag=(--revision 0)
        [ "$which" = 1 ] && flag=(--revision 1)
        "$BIN/bench_live_depth_maps" "$lr/live.bag" "$scene" "$lr/live_$which" \
          ${flag[@]+"${flag[@]}"} >"$lr/live_$which.log" 2>&1
        n=$(ls "$lr/live_$which/depth" 2>/dev/null | grep -c '\.pfm$' || true)
        sc=$(score "$lr/live_$which" "$scene")
        if [ "$which" = final ] && [ -f "$lr/live_fused.ply" ]; then
          f=$(fscore "$lr/live_fused.ply" "$scene")
        else
          f="- -"
        fi
        # How late: seconds from an image to its keyframe's first depth view
        # (median/max), and newer keyframes' first views before its
        # revision 1 or final revision (median/max).
        lat=$(sed -n 's/^first depth view after its image: median \([0-9.]*\) s, max \([0-9.]*\) s$/\1 \2/p' \
          "$lr/live_$which.log" | awk '{printf "%.1f/%.1f", $1, $2}')
        case "$which" in
          first) name="first revisions"; lag=- ;;
          1) name="revisions 1"; lat=-
             lag=$(sed -n 's/^revision 1 after \([0-9]*\) newer.* \([0-9]*\) (max).*/\1\/\2/p' \
               "$lr/live_$which.log") ;;
          final) name="final revisions"; lat=-
             lag=$(sed -n 's/^final revision after \([0-9]*\) newer.* \([0-9]*\) (max).*/\1\/\2/p' \
               "$lr/live_$which.log") ;;
        esac
        printf '%s\t%s\tlive %s%s\t%s/%s\t%s\t%s\t%s\t%s\t%s\n' "$kind" "$seed" \
          "$name" "$suffix" "$n" "$nviews" "${sc// /	}" "${f// /	}" \
          "$([ "$which" = final ] && echo "$cpu" || echo -)" "${lat:--}" "${lag:--}" >>"$TSV"
      done
    done
  done
done
column -t -s $'\t' "$TSV"
# shellcheck source=run_meta.sh
source "$ROOT/bench/run_meta.sh"
{
  printf 'key\tvalue\ncommand\t%s\n' "$COMMAND"
  run_meta_code "$ROOT"
  run_meta_now
} >"$OUT/meta.tsv"
