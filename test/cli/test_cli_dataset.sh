#!/usr/bin/env bash
# `wild_mvs info` and `wild_mvs sparse` on the sample shipped in data/, and
# clear errors for broken copies of it.
source "$(dirname "$0")/cli_lib.sh" "$@"
DATA="$SRC/data/templeSparseRing"

expect_ok "$WILD_MVS" info "$DATA"
grep -q "^format: *middlebury" "$TMP/last.log" || fail "info: format not middlebury"
grep -q "^views: *16 " "$TMP/last.log" || fail "info: not 16 views"
grep -q "640x480 (16 views)" "$TMP/last.log" || fail "info: resolution line"
grep -q "templeSR0001.png and templeSR0011.png were taken from (almost) the same position" \
  "$TMP/last.log" || fail "info: the zero-baseline twin is not reported"

# Sparse tracks at reduced size (fast), written as a COLMAP text model that
# info reads back with its points.
expect_ok "$WILD_MVS" sparse "$DATA" "$TMP/model" --max-image-size 320 --threads 2
for f in cameras.txt images.txt points3D.txt; do
  [ -s "$TMP/model/$f" ] || fail "sparse: $f missing"
done
npts=$(grep -vc '^#' "$TMP/model/points3D.txt")
[ "$npts" -gt 500 ] || fail "sparse: only $npts points"
ls "$TMP/model" | grep -q tmp && fail "sparse: temporary files left"
expect_ok "$WILD_MVS" info "$TMP/model" --images "$DATA"
grep -q "^points: *$npts$" "$TMP/last.log" || fail "info on the sparse model: points"
grep -q "^track length: min 2" "$TMP/last.log" || fail "info: track stats"

# Broken copies: missing image, wrong image size, truncated camera line.
cp -r "$DATA" "$TMP/broken"
chmod -R u+w "$TMP/broken"
rm "$TMP/broken/templeSR0007.png"
expect_fail 1 "templeSR0007.png" -- "$WILD_MVS" info "$TMP/broken"
expect_fail 1 "templeSR0007.png" -- "$WILD_MVS" sparse "$TMP/broken" "$TMP/m2"
cp "$DATA/templeSR0008.png" "$TMP/broken/templeSR0007.png"
python3 - "$TMP/broken/templeSR_par.txt" <<'PY'
import sys
p = sys.argv[1]
lines = open(p).read().splitlines()
lines[3] = " ".join(lines[3].split()[:12])  # truncated camera line
open(p, "w").write("\n".join(lines) + "\n")
PY
expect_fail 1 "templeSR_par.txt.*line 4" -- "$WILD_MVS" info "$TMP/broken"
expect_fail 1 "no_such_folder" -- "$WILD_MVS" info "$TMP/no_such_folder"
expect_fail 2 "unknown option --bogus" -- "$WILD_MVS" info "$DATA" --bogus
expect_fail 2 "missing argument OUT_MODEL_DIR" -- "$WILD_MVS" sparse "$DATA"
expect_fail 2 "'nope'" -- "$WILD_MVS" info "$DATA" --format nope
finish
