#!/usr/bin/python3
"""Plots a bench/soak.sh CSV (RSS, CPU, drops, keyframes, cloud size over
time) to a PNG and prints a summary.   soak_plot.py SOAK.csv OUT.png"""
import csv
import math
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def column(rows, key):
    out = []
    for r in rows:
        try:
            out.append(float(r[key]))
        except (KeyError, ValueError):
            out.append(math.nan)
    return out


def finite(v):
    return [x for x in v if not math.isnan(x)]


def main():
    rows = list(csv.DictReader(open(sys.argv[1])))
    if not rows:
        sys.exit("soak_plot: no rows in " + sys.argv[1])
    t = [x / 60.0 for x in column(rows, "elapsed_s")]
    fig, ax = plt.subplots(2, 2, figsize=(12, 7), sharex=True)
    for name in ("depth", "fusion"):
        ax[0][0].plot(t, column(rows, name + "_rss_mb"), label=name + "_node")
        ax[0][1].plot(t, column(rows, name + "_cpu_pct"), label=name + "_node")
    ax[0][0].set_ylabel("RSS (MB)")
    ax[0][1].set_ylabel("CPU (% of one core)")
    for key in ("frames_dropped", "views_dropped", "evicted_waiting"):
        ax[1][0].plot(t, column(rows, key), label=key)
    ax[1][0].plot(t, column(rows, "frames_sent"), "--", label="frames sent")
    ax[1][0].set_ylabel("count")
    ax[1][0].set_yscale("symlog")
    b = ax[1][1]
    b.plot(t, column(rows, "keyframes_created"), label="keyframes created")
    b.plot(t, column(rows, "depth_maps"), label="depth maps")
    b.plot(t, column(rows, "views_fused"), label="views fused")
    b.plot(t, column(rows, "keyframes_held"), label="keyframes held")
    b.set_ylabel("count")
    b2 = b.twinx()
    b2.plot(t, [x / 1000.0 for x in column(rows, "cloud_points")], "k:",
            label="cloud (k points)")
    b2.set_ylabel("cloud points (thousands)")
    for a in (ax[0][0], ax[0][1], ax[1][0], b):
        a.legend(loc="upper left", fontsize=8)
        a.grid(alpha=0.3)
    b2.legend(loc="lower right", fontsize=8)
    ax[1][0].set_xlabel("minutes")
    ax[1][1].set_xlabel("minutes")
    fig.suptitle("wild_mvs soak: looped bag through depth_node + fusion_node")
    fig.tight_layout()
    fig.savefig(sys.argv[2], dpi=80)

    def stat(key):
        v = finite(column(rows, key))
        return v if v else [math.nan]

    for name in ("depth", "fusion"):
        rss = stat(name + "_rss_mb")
        cpu = stat(name + "_cpu_pct")
        print("%s_node: RSS start %.0f MB, peak %.0f MB, end %.0f MB; CPU mean %.0f %%, "
              "max %.0f %%" % (name, rss[0], max(rss), rss[-1], sum(cpu) / len(cpu),
                               max(cpu)))
    last = rows[-1]
    print("after %.0f s: %s frames sent, %s dropped by the depth node, %s keyframes "
          "created (%s held, peak %.0f), %s depth maps, %s views fused, %s views "
          "dropped, cloud %s points (peak %.0f)" % (
              float(last["elapsed_s"]), last["frames_sent"], last["frames_dropped"],
              last["keyframes_created"], last["keyframes_held"],
              max(stat("keyframes_held")), last["depth_maps"], last["views_fused"],
              last["views_dropped"], last["cloud_points"], max(stat("cloud_points"))))


if __name__ == "__main__":
    main()
