#!/usr/bin/env python3
"""MVE scenes for the side-by-side benchmark (bench/run_mve.sh).

  bench/mve_scene.py from-colmap MODEL_DIR IMAGES_DIR SCENE_DIR
  bench/mve_scene.py to-wild-mvs SCENE_DIR EMBEDDING OUT

from-colmap writes the MVE scene that MVE's `dmrecon` reads from a COLMAP
text model (cameras.txt, images.txt, points3D.txt) of undistorted images
(PINHOLE or SIMPLE_PINHOLE cameras): SCENE_DIR/views/view_NNNN.mve/ with
meta.ini (the camera) and undistorted.<ext> (a copy of the image), and
SCENE_DIR/synth_0.out (the sparse points and the views that see them, MVE's
"drews 1.0" bundle). The views are numbered in the model's name order, so
the same model always gives the same scene. The cameras and points are the
model's own: no bundle adjustment or feature matching of MVE's runs.

to-wild-mvs converts the depth maps EMBEDDING (e.g. depth-L0) of every view
into a wild_mvs depth folder: OUT/depth/S.pfm (z along the optical axis,
0 = unknown) and OUT/cameras/S.txt (src/io/depth_map_io.cpp's layout), S
the stem of the view's name; `bench_depth_stats` and `wild_mvs eval depth`
read it like a reconstruct folder. The depth map may be smaller than the
image (dmrecon's --scale): the camera is scaled to it.

Conventions. MVE's camera (libs/mve/camera.cc): world-to-camera rotation
and translation, the camera looks along +z, x right, y down, as COLMAP's
and wild_mvs's; focal_length is normalised by the image's width (height
for portrait images once the pixel aspect is applied), pixel_aspect =
fy / fx, principal_point in fractions of width and height, pixel centres
at +0.5 as in COLMAP. MVE's depth is the distance along the viewing ray
(libs/mve/depthmap.cc, pixel_3dpos), so z = depth / |K^-1 (x+0.5, y+0.5,
1)|. The .mvei layout (libs/mve/image_io.cc): the 11-byte signature
"\\211MVE_IMAGE\\n", int32 width, height, channels, type (9 = float),
then the pixels, row by row, little endian on the machines MVE runs on.
Only the standard library is used.
"""
import array
import math
import os
import shutil
import struct
import sys

import wild_mvs_folder
from wild_mvs_folder import write_pfm

MVEI_SIGNATURE = b"\x89MVE_IMAGE\n"
MVEI_FLOAT = 9


def fail(msg):
    raise SystemExit(f"mve_scene.py: {msg}")


def data_lines(path):
    try:
        with open(path) as f:
            return [l.rstrip("\n") for l in f if not l.startswith("#")]
    except OSError as e:
        fail(f"{path}: {e.strerror}")


def read_colmap(model):
    cams = {}
    for l in data_lines(os.path.join(model, "cameras.txt")):
        t = l.split()
        if not t:
            continue
        cid, kind, w, h = int(t[0]), t[1], int(t[2]), int(t[3])
        p = [float(x) for x in t[4:]]
        if kind == "PINHOLE":
            fx, fy, cx, cy = p
        elif kind == "SIMPLE_PINHOLE":
            fx, cx, cy = p
            fy = fx
        else:
            fail(f"{model}/cameras.txt: camera {cid} is {kind}; MVE's "
                 "dmrecon needs undistorted images (PINHOLE or SIMPLE_PINHOLE)")
        cams[cid] = (w, h, fx, fy, cx, cy)
    lines = data_lines(os.path.join(model, "images.txt"))
    images = []
    for i in range(0, len(lines) - 1, 2):
        t = lines[i].split()
        if not t:
            continue
        qw, qx, qy, qz, tx, ty, tz = (float(x) for x in t[1:8])
        images.append(dict(id=int(t[0]), q=(qw, qx, qy, qz), t=(tx, ty, tz),
                           cam=int(t[8]), name=t[9]))
    points = []
    for l in data_lines(os.path.join(model, "points3D.txt")):
        t = l.split()
        if not t:
            continue
        xyz = [float(x) for x in t[1:4]]
        rgb = [int(x) for x in t[4:7]]
        track = [(int(t[k]), int(t[k + 1])) for k in range(8, len(t) - 1, 2)]
        points.append((xyz, rgb, track))
    return cams, images, points


def rotation(q):
    w, x, y, z = q
    n = math.sqrt(w * w + x * x + y * y + z * z)
    w, x, y, z = w / n, x / n, y / n, z / n
    return [1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y),
            2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x),
            2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)]


def mve_intrinsics(w, h, fx, fy, cx, cy):
    """MVE's (focal_length, pixel_aspect, principal_point) for this K."""
    aspect = fy / fx
    flen = fy / h if (w / h) * aspect < 1 else fx / w
    return flen, aspect, (cx / w, cy / h)


