#!/usr/bin/env python3
"""Writes the small seed corpora of the fuzz harnesses (test/fuzz/corpus/).

Seeds are cut from the real datasets in ../shared/datasets (a few cameras,
images and points of each) plus hand-made files for formats without real
samples there (COLMAP binary, Bundler, PFM, PLY). Each seed stays a few KB.
Run from anywhere: python3 test/fuzz/make_corpus.py [SHARED_DATASETS_DIR]
Files that exist already are left alone, so committed seeds (and kept
findings) are never rewritten.
"""
import math
import os
import struct
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
CORPUS = os.path.join(HERE, "corpus")
SHARED = sys.argv[1] if len(sys.argv) > 1 else os.path.join(
    HERE, "..", "..", "..", "shared", "datasets")
SPLIT = b"#WMSPLIT"


def put(harness, name, data):
    d = os.path.join(CORPUS, harness)
    os.makedirs(d, exist_ok=True)
    p = os.path.join(d, name)
    if os.path.exists(p):
        return
    if isinstance(data, str):
        data = data.encode()
    with open(p, "wb") as f:
        f.write(data)


def read_lines(path):
    with open(path) as f:
        return [l.rstrip("\n") for l in f]


def data_lines(lines):
    return [l for l in lines if l.strip() and not l.startswith("#")]


def small_colmap(model_dir, n_images=3, n_points2d=6):
    """A consistent small COLMAP text model: the first n_images images, the
    first n_points2d observations of each, the points seen only there."""
    cams = data_lines(read_lines(os.path.join(model_dir, "cameras.txt")))
    imgs = data_lines(read_lines(os.path.join(model_dir, "images.txt")))
    pts = data_lines(read_lines(os.path.join(model_dir, "points3D.txt")))
    images = []
    for i in range(0, 2 * n_images, 2):
        head = imgs[i].split()
        obs = imgs[i + 1].split()
        obs = [obs[j:j + 3] for j in range(0, len(obs), 3)]
        images.append((head, obs))
    keep = {}
    for head, obs in images:
        for idx, o in enumerate(obs[:n_points2d]):
            keep[(int(head[0]), idx)] = o[2]
    points = []
    wanted = set(v for v in keep.values() if v != "-1")
    for l in pts:
        t = l.split()
        if t[0] not in wanted:
            continue
        track = [(int(t[k]), int(t[k + 1])) for k in range(8, len(t), 2)]
        track = [tr for tr in track if tr in keep]
        if len(track) >= 2:
            points.append(t[:8] + [str(x) for tr in track for x in tr])
    used = set(p[0] for p in points)
    cam_ids = set(h[8] for h, _ in images)
    cam_txt = "# Camera list\n" + "".join(
        l + "\n" for l in cams if l.split()[0] in cam_ids)
    img_txt = "# Image list\n"
    for head, obs in images:
        img_txt += " ".join(head) + "\n"
        img_txt += " ".join(" ".join(o[:2] + [o[2] if o[2] in used else "-1"])
                            for o in obs[:n_points2d]) + "\n"
    pts_txt = "# 3D point list\n" + "".join(" ".join(p) + "\n" for p in points)
    return cam_txt, img_txt, pts_txt, images, points


