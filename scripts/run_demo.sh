#!/usr/bin/env bash
# The main job on the sample shipped in the repository: installs what is
# missing (Debian 12 packages), builds what it runs (the tool and the ROS
# nodes, no tests), then runs wild_mvs on
# data/templeSparseRing (16 views, Middlebury): info, sparse tracks from the
# known poses, depth maps, fused point cloud and mesh with the offline tool,
# then the same sample through the ROS nodes (bag -> depth_node ->
# fusion_node -> saved cloud); prints a summary.
# Works from any current directory; re-running resumes finished views.
#
# Usage: scripts/run_demo.sh [--full] [--no-ros] [--out DIR]
#   --full     full resolution (640x480; several minutes on 2 cores)
#              instead of 320x240
#   --no-ros   only the offline tool (no ROS packages needed)
#   --out DIR  output folder (default: build/demo)
set -eo pipefail
source "$(dirname "$0")/common.sh"

SIZE=320
OUT="$BUILD_DIR/demo"
while [ $# -gt 0 ]; do
  case "$1" in
    --full) SIZE=0 ;;
    --no-ros) NO_ROS=1 ;;
    --out) OUT="$2"; shift ;;
    -h|--help) sed -n '2,15p' "$0"; exit 0 ;;
    *) echo "run_demo.sh: unknown option '$1' (see --help)" >&2; exit 2 ;;
  esac
  shift
done

# Builds only what the demo runs (no tests: scripts/run_tests.sh builds them).
if [ -n "${NO_ROS:-}" ]; then
  bash "$WILD_MVS_ROOT/scripts/install_deps.sh" --no-ros
  mkdir -p "$BUILD_DIR"
  wild_mvs_configure -DWILD_MVS_WITH_ROS=OFF -DWILD_MVS_BUILD_TESTS=OFF
  cmake --build "$BUILD_DIR" -j"$JOBS" --target wild_mvs
else
  bash "$WILD_MVS_ROOT/scripts/install_deps.sh"
  mkdir -p "$BUILD_DIR"
  wild_mvs_configure -DWILD_MVS_WITH_ROS=ON -DWILD_MVS_BUILD_TESTS=OFF
  cmake --build "$BUILD_DIR" -j"$JOBS" --target "${WILD_MVS_DEMO_TARGETS[@]}"
fi
WILD_MVS="$BUILD_DIR/bin/wild_mvs"
DATA="$WILD_MVS_ROOT/data/templeSparseRing"
mkdir -p "$OUT"
TAG=$([ "$SIZE" = 0 ] && echo full || echo "$SIZE")
RUN="$OUT/temple_$TAG"

step() { printf '\n==> %s\n' "$*"; }

step "wild_mvs info $DATA"
"$WILD_MVS" info "$DATA"

step "wild_mvs sparse (tracks from the known poses) -> $OUT/sparse_model"
"$WILD_MVS" sparse "$DATA" "$OUT/sparse_model" --max-image-size "$SIZE"

step "wild_mvs reconstruct (depth maps, fused cloud, mesh) -> $RUN"
"$WILD_MVS" reconstruct "$DATA" "$RUN" --max-image-size "$SIZE" \
  | tee "$OUT/reconstruct_summary.txt"

if [ -z "${NO_ROS:-}" ]; then
  step "ROS pipeline: wild_mvs to-bag, rosbag play -> depth_node -> fusion_node -> $OUT/ros_$TAG/cloud.ply"
  bash "$WILD_MVS_ROOT/scripts/ros_reconstruct.sh" "$DATA" "$OUT/ros_$TAG" 2 \
    max_image_size:="$SIZE" | tee "$OUT/ros_summary.txt"
fi

step "demo summary"
n_depth=$(ls "$RUN"/depth/*.pfm 2>/dev/null | wc -l)
echo "binary:       $WILD_MVS"
echo "sparse model: $OUT/sparse_model/{cameras,images,points3D}.txt"
echo "depth maps:   $n_depth views in $RUN/depth (normal/, confidence/, cameras/, preview/*.png, log/*.json beside)"
echo "point cloud:  $RUN/fused.ply"
echo "mesh:         $RUN/mesh.ply"
cat "$OUT/reconstruct_summary.txt"
if [ -z "${NO_ROS:-}" ]; then
  echo "ROS pipeline: bag $OUT/ros_$TAG/input.bag, cloud $OUT/ros_$TAG/cloud.ply"
  grep -E "end-to-end|peak RSS|saved" "$OUT/ros_summary.txt" || true
fi
