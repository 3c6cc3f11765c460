#!/usr/bin/env python3
"""Converts OpenMVS per-view depth maps (.dmap) into a wild_mvs depth folder.

  bench/dmap_to_wild_mvs.py [--confidence] OUT DMAP...

Writes, per .dmap file, OUT/depth/S.pfm (z along the optical axis, 0 =
unknown) and OUT/cameras/S.txt (the depth map's camera in wild_mvs's layout,
src/io/depth_map_io.cpp), and with --confidence OUT/confidence/S.pfm; S is
the stem of the image file named in the .dmap. The result can be read by
`wild_mvs eval depth --est OUT` and bench_depth_stats like any reconstruct
folder. Only the standard library is used (no numpy).

The .dmap layout, from the format description in OpenMVS's
libs/MVS/Interface.h (HeaderDepthDataRaw), little endian:
  uint16 name ("DR"), uint8 type (1 depth, 2 normal, 4 confidence, 8 views),
  uint8 padding, uint32 image width, height, uint32 depth width, height,
  float dMin, dMax; uint16 n + n chars: image file name; uint32 n + n
  uint32: the view's ID and its neighbours' IDs; double K[3][3], R[3][3]
  (world to camera), C[3] (camera centre), row-major, at image resolution;
  float depth[h][w]; then optionally float normal[h][w][3], float
  confidence[h][w], uint8 views[h][w][4].
OpenMVS puts pixel centres at integer coordinates, wild_mvs (like COLMAP)
at +0.5, so cx, cy gain 0.5 (after scaling K to the depth map's size if it
differs from the image's).
"""
import array
import os
import struct
import sys

import wild_mvs_folder
from wild_mvs_folder import write_pfm

HAS_NORMAL, HAS_CONF, HAS_VIEWS = 2, 4, 8


def read_dmap(path):
    with open(path, "rb") as f:
        data = f.read()
    pos = 0

    def take(fmt):
        nonlocal pos
        vals = struct.unpack_from("<" + fmt, data, pos)
        pos += struct.calcsize("<" + fmt)
        return vals

    name, kind, _pad, iw, ih, dw, dh, dmin, dmax = take("HBBIIIIff")
    if name != struct.unpack("<H", b"DR")[0]:
        raise ValueError(f"{path}: not a .dmap file (magic {name:#x})")
    (nlen,) = take("H")
    image = data[pos:pos + nlen].decode("utf-8", "replace")
    pos += nlen
    (nids,) = take("I")
    ids = take(f"{nids}I")
    K = take("9d")
    R = take("9d")
    C = take("3d")
    n = dw * dh
    need = pos + 4 * n
    if len(data) < need:
        raise ValueError(f"{path}: truncated depth map ({len(data)} bytes, need {need})")
    depth = array.array("f")
    depth.frombytes(data[pos:pos + 4 * n])
    pos += 4 * n
    if kind & HAS_NORMAL:
        pos += 12 * n
    conf = None
    if kind & HAS_CONF:
        conf = array.array("f")
        conf.frombytes(data[pos:pos + 4 * n])
        pos += 4 * n
    if sys.byteorder != "little":
        depth.byteswap()
        if conf is not None:
            conf.byteswap()
    return dict(image=image, ids=ids, iw=iw, ih=ih, w=dw, h=dh, dmin=dmin,
                dmax=dmax, K=K, R=R, C=C, depth=depth, conf=conf)


def stem_of(image):
    base = image.replace("\\", "/").split("/")[-1]
    stem = base.rsplit(".", 1)[0] if "." in base else base
    return stem.replace(" ", "_")


def camera_text(d, neighbours):
    K, R, C = d["K"], d["R"], d["C"]
    sx, sy = d["w"] / d["iw"], d["h"] / d["ih"]
    fx, fy = K[0] * sx, K[4] * sy
    cx, cy = (K[2] + 0.5) * sx, (K[5] + 0.5) * sy
    t = [-(R[3 * r] * C[0] + R[3 * r + 1] * C[1] + R[3 * r + 2] * C[2])
         for r in range(3)]
    return wild_mvs_folder.camera_text("an OpenMVS .dmap", d["w"], d["h"],
                                       fx, fy, cx, cy, R, t, neighbours)


def main(argv):
    args = argv[1:]
    confidence = False
    if args and args[0] == "--confidence":
        confidence = True
        args = args[1:]
    if len(args) < 2 or args[0].startswith("-"):
        sys.stderr.write(__doc__)
        return 2
    out, paths = args[0], args[1:]
    for sub in ("depth", "cameras") + (("confidence",) if confidence else ()):
        os.makedirs(os.path.join(out, sub), exist_ok=True)
    maps = [read_dmap(p) for p in paths]
    # Neighbours by image file name (the scene's view names).
    names = {d["ids"][0]: d["image"].replace("\\", "/").split("/")[-1] for d in maps}
    total = 0
    for p, d in zip(paths, maps):
        s = stem_of(d["image"])
        valid = sum(1 for z in d["depth"] if z > 0)
        total += valid
        write_pfm(os.path.join(out, "depth", s + ".pfm"), d["depth"], d["w"], d["h"])
        if confidence and d["conf"] is not None:
            write_pfm(os.path.join(out, "confidence", s + ".pfm"), d["conf"],
                      d["w"], d["h"])
        nb = [names[i] for i in d["ids"][1:] if i in names]
        wild_mvs_folder.write_camera(out, s, camera_text(d, nb))
        print(f"{os.path.basename(p)} -> {s}: {d['w']}x{d['h']} "
              f"(image {d['iw']}x{d['ih']}), {valid} samples, "
              f"depth {d['dmin']:.4g}..{d['dmax']:.4g}, {len(d['ids']) - 1} neighbours")
    print(f"TOTAL views={len(maps)} samples={total}")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
