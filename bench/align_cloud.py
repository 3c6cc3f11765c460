#!/usr/bin/env python3
"""Brings a cloud from an arbitrary frame into a reference frame by the
camera centres (docs/METHODS.md, "Photos only").

Structure-from-motion from photos alone gives cameras and points in a frame
of its own choosing: any rotation, translation and scale. The similarity
transform (scale s, rotation R, translation t; x_ref = s R x + t) that maps
the run's camera centres onto the reference's in the least-squares sense
(Umeyama 1991, closed form from the SVD of the centres' covariance) is
applied to every point of the cloud. Cameras are paired by name; at least
three, not on one line, are needed.

Usage: bench/align_cloud.py REF_CAMERAS RUN_CAMERAS IN.ply OUT.ply
REF_CAMERAS, RUN_CAMERAS: `cameras/` folders of two `wild_mvs reconstruct`
outputs (NAME.txt: width height / fx fy cx cy / R / t, world-to-camera).
IN.ply: a binary little-endian PLY with float x y z vertices (other vertex
properties are dropped); OUT.ply: x y z only. Prints one line of JSON:
cameras paired, scale, and the centres' RMS and largest residual after the
alignment (in the reference's units).
"""
import json
import os
import sys

import numpy as np

PLY_TYPES = {"char": "i1", "uchar": "u1", "int8": "i1", "uint8": "u1",
             "short": "<i2", "ushort": "<u2", "int16": "<i2", "uint16": "<u2",
             "int": "<i4", "uint": "<u4", "int32": "<i4", "uint32": "<u4",
             "float": "<f4", "float32": "<f4", "double": "<f8",
             "float64": "<f8"}


def camera_centres(folder):
    out = {}
    for name in sorted(os.listdir(folder)):
        if not name.endswith(".txt"):
            continue
        rows = []
        with open(os.path.join(folder, name)) as f:
            for line in f:
                line = line.strip()
                if line and not line.startswith("#"):
                    rows.append(line.split())
        if len(rows) < 6:
            sys.exit(f"{folder}/{name}: not a wild_mvs camera file")
        r = np.array(rows[2:5], dtype=float)
        t = np.array(rows[5], dtype=float)
        out[name[:-4]] = -r.T @ t
    return out


def similarity(src, dst):
    """s, R, t minimising sum |dst - (s R src + t)|^2 (Umeyama)."""
    mu_s, mu_d = src.mean(0), dst.mean(0)
    a, b = src - mu_s, dst - mu_d
    u, d, vt = np.linalg.svd(b.T @ a / len(src))
    e = np.eye(3)
    if np.linalg.det(u) * np.linalg.det(vt) < 0:
        e[2, 2] = -1
    rot = u @ e @ vt
    var = (a ** 2).sum() / len(src)
    s = np.trace(np.diag(d) @ e) / var
    return s, rot, mu_d - s * rot @ mu_s


def read_ply_xyz(path):
    with open(path, "rb") as f:
        if f.readline().strip() != b"ply":
            sys.exit(f"{path}: not a PLY file")
        fmt, count, props, in_vertex = None, 0, [], False
        while True:
            line = f.readline()
            if not line:
                sys.exit(f"{path}: no end_header")
            w = line.decode("ascii", "replace").split()
            if not w:
                continue
            if w[0] == "format":
                fmt = w[1]
            elif w[0] == "element":
                in_vertex = w[1] == "vertex"
                if in_vertex:
                    count = int(w[2])
            elif w[0] == "property" and in_vertex:
                if w[1] == "list" or w[1] not in PLY_TYPES:
                    sys.exit(f"{path}: vertex property '{' '.join(w[1:])}' unsupported")
                props.append((w[2], PLY_TYPES[w[1]]))
            elif w[0] == "end_header":
                break
        if fmt != "binary_little_endian":
            sys.exit(f"{path}: format {fmt}, expected binary_little_endian")
        v = np.fromfile(f, dtype=np.dtype(props), count=count)
    if len(v) < count:
        sys.exit(f"{path}: truncated ({len(v)} of {count} vertices)")
    return np.stack([v["x"], v["y"], v["z"]], 1).astype(float)


def write_ply_xyz(path, xyz):
    tmp = path + ".tmp"
    with open(tmp, "wb") as f:
        f.write(b"ply\nformat binary_little_endian 1.0\n"
                b"element vertex %d\nproperty float x\nproperty float y\n"
                b"property float z\nend_header\n" % len(xyz))
        f.write(xyz.astype("<f4").tobytes())
    os.replace(tmp, path)


def main():
    if len(sys.argv) != 5:
        sys.exit(__doc__)
    ref_dir, run_dir, src, dst = sys.argv[1:]
    ref, run = camera_centres(ref_dir), camera_centres(run_dir)
    names = sorted(set(ref) & set(run))
    if len(names) < 3:
        sys.exit(f"{run_dir}: {len(names)} cameras named as in {ref_dir}; need 3")
    a = np.array([run[n] for n in names])
    b = np.array([ref[n] for n in names])
    if np.linalg.svd(a - a.mean(0), compute_uv=False)[1] < 1e-9 * max(1.0, np.abs(a).max()):
        sys.exit(f"{run_dir}: camera centres on one line; the alignment is undetermined")
    s, rot, t = similarity(a, b)
    res = np.linalg.norm((s * (rot @ a.T)).T + t - b, axis=1)
    xyz = read_ply_xyz(src)
    write_ply_xyz(dst, (s * (rot @ xyz.T)).T + t)
    print(json.dumps({"cameras": len(names), "scale": s,
                      "centre_rms": float(np.sqrt((res ** 2).mean())),
                      "centre_max": float(res.max())}))


if __name__ == "__main__":
    main()
