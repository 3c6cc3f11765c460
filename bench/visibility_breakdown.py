#!/usr/bin/env python3
"""Coverage by how many other views see a pixel (docs/METHODS.md, "Where
coverage is lost").

For every 2nd pixel and row of each view's ground-truth depth, the surface
point is projected into every other view; the view sees it when the point
lands inside it and the view's own ground-truth depth there agrees within
1 %. The pixels are grouped by that count (0, 1, 2, 3-4, 5 or more), pooled
over the views, and each group's share and coverage (an estimate in
RUN/depth) are printed. Views whose map is not at the ground truth's size
(matched at another working size) are left out, with a note.

Usage: bench/visibility_breakdown.py SCENE RUN
SCENE: a rendered scene of bench/run_families.sh (sparse/cameras.txt and
images.txt, COLMAP text with PINHOLE cameras; gt_depth/NAME.pfm); RUN: a
`wild_mvs reconstruct` folder of it.
"""
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from common_accuracy import read_pfm  # noqa: E402

GROUPS = [(0, 0), (1, 1), (2, 2), (3, 4), (5, 10 ** 6)]


def read_model(scene):
    cams = {}
    for line in open(os.path.join(scene, "sparse", "cameras.txt")):
        w = line.split()
        if not w or w[0].startswith("#"):
            continue
        if w[1] != "PINHOLE":
            sys.exit(f"{scene}: camera {w[0]} is {w[1]}, expected PINHOLE")
        cams[int(w[0])] = [float(x) for x in w[4:8]]
    lines = [l for l in open(os.path.join(scene, "sparse", "images.txt"))
             if not l.startswith("#")]
    views = {}
    for i in range(0, len(lines), 2):
        w = lines[i].split()
        if len(w) < 10:
            continue
        qw, qx, qy, qz, tx, ty, tz = map(float, w[1:8])
        r = np.array([
            [1 - 2 * (qy * qy + qz * qz), 2 * (qx * qy - qz * qw), 2 * (qx * qz + qy * qw)],
            [2 * (qx * qy + qz * qw), 1 - 2 * (qx * qx + qz * qz), 2 * (qy * qz - qx * qw)],
            [2 * (qx * qz - qy * qw), 2 * (qy * qz + qx * qw), 1 - 2 * (qx * qx + qy * qy)]])
        views[os.path.splitext(w[9])[0]] = (r, np.array([tx, ty, tz]), cams[int(w[8])])
    return views


def main():
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    scene, run = sys.argv[1:]
    views = read_model(scene)
    gts = {n: read_pfm(os.path.join(scene, "gt_depth", n + ".pfm")) for n in views}
    total = {g: [0, 0] for g in GROUPS}
    for name, (r, t, (fx, fy, cx, cy)) in sorted(views.items()):
        g = gts[name]
        est_path = os.path.join(run, "depth", name + ".pfm")
        if not os.path.exists(est_path):
            print(f"{name}: no depth map, left out")
            continue
        est = read_pfm(est_path)
        if est.shape != g.shape:
            print(f"{name}: matched at {est.shape[1]}x{est.shape[0]}, left out")
            continue
        ys, xs = np.mgrid[0:g.shape[0]:2, 0:g.shape[1]:2]
        z = g[ys, xs]
        ok = np.isfinite(z) & (z > 0)
        xs, ys, z = xs[ok], ys[ok], z[ok]
        xc = np.stack([(xs + .5 - cx) / fx * z, (ys + .5 - cy) / fy * z, z])
        xw = r.T @ (xc - t[:, None])
        seen = np.zeros(len(z), int)
        for other, (ro, to, (fxo, fyo, cxo, cyo)) in views.items():
            if other == name:
                continue
            y = ro @ xw + to[:, None]
            with np.errstate(divide="ignore", invalid="ignore"):
                u = fxo * y[0] / y[2] + cxo - .5
                v = fyo * y[1] / y[2] + cyo - .5
            go = gts[other]
            inside = (y[2] > 0) & (u >= 0) & (v >= 0) & (u < go.shape[1] - 1) & (v < go.shape[0] - 1)
            zo = np.full(len(z), np.nan)
            zo[inside] = go[np.round(v[inside]).astype(int), np.round(u[inside]).astype(int)]
            with np.errstate(invalid="ignore"):
                seen += inside & (np.abs(zo - y[2]) < 0.01 * y[2])
        e = est[ys, xs]
        has = np.isfinite(e) & (e > 0)
        for lo, hi in GROUPS:
            m = (seen >= lo) & (seen <= hi)
            total[(lo, hi)][0] += int(m.sum())
            total[(lo, hi)][1] += int((has & m).sum())
    n = sum(a for a, _ in total.values())
    if n == 0:
        sys.exit(f"{run}: no view at the ground truth's size")
    print("seen by other views\tshare of pixels\tcoverage")
    for (lo, hi), (a, b) in total.items():
        label = str(lo) if lo == hi else (f"{lo}-{hi}" if hi < 10 ** 6 else f"{lo}+")
        print(f"{label}\t{a / n:.3f}\t{b / max(a, 1):.3f}")


if __name__ == "__main__":
    main()
