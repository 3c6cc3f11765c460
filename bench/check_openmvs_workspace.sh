#!/usr/bin/env bash
# OpenMVS on wild_mvs's COLMAP workspace (not a test; OpenMVS is built
# separately, none of its code is here): InterfaceCOLMAP reads the
# workspace `wild_mvs photos` (or `wild_mvs reconstruct` of a COLMAP
# dense folder) wrote, imports its depth maps into OpenMVS's .dmap files,
# and DensifyPointCloud fuses them as they are. Checks that every
# imported map equals wild_mvs's own map value for value (via
# bench/dmap_to_wild_mvs.py) and that the fusion gives points.
#
#   bench/check_openmvs_workspace.sh OUT [WORK]
# OUT: a `wild_mvs photos` output folder (its COLMAP workspace OUT/dense
#   and its maps OUT/depth); WORK: scratch folder (default OUT/openmvs).
# Environment: OPENMVS_BIN, the folder of InterfaceCOLMAP and
# DensifyPointCloud. Prints one line per view and a verdict; exit 1 when a
# map differs or a step fails.
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
[ $# -ge 1 ] || { sed -n '2,16p' "$0"; exit 2; }
OUT="$(cd "$1" && pwd)"
WORK="${2:-$OUT/openmvs}"
WS="$OUT/dense"
[ -n "${OPENMVS_BIN:-}" ] || { echo "check_openmvs_workspace.sh: set OPENMVS_BIN" >&2; exit 1; }
for b in InterfaceCOLMAP DensifyPointCloud; do
  [ -x "$OPENMVS_BIN/$b" ] || { echo "check_openmvs_workspace.sh: no $OPENMVS_BIN/$b" >&2; exit 1; }
done
[ -d "$WS/stereo/depth_maps" ] || { echo "check_openmvs_workspace.sh: $WS is not a workspace with depth maps" >&2; exit 1; }
PY=python3
[ -x /usr/bin/python3 ] && PY=/usr/bin/python3
rm -rf "$WORK"
mkdir -p "$WORK"
ln -s "$WS" "$WORK/dense"
# OpenMVS writes scene.mvs, its .dmap files and logs next to the -o file.
(cd "$WORK" && "$OPENMVS_BIN/InterfaceCOLMAP" -i "$WS" -o "$WORK/scene.mvs" \
  --image-folder "$WS/images" >"$WORK/interface.log" 2>&1) ||
  { tail -5 "$WORK/interface.log" >&2; echo "check_openmvs_workspace.sh: InterfaceCOLMAP failed" >&2; exit 1; }
"$PY" "$ROOT/bench/dmap_to_wild_mvs.py" "$WORK/imported" "$WORK"/depth*.dmap >/dev/null
"$PY" - "$ROOT/bench" "$OUT/depth" "$WORK/imported/depth" <<'PY'
import os, sys
import numpy as np
sys.path.insert(0, sys.argv[1])
from common_accuracy import read_pfm
ours_dir, theirs_dir = sys.argv[2:]
names = sorted(n for n in os.listdir(ours_dir) if n.endswith(".pfm"))
bad = 0
for n in names:
    p = os.path.join(theirs_dir, n)
    if not os.path.exists(p):
        print(f"{n[:-4]}: not imported"); bad += 1; continue
    a, b = read_pfm(os.path.join(ours_dir, n)), read_pfm(p)
    va, vb = np.isfinite(a) & (a > 0), np.isfinite(b) & (b > 0)
    same = a.shape == b.shape and (va == vb).all() and np.array_equal(a[va], b[vb])
    print(f"{n[:-4]}: {va.sum()} samples ours, {vb.sum()} imported, "
          f"{'equal' if same else 'DIFFERENT'}")
    bad += not same
print(f"{len(names) - bad} of {len(names)} imported maps equal ours")
sys.exit(1 if bad else 0)
PY
# OpenMVS 2.3.0's depth-map post-processing reads a confidence map that
# imported maps do not have (it crashes); without it the maps are fused as
# they are.
(cd "$WORK" && "$OPENMVS_BIN/DensifyPointCloud" -i scene.mvs --resolution-level 0 \
  --geometric-iters 0 --postprocess-dmaps 0 >"$WORK/densify.log" 2>&1) ||
  { tail -5 "$WORK/densify.log" >&2; echo "check_openmvs_workspace.sh: DensifyPointCloud failed" >&2; exit 1; }
pts=$(grep -a -o 'element vertex [0-9]*' "$WORK/scene_dense.ply" | head -1 | awk '{print $3}')
echo "DensifyPointCloud fused the imported maps: ${pts:-?} points ($WORK/scene_dense.ply)"
