#!/usr/bin/env bash
# Soak benchmark (not a test): loops a bag through depth_node + fusion_node
# for DURATION seconds at a high frame rate, with its own ROS master, and
# records RSS, CPU and the diagnostics counters (drops, keyframes, depth
# maps, fused views, cloud size) every 10 s to a CSV, then plots it.
#
#   bench/soak.sh [DURATION_S=1800] [OUT_DIR=/tmp/wild_mvs_soak] [RATE_HZ=20] [DATASET]
#
# DATASET defaults to the shipped sample data/templeSparseRing (16 views,
# 640x480), turned into a bag with `wild_mvs to-bag`; the depth node works at
# max_image_size 320 (SOAK_MAX_IMAGE_SIZE). The bag's frames are replayed by
# bench/soak_player.py with a continuous clock (a robot circling the object
# forever), so the stream never resets and every stage keeps working.
# Output: OUT_DIR/soak.csv, OUT_DIR/soak.png (copied to docs/soak.png, or
# docs/$SOAK_DOCS_NAME, when SOAK_UPDATE_DOCS=1), OUT_DIR/summary.txt, node
# logs, the final cloud OUT_DIR/cloud.ply.
# SOAK_FUSION_MB=N sets the fusion node's memory bounds (map_store_mb,
# fusion/map_cache_mb, fusion/pending_mb; defaults 256, 256, 128) to N MB
# each, so that their plateau shows within the run.
# SOAK_LINGER=N shows each view N frames in a row (a 30 Hz camera on a
# robot moving one view step per N frames; default 1: every frame a new
# view, so every frame is a keyframe).
# Runs under nice -n 10. Needs a ROS build (scripts/common.sh wild_mvs_build).
set -eo pipefail
source "$(dirname "$0")/../scripts/common.sh"
DURATION=${1:-1800}
OUT=${2:-/tmp/wild_mvs_soak}
RATE=${3:-20}
DATASET=${4:-$WILD_MVS_ROOT/data/templeSparseRing}
MAX_IMAGE_SIZE=${SOAK_MAX_IMAGE_SIZE:-320}
PY=/usr/bin/python3
mkdir -p "$OUT"
OUT=$(cd "$OUT" && pwd)

if ! $PY -c "import matplotlib" 2>/dev/null; then
  echo "soak: installing python3-matplotlib (Debian) for the plot"
  DEBIAN_FRONTEND=noninteractive apt-get install -y -qq python3-matplotlib >/dev/null ||
    echo "soak: could not install python3-matplotlib: no plot" >&2
fi
DEVEL=$(wild_mvs_devel_dir)
[ -x "$DEVEL/lib/wild_mvs/depth_node" ] ||
  { echo "soak: no ROS build in $BUILD_DIR (devel space $DEVEL; run wild_mvs_build)" >&2; exit 1; }
set +u
source "$DEVEL/setup.bash"
LIB="$DEVEL/lib/wild_mvs"

"$LIB/wild_mvs_to_bag" "$DATASET" "$OUT/soak.bag" --rate 2 >/dev/null

PORT=$($PY -c 'import socket; s=socket.socket(); s.bind(("",0)); print(s.getsockname()[1])')
export ROS_MASTER_URI=http://localhost:$PORT
pids=()
cleanup() {
  for p in "${pids[@]}"; do kill -INT "$p" 2>/dev/null || true; done
  sleep 3
  for p in "${pids[@]}"; do kill -9 "$p" 2>/dev/null || true; done
}
trap cleanup EXIT
nice -n 10 roscore -p "$PORT" >"$OUT/roscore.log" 2>&1 &
pids+=($!)
for _ in $(seq 60); do rosparam list >/dev/null 2>&1 && break; sleep 0.5; done

rosparam load "$WILD_MVS_ROOT/config/depth_node.yaml" /depth_node
rosparam load "$WILD_MVS_ROOT/config/fusion_node.yaml" /fusion_node
rosparam load "$WILD_MVS_ROOT/config/sample.yaml" /
rosparam set /depth_node/mvs/max_image_size "$MAX_IMAGE_SIZE"
rosparam set /depth_node/diagnostics_period 2.0
rosparam set /fusion_node/diagnostics_period 2.0
rosparam set /fusion_node/output_path "$OUT/cloud.ply"
if [ -n "${SOAK_FUSION_MB:-}" ]; then  # tighter fusion memory bounds (MB each)
  rosparam set /fusion_node/map_store_mb "$SOAK_FUSION_MB"
  rosparam set /fusion_node/fusion/map_cache_mb "$SOAK_FUSION_MB"
  rosparam set /fusion_node/fusion/pending_mb "$SOAK_FUSION_MB"
fi

nice -n 10 "$LIB/depth_node" __name:=depth_node image:=/camera/image_raw \
  camera_info:=/camera/camera_info >"$OUT/depth_node.log" 2>&1 &
depth_pid=$!
pids+=("$depth_pid")
nice -n 10 "$LIB/fusion_node" __name:=fusion_node \
  depth_view:=/depth_node/depth_view >"$OUT/fusion_node.log" 2>&1 &
fusion_pid=$!
pids+=("$fusion_pid")
sleep 3

echo "soak: ${DURATION} s at ${RATE} Hz of $(basename "$DATASET") frames (depth at ${MAX_IMAGE_SIZE} px), CSV $OUT/soak.csv"
nice -n 10 $PY "$WILD_MVS_ROOT/bench/soak_player.py" "$OUT/soak.bag" "$OUT/soak.csv" \
  --rate "$RATE" --linger "${SOAK_LINGER:-1}" --duration "$DURATION" \
  --pid depth="$depth_pid" --pid fusion="$fusion_pid"
for p in "$depth_pid" "$fusion_pid"; do
  kill -0 "$p" 2>/dev/null || echo "soak: a node died (pid $p): see $OUT/*.log" >&2
done
# Shut down (the fusion node saves its cloud on SIGINT).
kill -INT "$depth_pid" "$fusion_pid" 2>/dev/null || true
# (the depth node first finishes the reconstruction it is running)
for _ in $(seq 360); do
  kill -0 "$fusion_pid" 2>/dev/null || kill -0 "$depth_pid" 2>/dev/null || break
  sleep 0.5
done
grep -h "peak RSS\|saved" "$OUT"/depth_node.log "$OUT"/fusion_node.log || true
if $PY -c "import matplotlib" 2>/dev/null; then
  $PY "$WILD_MVS_ROOT/bench/soak_plot.py" "$OUT/soak.csv" "$OUT/soak.png" | tee "$OUT/summary.txt"
  [ -z "${SOAK_UPDATE_DOCS:-}" ] || cp "$OUT/soak.png" "$WILD_MVS_ROOT/docs/${SOAK_DOCS_NAME:-soak.png}"
fi
