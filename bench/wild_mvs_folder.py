"""Writes a wild_mvs depth folder (the layout of src/io/depth_map_io.cpp)
from another system's depth maps: OUT/depth/S.pfm (z along the optical
axis in metres, 0 = unknown, little endian, bottom row first) and
OUT/cameras/S.txt (the depth map's camera: size, fx fy cx cy with pixel
centres at +0.5, world-to-camera R and t, neighbour names). Shared by the
peers' converters (bench/dmap_to_wild_mvs.py, bench/mve_scene.py); only the
standard library is used.
"""
import array
import os
import sys


def write_atomic(path, blob):
    tmp = path + ".tmp"
    with open(tmp, "wb") as f:
        f.write(blob)
    os.replace(tmp, path)


def write_pfm(path, values, w, h):
    """One-channel PFM of w x h floats given row by row from the top."""
    v = array.array("f", values)
    if sys.byteorder != "little":
        v.byteswap()
    raw = v.tobytes()
    row = 4 * w
    body = b"".join(raw[r * row:(r + 1) * row] for r in range(h - 1, -1, -1))
    write_atomic(path, b"Pf\n%d %d\n-1\n" % (w, h) + body)


def camera_text(source, w, h, fx, fy, cx, cy, R, t, neighbours):
    """The camera file's text; R: 9 values row-major, t: 3 values."""
    g = lambda x: repr(float(x))
    lines = [f"# wild_mvs depth map camera (converted from {source}): "
             "width height / fx fy cx cy / R (3 rows, world-to-camera) / t / "
             "N / N neighbour names",
             f"{w} {h}", f"{g(fx)} {g(fy)} {g(cx)} {g(cy)}"]
    for r in range(3):
        lines.append(" ".join(g(R[3 * r + k]) for k in range(3)))
    lines.append(" ".join(g(x) for x in t))
    lines.append(str(len(neighbours)))
    lines += neighbours
    return ("\n".join(lines) + "\n").encode()


def write_camera(out, stem, text):
    # The camera last, as wild_mvs does: its presence marks a finished view.
    write_atomic(os.path.join(out, "cameras", stem + ".txt"), text)