def colmap_binary(cam_txt, img_txt, pts_txt):
    models = {"SIMPLE_PINHOLE": 0, "PINHOLE": 1, "SIMPLE_RADIAL": 2,
              "RADIAL": 3, "OPENCV": 4}
    cams = data_lines(cam_txt.splitlines())
    out_c = struct.pack("<Q", len(cams))
    for l in cams:
        t = l.split()
        params = [float(x) for x in t[4:]]
        out_c += struct.pack("<IiQQ", int(t[0]), models[t[1]], int(t[2]),
                             int(t[3]))
        out_c += struct.pack("<%dd" % len(params), *params)
    imgs = data_lines(img_txt.splitlines())
    n = len(imgs) // 2
    out_i = struct.pack("<Q", n)
    for i in range(n):
        t = imgs[2 * i].split()
        out_i += struct.pack("<I7dI", int(t[0]), *[float(x) for x in t[1:8]],
                             int(t[8]))
        out_i += t[9].encode() + b"\0"
        o = imgs[2 * i + 1].split()
        obs = [o[j:j + 3] for j in range(0, len(o), 3)]
        out_i += struct.pack("<Q", len(obs))
        for x, y, pid in obs:
            out_i += struct.pack("<ddq", float(x), float(y), int(pid))
    pts = data_lines(pts_txt.splitlines())
    out_p = struct.pack("<Q", len(pts))
    for l in pts:
        t = l.split()
        out_p += struct.pack("<Q3d3Bd", int(t[0]), *[float(x) for x in t[1:4]],
                             *[int(x) for x in t[4:7]], float(t[7]))
        track = t[8:]
        out_p += struct.pack("<Q", len(track) // 2)
        for k in range(0, len(track), 2):
            out_p += struct.pack("<II", int(track[k]), int(track[k + 1]))
    return out_c, out_i, out_p


def colmap_seeds():
    sets = [("temple", "middlebury_templeSparseRing/colmap_sift_gt"),
            ("sacre_coeur", "internet_sacre_coeur/colmap_estimated/"
                            "sparse_pinhole_txt"),
            ("fountain", "strecha_fountain-P11/colmap_sift_gt")]
    for name, rel in sets:
        d = os.path.join(SHARED, rel)
        if not os.path.isdir(d):
            continue
        c, i, p, _, _ = small_colmap(d)
        put("colmap_text", name, "#WMSPLIT".join([c, i, p]))
        put("colmap_text", name + "_no_points", "#WMSPLIT".join([c, i]))
        bc, bi, bp = colmap_binary(c, i, p)
        put("colmap_binary", name, SPLIT.join([bc, bi, bp]))
        if name == "temple":
            # Distorted camera models, each with its parameter count.
            first = data_lines(c.splitlines())
            w, h = first[0].split()[2:4]
            variants = {
                "SIMPLE_PINHOLE": "1500 320 240",
                "SIMPLE_RADIAL": "1500 320 240 -0.05",
                "RADIAL": "1500 320 240 -0.05 0.01",
                "OPENCV": "1500 1510 320 240 -0.05 0.01 0.001 -0.002",
            }
            for model, params in variants.items():
                cams = "".join("%s %s %s %s %s\n" % (l.split()[0], model, w, h,
                                                     params) for l in first)
                put("colmap_text", "temple_" + model.lower(),
                    "#WMSPLIT".join([cams, i, p]))
                bc, bi, bp = colmap_binary(cams, i, p)
                put("colmap_binary", "temple_" + model.lower(),
                    SPLIT.join([bc, bi, bp]))


def par_seeds():
    for rel in ["middlebury_templeSparseRing/templeSR_par.txt",
                "middlebury_dinoSparseRing/dinoSR_par.txt"]:
        p = os.path.join(SHARED, rel)
        if not os.path.exists(p):
            continue
        lines = data_lines(read_lines(p))[1:4]
        lines = [n + l[l.index(" "):] for n, l in
                 zip(["a.png", "b.png", "c.png"], lines)]
        put("middlebury_par", os.path.basename(p).replace(".txt", ""),
            "3\n" + "\n".join(lines) + "\n")


def strecha_seeds():
    for rel in ["strecha_fountain-P11/cameras/0000.jpg.camera",
                "strecha_Herz-Jesus-P8/cameras/0003.jpg.camera"]:
        p = os.path.join(SHARED, rel)
        if os.path.exists(p):
            with open(p, "rb") as f:
                put("strecha_camera", rel.split("/")[0], b"\0" + f.read())
    d = os.path.join(SHARED, "pavilion_chair_sequence/cameras")
    for name in ["029.projmatrix", "067.projmatrix"]:
        if os.path.exists(os.path.join(d, name)):
            with open(os.path.join(d, name), "rb") as f:
                put("strecha_camera", "pavilion_" + name, b"\1" + f.read())


def rot_to_quat_inv(q):
    w, x, y, z = q
    return [[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
            [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
            [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]]


def bundler_seeds():
    d = os.path.join(SHARED, "middlebury_templeSparseRing/colmap_sift_gt")
    if not os.path.isdir(d):
        return
    cams_txt, _, _, images, points = small_colmap(d, 3, 8)
    cams = {l.split()[0]: l.split() for l in data_lines(cams_txt.splitlines())}
    out = "# Bundle file v0.3\n%d %d\n" % (len(images), len(points))
    idx_of = {}
    for k, (head, obs) in enumerate(images):
        idx_of[int(head[0])] = k
        c = cams[head[8]]
        f = float(c[4])
        R = rot_to_quat_inv([float(v) for v in head[1:5]])
        t = [float(v) for v in head[5:8]]
        # Bundler: camera looks down -z, y up: flip rows 2 and 3.
        Rb = [R[0], [-v for v in R[1]], [-v for v in R[2]]]
        tb = [t[0], -t[1], -t[2]]
        out += "%.6f 0 0\n" % f
        for row in Rb:
            out += " ".join("%.12f" % v for v in row) + "\n"
        out += " ".join("%.12f" % v for v in tb) + "\n"
    for p in points:
        out += " ".join(p[1:4]) + "\n" + " ".join(p[4:7]) + "\n"
        track = p[8:]
        entries = []
        for j in range(0, len(track), 2):
            iid, idx = int(track[j]), int(track[j + 1])
            head, obs = images[idx_of[iid]]
            c = cams[head[8]]
            x = float(obs[idx][0]) - float(c[2]) / 2
            y = float(c[3]) / 2 - float(obs[idx][1])
            entries.append("%d %d %.3f %.3f" % (idx_of[iid], idx, x, y))
        out += "%d %s\n" % (len(entries), " ".join(entries))
    names = ["a.png", "b.png", "c.png"]  # images the harness provides
    lst = "".join("images/%s 0 %s\n" % (n, cams[h[8]][4])
                  for n, (h, _) in zip(names, images))
    put("bundler", "temple", out + "#WMSPLIT" + lst)
    put("bundler", "temple_plain_list",
        out + "#WMSPLIT" + "".join("%s\n" % n for n in names))


def pfm_seeds():
    def pfm(tag, w, h, scale, vals, fmt):
        return (b"%s\n%d %d\n%s\n" % (tag, w, h, scale) +
                struct.pack(fmt % len(vals), *vals))
    put("pfm", "gray_le", pfm(b"Pf", 4, 3, b"-1.0",
                              [float(i) * 0.25 for i in range(12)], "<%df"))
    put("pfm", "color_be", pfm(b"PF", 2, 2, b"1.0",
                               [float(i) for i in range(12)], ">%df"))
    put("pfm", "nan_inf", pfm(b"Pf", 3, 1, b"-1",
                              [float("nan"), float("inf"), 0.0], "<%df"))
    put("pfm", "one_line_header", b"Pf 2 1 -1.0\n" + struct.pack("<2f", 1, 2))


def ply_seeds():
    verts = [(0, 0, 0), (1, 0, 0), (0, 1, 0), (0, 0, 1)]
    normals = [(0, 0, 1), (0, 0, 1), (0, 0, 1), (1, 0, 0)]
    colors = [(255, 0, 0), (0, 255, 0), (0, 0, 255), (128, 128, 128)]
    faces = [(0, 1, 2), (0, 1, 3)]
    head = ("ply\nformat %s 1.0\ncomment wild_mvs seed\nelement vertex 4\n"
            "property float x\nproperty float y\nproperty float z\n"
            "property float nx\nproperty float ny\nproperty float nz\n"
            "property uchar red\nproperty uchar green\nproperty uchar blue\n"
            "%send_header\n")
    face_head = "element face 2\nproperty list uchar int vertex_indices\n"
    body = "".join("%g %g %g %g %g %g %d %d %d\n" % (v + n + c)
                   for v, n, c in zip(verts, normals, colors))
    put("ply", "ascii_cloud", head % ("ascii", "") + body)
    put("ply", "ascii_mesh", head % ("ascii", face_head) + body +
        "".join("3 %d %d %d\n" % f for f in faces))
    for fmt, e in (("binary_little_endian", "<"), ("binary_big_endian", ">")):
        b = (head % (fmt, face_head)).encode()
        for v, n, c in zip(verts, normals, colors):
            b += struct.pack(e + "6f3B", *(v + n + c))
        for f in faces:
            b += struct.pack(e + "B3i", 3, *f)
        put("ply", fmt + "_mesh", b)
    xyz = ("ply\nformat ascii 1.0\nelement vertex 2\nproperty double x\n"
           "property double y\nproperty double z\nend_header\n1 2 3\n4 5 6\n")
    put("ply", "ascii_xyz_double", xyz)


def image_size_seeds():
    import zlib
    def chunk(t, d):
        return (struct.pack(">I", len(d)) + t + d +
                struct.pack(">I", zlib.crc32(t + d) & 0xffffffff))
    raw = b"".join(b"\0" + bytes(3 * 4) for _ in range(3))
    png = (b"\x89PNG\r\n\x1a\n" +
           chunk(b"IHDR", struct.pack(">IIBBBBB", 4, 3, 8, 2, 0, 0, 0)) +
           chunk(b"IDAT", zlib.compress(raw)) + chunk(b"IEND", b""))
    put("image_size", "png_4x3", png)
    put("image_size", "pnm_p6", b"P6\n# comment\n5 2\n255\n" + bytes(30))
    put("image_size", "pfm", b"Pf\n2 2\n-1\n" + bytes(16))
    bmp = (b"BM" + struct.pack("<IHHI", 54 + 16, 0, 0, 54) +
           struct.pack("<IiiHHIIiiII", 40, 2, -2, 1, 24, 0, 16, 0, 0, 0, 0) +
           bytes(16))
    put("image_size", "bmp_top_down", bmp)
    jpg = (b"\xff\xd8\xff\xe0" + struct.pack(">H", 16) + b"JFIF\0" +
           bytes(9) + b"\xff\xc0" + struct.pack(">HBHHB", 11, 8, 6, 7, 1) +
           b"\x01\x11\x00" + b"\xff\xd9")
    put("image_size", "jpeg_sof0_header", jpg)


def ros_seeds():
    def image(h, w, enc, step, data, big=0):
        return (struct.pack("<II", h, w) + bytes([len(enc)]) + enc.encode() +
                struct.pack("<BII", big, step, len(data)) + data)

    def info(h, w, model, D, K):
        return (struct.pack("<II", h, w) + bytes([len(model)]) +
                model.encode() + bytes([len(D)]) +
                struct.pack("<%dd" % len(D), *D) + struct.pack("<9d", *K))

    pose = struct.pack("<7d", 0.1, -0.2, 0.3, 0, 0, math.sin(0.1), math.cos(0.1))
    w, h = 4, 3
    depth = [1.0 + 0.1 * i for i in range(w * h)]
    depth[5] = float("nan")
    conf = [0.5] * (w * h)
    normals = [0.0, 0.0, -1.0] * (w * h)
    K = [100, 0, 1.5, 0, 100, 1.0, 0, 0, 1]
    dv = (b"\0" + struct.pack("<I", 7) + bytes([2]) + struct.pack("<II", 3, 5) +
          image(h, w, "32FC1", 4 * w, struct.pack("<%df" % len(depth), *depth)) +
          image(h, w, "32FC1", 4 * w, struct.pack("<%df" % len(conf), *conf)) +
          image(h, w, "32FC3", 12 * w,
                struct.pack("<%df" % len(normals), *normals)) +
          info(h, w, "plumb_bob", [0] * 5, K) + pose)
    put("ros_messages", "depth_view", dv)
    put("ros_messages", "image_rgb8",
        b"\1" + image(2, 2, "rgb8", 6, bytes(range(12))) + b"\1")
    put("ros_messages", "image_mono16",
        b"\1" + image(2, 3, "mono16", 6, bytes(range(12))) + b"\0")
    put("ros_messages", "image_bgra8_padded",
        b"\1" + image(2, 2, "bgra8", 10, bytes(range(20))) + b"\1")
    put("ros_messages", "camera_info",
        b"\2" + info(480, 640, "plumb_bob", [-0.1, 0.01, 0.001, 0, 0],
                      [500, 0, 319.5, 0, 505, 239.5, 0, 0, 1]) + pose)


if __name__ == "__main__":
    colmap_seeds()
    par_seeds()
    strecha_seeds()
    bundler_seeds()
    pfm_seeds()
    ply_seeds()
    ros_seeds()
    image_size_seeds()
    for h in sorted(os.listdir(CORPUS)):
        files = os.listdir(os.path.join(CORPUS, h))
        size = sum(os.path.getsize(os.path.join(CORPUS, h, f)) for f in files)
        print("%-16s %2d files %6d bytes" % (h, len(files), size))
