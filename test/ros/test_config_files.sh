#!/usr/bin/env bash
# config/reconstruct.yaml, the depth roles' depth_node.yaml,
# keyframe_selector.yaml and depth_worker.yaml, and fusion_node.yaml are exactly
# what wild_mvs_write_config writes from the option registry (every key, its
# default and its valid range). After changing an option:
#   build/devel/lib/wild_mvs/wild_mvs_write_config config   (or devel/lib/...)
set -euo pipefail
TOOL="$1"
CONFIG="$2"
TMP="$(mktemp -d)"
trap 'rm -rf "$TMP"' EXIT
"$TOOL" "$TMP" >/dev/null
status=0
# Every file the tool writes is in config/, and the other way round.
for f in "$TMP"/*.yaml; do
  f=$(basename "$f")
  [ -f "$CONFIG/$f" ] || { echo "FAIL: $CONFIG/$f missing"; status=1; }
done
for f in reconstruct.yaml depth_node.yaml keyframe_selector.yaml \
  depth_worker.yaml fusion_node.yaml; do
  if ! diff -u "$CONFIG/$f" "$TMP/$f"; then
    echo "FAIL: $CONFIG/$f is not what wild_mvs_write_config writes" \
         "(regenerate: wild_mvs_write_config $CONFIG)"
    status=1
  fi
done
[ "$status" = 0 ] && echo "ok: config files match the option registry"
exit "$status"
