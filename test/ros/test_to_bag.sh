#!/usr/bin/env bash
# `wild_mvs to-bag` (the CLI command, which runs wild_mvs_to_bag): a small
# rendered dataset (make_scene, COLMAP text model) written as a bag, then
# read back with `rosbag info` and python3-rosbag: topics, message types and
# counts, stamps (start 1000 s, 1 / rate apart), frame ids, the rgb8
# encoding and pixels, camera_info K (core -> ROS pixel convention: c - 0.5)
# and /tf and /camera/pose (camera centre and orientation) against the
# dataset's cameras.txt / images.txt; /sparse_points with --with-points.
# Then --compressed png (lossless: the same pixels), --max-image-size
# (K scaled), and a bag as a robot records it (--frames-per-view,
# --body-frame, --start-time: lingering frames, /tf of the body at 100 Hz,
# /tf_static of the camera).
#   test/ros/test_to_bag.sh WILD_MVS MAKE_SCENE DEVEL_DIR
set -eo pipefail
CLI=${1:?usage: test_to_bag.sh WILD_MVS MAKE_SCENE DEVEL_DIR}
MAKE_SCENE=${2:?usage}
DEVEL=${3:?usage}
# shellcheck source=/dev/null
source "$DEVEL/setup.bash"
export PATH=/usr/local/sbin:/usr/local/bin:/usr/sbin:/usr/bin:/sbin:/bin:$PATH
TMP=$(mktemp -d)
trap 'rm -rf "$TMP"' EXIT
fail() { echo "FAIL: $*" >&2; for f in "$TMP"/*.log; do [ -f "$f" ] && { echo "--- $f" >&2; tail -20 "$f" >&2; }; done; exit 1; }

"$MAKE_SCENE" constant "$TMP/ds" --views 4 --width 96 --height 72 --points 300 \
  >"$TMP/make_scene.log" 2>&1 || fail "make_scene"
"$CLI" to-bag "$TMP/ds" "$TMP/raw.bag" --rate 2 --with-points --with-pose \
  --world-frame map --camera-frame cam_opt >"$TMP/raw.log" 2>&1 || fail "to-bag (raw)"
"$CLI" to-bag "$TMP/ds" "$TMP/png.bag" --compressed png >"$TMP/png.log" 2>&1 ||
  fail "to-bag --compressed png"
"$CLI" to-bag "$TMP/ds" "$TMP/small.bag" --max-image-size 48 >"$TMP/small.log" 2>&1 ||
  fail "to-bag --max-image-size 48"
"$CLI" to-bag "$TMP/ds" "$TMP/robot.bag" --rate 1 --frames-per-view 3 \
  --body-frame base_link --start-time 1764800000.25 >"$TMP/robot.log" 2>&1 ||
  fail "to-bag as a robot records"
if "$CLI" to-bag "$TMP/ds" "$TMP/bad2.bag" --rate 20 --frames-per-view 3 \
  >"$TMP/bad2.log" 2>&1; then
  fail "to-bag: 3 frames at 30 Hz between views at 20 Hz succeeded"
fi
grep -q "do not fit between views" "$TMP/bad2.log" || fail "no reason for --frames-per-view"
# A bad argument is an error, not a bag.
if "$CLI" to-bag "$TMP/ds" "$TMP/bad.bag" --rate 0 >"$TMP/bad.log" 2>&1; then
  fail "to-bag --rate 0 succeeded"
fi
[ ! -e "$TMP/bad.bag" ] || fail "to-bag --rate 0 left a bag"

rosbag info "$TMP/raw.bag" >"$TMP/info.txt" 2>&1 || fail "rosbag info"
for want in "messages:    20" "/camera/image_raw  *4 msgs *: sensor_msgs/Image" \
  "/camera/camera_info  *4 msgs *: sensor_msgs/CameraInfo" \
  "/tf  *4 msgs *: tf2_msgs/TFMessage" \
  "/camera/pose  *4 msgs *: geometry_msgs/PoseStamped" \
  "/sparse_points  *4 msgs *: wild_mvs/SparsePoints" "duration:    1.5s"; do
  grep -Eq -- "$want" "$TMP/info.txt" || { cat "$TMP/info.txt" >&2; fail "rosbag info: no '$want'"; }
done
echo "ok: rosbag info"

/usr/bin/python3 - "$TMP" <<'PY' || fail "bag contents"
import os, struct, sys, zlib
import numpy as np
import rosbag

tmp = sys.argv[1]
ds = os.path.join(tmp, "ds")
errors = []


def check(cond, what):
    if not cond:
        errors.append(what)


def png_rgb(data):
    """8-bit RGB PNG (non-interlaced, as OpenCV writes it) -> HxWx3 RGB."""
    assert data[:8] == b"\x89PNG\r\n\x1a\n", "not a PNG"
    pos, idat = 8, b""
    while pos < len(data):
        n, kind = struct.unpack(">I4s", data[pos:pos + 8])
        body = data[pos + 8:pos + 8 + n]
        if kind == b"IHDR":
            w, h, depth, ctype, _, _, interlace = struct.unpack(">IIBBBBB", body)
            assert depth == 8 and ctype == 2 and interlace == 0, (depth, ctype)
        elif kind == b"IDAT":
            idat += body
        pos += 12 + n
    raw = zlib.decompress(idat)
    stride = 3 * w
    out = np.zeros((h, stride), np.int32)
    for y in range(h):
        f = raw[y * (stride + 1)]
        line = np.frombuffer(raw, np.uint8, stride, y * (stride + 1) + 1).astype(np.int32)
        prev = out[y - 1] if y else np.zeros(stride, np.int32)
        cur = np.zeros(stride, np.int32)
        for x in range(stride):
            a = cur[x - 3] if x >= 3 else 0
            b = prev[x]
            c = prev[x - 3] if x >= 3 else 0
            if f == 0:
                pred = 0
            elif f == 1:
                pred = a
            elif f == 2:
                pred = b
            elif f == 3:
                pred = (a + b) // 2
            else:  # Paeth
                p = a + b - c
                pa, pb, pc = abs(p - a), abs(p - b), abs(p - c)
                pred = a if pa <= pb and pa <= pc else (b if pb <= pc else c)
            cur[x] = (line[x] + pred) & 255
        out[y] = cur
    return out.reshape(h, w, 3).astype(np.uint8)


def png_file(path):
    with open(path, "rb") as f:
        return png_rgb(f.read())


def lines(path):
    with open(path) as f:
        return [l.split() for l in f if l.strip() and not l.startswith("#")]


cams = {}
for c in lines(os.path.join(ds, "sparse", "cameras.txt")):
    assert c[1] in ("PINHOLE",), c
    cams[int(c[0])] = dict(w=int(c[2]), h=int(c[3]), fx=float(c[4]),
                           fy=float(c[5]), cx=float(c[6]), cy=float(c[7]))
rows = lines(os.path.join(ds, "sparse", "images.txt"))
views = []
for r in rows:  # header lines then 2D-point lines alternate
    if len(r) == 10 and r[9].endswith(".png"):
        q = [float(v) for v in r[1:5]]  # qw qx qy qz (world -> camera)
        t = np.array([float(v) for v in r[5:8]])
        views.append(dict(name=r[9], q=q, t=t, cam=cams[int(r[8])]))
check(len(views) == 4, "4 views in images.txt, got %d" % len(views))


def rot(q):
    w, x, y, z = q
    return np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
                     [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
                     [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]])


def by_topic(path):
    out = {}
    for topic, msg, t in rosbag.Bag(path).read_messages():
        out.setdefault(topic, []).append((msg, t))
    return out


raw = by_topic(os.path.join(tmp, "raw.bag"))
check(sorted(raw) == ["/camera/camera_info", "/camera/image_raw", "/camera/pose",
                      "/sparse_points", "/tf"], "topics %s" % sorted(raw))
# Scene order: the views as LoadDataset orders them (by name).
views.sort(key=lambda v: v["name"])
for i, v in enumerate(views):
    stamp = 1000.0 + i / 2.0
    c = v["cam"]
    info, t = raw["/camera/camera_info"][i]
    check(abs(t.to_sec() - stamp) < 1e-6 and abs(info.header.stamp.to_sec() - stamp) < 1e-6,
          "camera_info %d stamp %s" % (i, info.header.stamp.to_sec()))
    check(info.header.frame_id == "cam_opt", "camera_info frame %s" % info.header.frame_id)
    check((info.width, info.height) == (c["w"], c["h"]), "camera_info size")
    K = [c["fx"], 0, c["cx"] - 0.5, 0, c["fy"], c["cy"] - 0.5, 0, 0, 1]
    check(np.allclose(info.K, K, atol=1e-9), "K %d: %s vs %s" % (i, list(info.K), K))
    check(list(info.D) == [0.0] * 5, "D not zero")

    img, t = raw["/camera/image_raw"][i]
    check(abs(img.header.stamp.to_sec() - stamp) < 1e-6, "image %d stamp" % i)
    check(img.header.frame_id == "cam_opt", "image frame %s" % img.header.frame_id)
    check(img.encoding == "rgb8" and img.step == 3 * img.width, "encoding %s" % img.encoding)
    check((img.width, img.height) == (c["w"], c["h"]), "image size")
    px = np.frombuffer(img.data, np.uint8).reshape(img.height, img.width, 3)
    png = png_file(os.path.join(ds, "images", v["name"]))
    check(np.array_equal(px, png), "image %d pixels differ from %s" % (i, v["name"]))

    R = rot(v["q"])
    C = -R.T @ v["t"]
    tf, t = raw["/tf"][i]
    check(len(tf.transforms) == 1, "one transform")
    T = tf.transforms[0]
    check(abs(T.header.stamp.to_sec() - stamp) < 1e-6, "tf stamp")
    check(T.header.frame_id == "map" and T.child_frame_id == "cam_opt",
          "tf frames %s -> %s" % (T.header.frame_id, T.child_frame_id))
    tr = T.transform.translation
    check(np.allclose([tr.x, tr.y, tr.z], C, atol=1e-6), "tf %d translation %s vs %s" % (i, tr, C))
    r = T.transform.rotation
    # camera -> world is R^T: the conjugate of the world -> camera quaternion.
    qcw = np.array([v["q"][0], -v["q"][1], -v["q"][2], -v["q"][3]])
    check(abs(abs(np.dot([r.w, r.x, r.y, r.z], qcw / np.linalg.norm(qcw))) - 1) < 1e-6,
          "tf %d rotation" % i)
    ps, t = raw["/camera/pose"][i]
    check(ps.header.frame_id == "map" and abs(ps.header.stamp.to_sec() - stamp) < 1e-6,
          "pose header")
    check(np.allclose([ps.pose.position.x, ps.pose.position.y, ps.pose.position.z], C,
                      atol=1e-6), "pose position")
    sp, t = raw["/sparse_points"][i]
    check(sp.header.frame_id == "map" and abs(sp.header.stamp.to_sec() - stamp) < 1e-6,
          "sparse_points header")
    for m in sp.points:
        check(len(m.stamps) >= 2 and all(s.to_sec() <= stamp + 1e-6 for s in m.stamps),
              "sparse point stamps")
        break
counts = [len(m.points) for m, _ in raw["/sparse_points"]]
check(counts == sorted(counts) and counts[-1] > 0, "sparse point counts %s" % counts)

png = by_topic(os.path.join(tmp, "png.bag"))
check(sorted(png) == ["/camera/camera_info", "/camera/image_raw/compressed", "/tf"],
      "png topics %s" % sorted(png))
for i, v in enumerate(views):
    cm, t = png["/camera/image_raw/compressed"][i]
    check(abs(t.to_sec() - (1000.0 + i / 5.0)) < 1e-6, "png stamp (default 5 Hz)")
    check(cm.format == "rgb8; png compressed bgr8", "format %s" % cm.format)
    check(cm.header.frame_id == "camera_optical_frame", "default frame %s" % cm.header.frame_id)
    # A PNG stores RGB ("bgr8" is the order OpenCV decodes it to).
    dec = png_rgb(bytes(cm.data))
    ref = png_file(os.path.join(ds, "images", v["name"]))
    check(np.array_equal(dec, ref), "png %d pixels" % i)

small = by_topic(os.path.join(tmp, "small.bag"))
for i, v in enumerate(views):
    c = v["cam"]
    s = 48.0 / max(c["w"], c["h"])
    info, _ = small["/camera/camera_info"][i]
    img, _ = small["/camera/image_raw"][i]
    check((info.width, info.height) == (48, 36) and (img.width, img.height) == (48, 36),
          "small size %dx%d" % (info.width, info.height))
    K = [c["fx"] * s, 0, c["cx"] * s - 0.5, 0, c["fy"] * s, c["cy"] * s - 0.5, 0, 0, 1]
    check(np.allclose(info.K, K, atol=1e-6), "small K %s vs %s" % (list(info.K), K))

# As a robot records: 3 frames of each view at 30 Hz, /tf world -> base_link
# at 100 Hz, one latched /tf_static base_link -> camera; tf at every image
# stamp (the samples beside it composed with the static transform) is the
# view's camera pose.
robot = by_topic(os.path.join(tmp, "robot.bag"))
check(sorted(robot) == ["/camera/camera_info", "/camera/image_raw", "/tf", "/tf_static"],
      "robot topics %s" % sorted(robot))
imgs = robot["/camera/image_raw"]
check(len(imgs) == 12, "robot images %d" % len(imgs))
st = robot["/tf_static"]
check(len(st) == 1 and len(st[0][0].transforms) == 1, "one /tf_static")
S = st[0][0].transforms[0]
check(S.header.frame_id == "base_link" and S.child_frame_id == "camera_optical_frame",
      "static frames %s -> %s" % (S.header.frame_id, S.child_frame_id))
conn = [c for c in rosbag.Bag(os.path.join(tmp, "robot.bag"))._connections.values()
        if c.topic == "/tf_static"]
check(conn and conn[0].header.get("latching") in ("1", b"1"), "/tf_static not latched")
tfs = sorted((T.header.stamp.to_sec(), T) for m, _ in robot["/tf"] for T in m.transforms)
check(all(T.header.frame_id == "map" or T.header.frame_id == "world" for _, T in tfs), "tf parent")
check(all(T.child_frame_id == "base_link" for _, T in tfs), "tf child")
gaps = np.diff([s for s, _ in tfs])
check(np.allclose(gaps, 0.01, atol=1e-6), "tf not at 100 Hz")


def mat(tr):
    q = tr.rotation
    M = np.eye(4)
    M[:3, :3] = rot([q.w, q.x, q.y, q.z])
    M[:3, 3] = [tr.translation.x, tr.translation.y, tr.translation.z]
    return M


body_cam = mat(S.transform)
for k, (img, t) in enumerate(imgs):
    i, j = divmod(k, 3)
    stamp = 1764800000.25 + i + j / 30.0
    check(abs(img.header.stamp.to_sec() - stamp) < 1e-5, "robot image %d stamp %.6f" %
          (k, img.header.stamp.to_sec()))
    # The tf samples on both sides of the stamp (tf2 interpolates them).
    before = max((s, T) for s, T in tfs if s <= stamp + 1e-9)[1]
    after = min((s, T) for s, T in tfs if s >= stamp - 1e-9)[1]
    v = views[i]
    R = rot(v["q"])
    for T in (before, after):
        W = mat(T.transform) @ body_cam  # world_T_camera
        check(np.allclose(W[:3, 3], -R.T @ v["t"], atol=1e-6) and
              np.allclose(W[:3, :3], R.T, atol=1e-6), "robot tf at image %d" % k)

if errors:
    print("\n".join(errors[:30]))
    sys.exit(1)
print("ok: bag contents (%d views, sparse points per frame %s)" % (len(views), counts))
PY
echo "ok: to-bag"
