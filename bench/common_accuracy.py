#!/usr/bin/env python3
"""Accuracy of two runs on the pixels both estimate (docs/METHODS.md).

The pooled `in1%` of bench/run_families.sh is a ratio over the pixels a run
estimates: a change that adds harder pixels lowers it even when it is as
accurate as before everywhere the old run answered. This splits the
ground-truth pixels of two runs A (before) and B (after) of one scene into
those both estimate (scored for A and for B), those only A estimates and
those only B estimates, and prints in1% and off>5% of each part. Then the
pixels without a surface (the sky) that only B estimates, by their
distance from the nearest surface pixel (pixels, the larger of the row and
column offsets; "far" beyond 20): where a change adds estimates beside
silhouettes.

Usage: bench/common_accuracy.py RUN_A RUN_B GT_DEPTH_DIR
(RUN_*/depth/NAME.pfm and GT_DEPTH_DIR/NAME.pfm, depth z in metres, 0 or
NaN = none; views whose map size differs from the ground truth's are
skipped with a note.)
"""
import os
import sys

import numpy as np


def read_pfm(path):
    with open(path, "rb") as f:
        if f.readline().strip() not in (b"Pf", b"PF"):
            sys.exit(f"{path}: not a PFM file")
        w, h = map(int, f.readline().split())
        scale = float(f.readline())
        data = np.fromfile(f, "<f4" if scale < 0 else ">f4")
    if data.size < w * h:
        sys.exit(f"{path}: truncated")
    return np.flipud(data[: w * h].reshape(h, -1)[:, :w])


MAX_DISTANCE = 20


def distance_to_surface(surface):
    """Per pixel, the chessboard distance to the nearest surface pixel, up to
    MAX_DISTANCE + 1 (= farther)."""
    dist = np.full(surface.shape, MAX_DISTANCE + 1, dtype=np.int32)
    reached = surface.copy()
    dist[reached] = 0
    for k in range(1, MAX_DISTANCE + 1):
        grown = reached.copy()
        grown[1:, :] |= reached[:-1, :]
        grown[:-1, :] |= reached[1:, :]
        grown[:, 1:] |= reached[:, :-1]
        grown[:, :-1] |= reached[:, 1:]
        grown[1:, 1:] |= reached[:-1, :-1]
        grown[:-1, :-1] |= reached[1:, 1:]
        grown[1:, :-1] |= reached[:-1, 1:]
        grown[:-1, 1:] |= reached[1:, :-1]
        dist[grown & ~reached] = k
        reached = grown
    return dist


def main():
    if len(sys.argv) != 4:
        sys.exit(__doc__)
    run_a, run_b, gt_dir = sys.argv[1:]
    parts = {k: [0, 0, 0] for k in ("both: A", "both: B", "A only", "B only")}
    sky_added = {}  # distance from the surface -> pixels
    for name in sorted(os.listdir(gt_dir)):
        if not name.endswith(".pfm"):
            continue
        gt = read_pfm(os.path.join(gt_dir, name))
        a = read_pfm(os.path.join(run_a, "depth", name))
        b = read_pfm(os.path.join(run_b, "depth", name))
        if a.shape != gt.shape or b.shape != gt.shape:
            print(f"{name}: map size differs from the ground truth; skipped")
            continue
        valid = np.isfinite(gt) & (gt > 0)
        est_a = np.isfinite(a) & (a > 0)
        est_b = np.isfinite(b) & (b > 0)
        sky_b = est_b & ~est_a & ~valid
        if sky_b.any():
            counts = np.bincount(distance_to_surface(valid)[sky_b])
            for d in np.nonzero(counts)[0]:
                sky_added[int(d)] = sky_added.get(int(d), 0) + int(counts[d])
        has_a = est_a & valid
        has_b = est_b & valid
        for key, mask, d in (("both: A", has_a & has_b, a),
                             ("both: B", has_a & has_b, b),
                             ("A only", has_a & ~has_b, a),
                             ("B only", has_b & ~has_a, b)):
            rel = np.abs(d[mask] - gt[mask]) / gt[mask]
            p = parts[key]
            p[0] += int(mask.sum())
            p[1] += int((rel <= 0.01).sum())
            p[2] += int((rel > 0.05).sum())
    print(f"{'pixels':8s} {'count':>9s} {'in1%':>6s} {'off>5%':>7s}")
    for key, (n, within, off) in parts.items():
        n1 = max(n, 1)
        print(f"{key:8s} {n:9d} {within / n1:6.3f} {off / n1:7.4f}")
    total = sum(sky_added.values())
    by_distance = ", ".join(
        f"{'far' if d > MAX_DISTANCE else d}: {n}"
        for d, n in sorted(sky_added.items()))
    print(f"no surface, B only: {total} pixels" +
          (f" (px from the surface: {by_distance})" if total else ""))


if __name__ == "__main__":
    main()
