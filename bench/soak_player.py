#!/usr/bin/python3
"""Soak driver for bench/soak.sh (not a test).

Plays the frames of a `wild_mvs to-bag` bag (image, camera_info, tf) in an
endless loop at a fixed frame rate, restamping them with a continuous clock
(loop k, frame i -> t0 + (k * n + i) / rate), as a robot circling the same
object forever would send them: the depth node never sees time go back, so
keyframes, tracks, reconstructions and fusion keep running. Every
--sample-period s it appends one CSV row: RSS and CPU of the node processes
and the counters of their /diagnostics.

  soak_player.py BAG CSV --rate HZ [--linger N] --duration S --pid depth=PID --pid fusion=PID
"""
import argparse
import csv
import os
import sys
import time

import rosbag
import rospy
from diagnostic_msgs.msg import DiagnosticArray
from sensor_msgs.msg import CameraInfo, Image
from tf2_msgs.msg import TFMessage

CLK_TCK = os.sysconf("SC_CLK_TCK")

# (column, diagnostics status name part, key)
DIAG_COLUMNS = [
    ("frames_received", "depth_node", "frames received"),
    ("frames_dropped", "depth_node", "frames dropped"),
    ("queue_len", "depth_node", "input queue length"),
    ("keyframes_held", "depth_node", "keyframes held"),
    ("store_mb", "depth_node", "keyframe store MB"),
    ("keyframes_created", "depth_node", "keyframes created"),
    ("pending", "depth_node", "reconstructions pending"),
    ("depth_maps", "depth_node", "depth maps"),
    ("evicted_waiting", "depth_node", "keyframes evicted before reconstruction"),
    ("resets", "depth_node", "stream resets"),
    ("tracker_mb", "depth_node", "tracker MB"),
    ("views_fused", "fusion_node", "views fused"),
    ("views_dropped", "fusion_node", "views dropped"),
    ("revisions_ignored", "fusion_node", "revisions ignored"),
    ("cloud_points", "fusion_node", "points"),
    ("held_map_mb", "fusion_node", "held depth map MB"),
    ("maps_spilled", "fusion_node", "depth maps spilled"),
]


def read_frames(bag_path):
    """[(tf, info, image)] in bag order, one per image."""
    tfs, infos, frames = {}, {}, []
    with rosbag.Bag(bag_path) as bag:
        for topic, msg, _ in bag.read_messages():
            if topic == "/tf":
                tfs[msg.transforms[0].header.stamp] = msg
            elif topic.endswith("camera_info"):
                infos[msg.header.stamp] = msg
            elif topic.endswith("image_raw"):
                frames.append(msg)
    out = []
    for im in frames:
        s = im.header.stamp
        if s in tfs and s in infos:
            out.append((tfs[s], infos[s], im))
    if not out:
        sys.exit("soak_player: no (tf, camera_info, image) frames in " + bag_path)
    return out


def proc_sample(pid):
    """(RSS MB, CPU seconds) of a process, or (nan, nan) when it is gone."""
    try:
        with open("/proc/%d/status" % pid) as f:
            rss = next(int(l.split()[1]) for l in f if l.startswith("VmRSS:"))
        with open("/proc/%d/stat" % pid) as f:
            fields = f.read().rsplit(")", 1)[1].split()
        cpu = (int(fields[11]) + int(fields[12])) / CLK_TCK
        return rss / 1024.0, cpu
    except (OSError, StopIteration, ValueError):
        return float("nan"), float("nan")


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("bag")
    ap.add_argument("csv")
    ap.add_argument("--rate", type=float, default=20.0, help="frames per second")
    ap.add_argument("--linger", type=int, default=1,
                    help="frames per view in a row (1 = a new view every frame)")
    ap.add_argument("--duration", type=float, default=1800.0, help="seconds")
    ap.add_argument("--sample-period", type=float, default=10.0)
    ap.add_argument("--pid", action="append", default=[], help="NAME=PID")
    args = ap.parse_args(rospy.myargv()[1:])
    pids = dict((p.split("=")[0], int(p.split("=")[1])) for p in args.pid)

    rospy.init_node("soak_player", disable_signals=True)
    frames = read_frames(args.bag)
    n = len(frames)
    tf_pub = rospy.Publisher("/tf", TFMessage, queue_size=50)
    info_pub = rospy.Publisher("/camera/camera_info", CameraInfo, queue_size=50)
    image_pub = rospy.Publisher("/camera/image_raw", Image, queue_size=50)
    diag = {}

    def on_diag(msg):
        for st in msg.status:
            diag[st.name] = dict((kv.key, kv.value) for kv in st.values)

    rospy.Subscriber("/diagnostics", DiagnosticArray, on_diag)
    time.sleep(2.0)  # subscriptions settle

    def diag_value(name_part, key):
        for name, vals in list(diag.items()):
            if name_part in name and key in vals:
                return vals[key]
        return ""

    header = ["elapsed_s", "frames_sent", "loops"]
    for name in sorted(pids):
        header += [name + "_rss_mb", name + "_cpu_pct"]
    header += [c for c, _, _ in DIAG_COLUMNS]
    out = open(args.csv, "w", newline="")
    writer = csv.writer(out)
    writer.writerow(header)
    out.flush()

    t0_stamp = rospy.Time.now().to_sec()
    start = time.monotonic()
    last_cpu = dict((name, proc_sample(pid)[1]) for name, pid in pids.items())
    last_sample = start
    k = 0
    while True:
        now = time.monotonic()
        if now - start >= args.duration:
            break
        # Each view `linger` frames in a row (a camera at the frame rate on
        # a robot that moves one view step per linger frames).
        tf, info, im = frames[(k // args.linger) % n]
        stamp = rospy.Time.from_sec(t0_stamp + k / args.rate)
        tf.transforms[0].header.stamp = stamp
        info.header.stamp = stamp
        im.header.stamp = stamp
        tf_pub.publish(tf)
        info_pub.publish(info)
        image_pub.publish(im)
        k += 1
        if now - last_sample >= args.sample_period:
            row = ["%.1f" % (now - start), k, k // (n * args.linger)]
            dt = now - last_sample
            for name in sorted(pids):
                rss, cpu = proc_sample(pids[name])
                row += ["%.1f" % rss, "%.1f" % (100.0 * (cpu - last_cpu[name]) / dt)]
                last_cpu[name] = cpu
            row += [diag_value(p, key) for _, p, key in DIAG_COLUMNS]
            writer.writerow(row)
            out.flush()
            last_sample = now
        # Fixed frame rate on the wall clock.
        next_t = start + k / args.rate
        delay = next_t - time.monotonic()
        if delay > 0:
            time.sleep(delay)
    out.close()
    print("soak_player: sent %d frames (%d loops of %d) in %.0f s" %
          (k, k // n, n, time.monotonic() - start))


if __name__ == "__main__":
    main()