def from_colmap(model, images_dir, scene):
    cams, images, points = read_colmap(model)
    images.sort(key=lambda im: im["name"])
    index = {im["id"]: k for k, im in enumerate(images)}
    views = os.path.join(scene, "views")
    if os.path.exists(views):
        shutil.rmtree(views)
    os.makedirs(views)
    g = lambda v: repr(float(v))
    for k, im in enumerate(images):
        w, h, fx, fy, cx, cy = cams[im["cam"]]
        flen, aspect, pp = mve_intrinsics(w, h, fx, fy, cx, cy)
        src = os.path.join(images_dir, im["name"])
        if not os.path.isfile(src):
            fail(f"{src}: no such image (named in {model}/images.txt)")
        d = os.path.join(views, f"view_{k:04d}.mve")
        os.makedirs(d)
        ext = os.path.splitext(im["name"])[1].lower()
        shutil.copyfile(src, os.path.join(d, "undistorted" + ext))
        stem = os.path.splitext(os.path.basename(im["name"]))[0]
        with open(os.path.join(d, "meta.ini"), "w") as f:
            f.write("# MVE view meta data, from a COLMAP model\n\n[camera]\n"
                    f"focal_length = {g(flen)}\npixel_aspect = {g(aspect)}\n"
                    f"principal_point = {g(pp[0])} {g(pp[1])}\n"
                    "radial_distortion = 0 0\n"
                    f"rotation = {' '.join(g(r) for r in rotation(im['q']))}\n"
                    f"translation = {' '.join(g(x) for x in im['t'])}\n\n"
                    f"[view]\nid = {k}\nname = {stem}\n")
    out = ["drews 1.0", f"{len(images)} {len(points)}"]
    for im in images:
        w, h, fx, fy, cx, cy = cams[im["cam"]]
        flen = mve_intrinsics(w, h, fx, fy, cx, cy)[0]
        r = rotation(im["q"])
        out += [f"{g(flen)} 0 0", " ".join(g(x) for x in r[0:3]),
                " ".join(g(x) for x in r[3:6]), " ".join(g(x) for x in r[6:9]),
                " ".join(g(x) for x in im["t"])]
    for xyz, rgb, track in points:
        refs = [(index[i], p) for i, p in track if i in index]
        out += [" ".join(g(x) for x in xyz), " ".join(str(c) for c in rgb),
                " ".join([str(len(refs))] + [f"{v} {p} 0" for v, p in refs])]
    with open(os.path.join(scene, "synth_0.out"), "w") as f:
        f.write("\n".join(out) + "\n")
    print(f"{scene}: {len(images)} views, {len(points)} points")


def read_ini(path):
    values, section = {}, ""
    with open(path) as f:
        for l in f:
            l = l.strip()
            if not l or l.startswith("#"):
                continue
            if l.startswith("[") and l.endswith("]"):
                section = l[1:-1]
            elif "=" in l:
                k, v = l.split("=", 1)
                values[f"{section}.{k.strip()}"] = v.strip()
    return values


def read_mvei(path):
    with open(path, "rb") as f:
        data = f.read()
    if not data.startswith(MVEI_SIGNATURE):
        fail(f"{path}: not an MVE image")
    w, h, c, kind = struct.unpack_from("<4i", data, len(MVEI_SIGNATURE))
    if c != 1 or kind != MVEI_FLOAT:
        fail(f"{path}: {c} channels of type {kind}, not one float channel")
    start = len(MVEI_SIGNATURE) + 16
    if len(data) < start + 4 * w * h:
        fail(f"{path}: truncated ({len(data)} bytes for {w}x{h})")
    v = array.array("f")
    v.frombytes(data[start:start + 4 * w * h])
    if sys.byteorder != "little":
        v.byteswap()
    return w, h, v


def to_wild_mvs(scene, embedding, out):
    views = os.path.join(scene, "views")
    for sub in ("depth", "cameras"):
        os.makedirs(os.path.join(out, sub), exist_ok=True)
    total = n = 0
    for d in sorted(os.listdir(views)):
        vd = os.path.join(views, d)
        dm = os.path.join(vd, embedding + ".mvei")
        if not d.endswith(".mve") or not os.path.isfile(dm):
            continue
        meta = read_ini(os.path.join(vd, "meta.ini"))
        w, h, depth = read_mvei(dm)
        flen = float(meta["camera.focal_length"])
        aspect = float(meta.get("camera.pixel_aspect", "1"))
        ppx, ppy = (float(x) for x in meta["camera.principal_point"].split())
        # K of the depth map's size (MVE's CameraInfo::fill_calibration).
        if (w / h) * aspect < 1:
            fx, fy = flen * h / aspect, flen * h
        else:
            fx, fy = flen * w, flen * w * aspect
        cx, cy = ppx * w, ppy * h
        z = array.array("f", bytes(4 * w * h))
        valid = 0
        for y in range(h):
            ry = (y + 0.5 - cy) / fy
            for x in range(w):
                r = depth[y * w + x]
                if r > 0:
                    rx = (x + 0.5 - cx) / fx
                    z[y * w + x] = r / math.sqrt(rx * rx + ry * ry + 1.0)
                    valid += 1
        stem = meta["view.name"].replace(" ", "_")
        write_pfm(os.path.join(out, "depth", stem + ".pfm"), z, w, h)
        text = wild_mvs_folder.camera_text(
            "an MVE view", w, h, fx, fy, cx, cy,
            meta["camera.rotation"].split(), meta["camera.translation"].split(),
            [])
        wild_mvs_folder.write_camera(out, stem, text)
        print(f"{d} -> {stem}: {w}x{h}, {valid} samples")
        total += valid
        n += 1
    if n == 0:
        fail(f"{views}: no view has {embedding}.mvei")
    print(f"TOTAL views={n} samples={total}")


def main(argv):
    if len(argv) == 5 and argv[1] == "from-colmap":
        from_colmap(argv[2], argv[3], argv[4])
    elif len(argv) == 5 and argv[1] == "to-wild-mvs":
        to_wild_mvs(argv[2], argv[3], argv[4])
    else:
        sys.stderr.write(__doc__)
        return 2
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
