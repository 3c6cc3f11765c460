#!/usr/bin/env python3
"""Writes docs/RESULTS.md, its plots and README's results block from the raw
outputs of one bench/run_all.sh run, and docs/ABLATION.md from the tables of
bench/run_ablation.sh (not a test).

    bench/make_results.py OUT_DIR ROOT

OUT_DIR holds what run_all.sh wrote: meta.tsv (key, value), speed/table.tsv,
fountain/fountain.tsv, families/*.tsv, scale/scale.tsv and, where the peers
ran here, peers/*.tsv. A section whose file is missing is listed as not run.
The peers' recorded figures come from bench/peers/*.tsv and are marked so.
Without OUT_DIR/meta.tsv, RESULTS.md and README are left as they are.

OUT_DIR/ablation (run_ablation.sh's --out) holds the ablation's tables and
its own meta.tsv (machine and code of its first table): with them,
ABLATION.md is written; without, it is left as it is. The ablation takes
longer than the rest of the set together, so the two pages are made on their
own schedules, and each names the code it measured.
"""
import csv
import glob
import os
import re
import sys

BEGIN = "<!-- results:begin -->"
END = "<!-- results:end -->"


def read_tsv(path):
    """Rows of a TSV file as dicts; lines starting with '#' are skipped."""
    if not os.path.isfile(path):
        return None
    with open(path) as f:
        lines = [l for l in f if l.strip() and not l.startswith("#")]
    return list(csv.DictReader(lines, delimiter="\t", quoting=csv.QUOTE_NONE))


def num(v):
    try:
        return float(v)
    except (TypeError, ValueError):
        return None


def pct(v, digits=2):
    x = num(v)
    return "-" if x is None else f"{100 * x:.{digits}f} %"


def count(v):
    x = num(v)
    if x is None:
        return "-"
    if x >= 1e6:
        return f"{x / 1e6:.2f} M"
    return f"{x:,.0f}"


def kilo(v):
    x = num(v)
    return "-" if x is None else f"{x / 1000:.1f} K"


def plain(v, fmt="{:.1f}"):
    x = num(v)
    return "-" if x is None else fmt.format(x)


def table(header, rows):
    out = ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
    out += ["| " + " | ".join(str(c) for c in r) + " |" for r in rows]
    return "\n".join(out)


# Columns of the scene-family tables: label and formatter, by TSV name.
FAMILY_COLUMNS = {
    "scene": ("scene", str), "family": ("family", str), "seed": ("seed", str),
    "complete@1%": ("coverage within 1 %", pct),
    "cmp@1%": ("coverage within 1 %", pct), "in1%": ("within 1 %", pct),
    "coverage": ("coverage", pct),
    "within0.5%": ("within 0.5 %", pct), "within1%": ("within 1 %", pct),
    "off>5%": ("off > 5 %", pct), "sky": ("sky", pct),
    "background": ("background", pct),
    "median_rel": ("median rel. error", lambda v: plain(v, "{:.5f}")),
    "represented": ("represented", pct),
    "F@1cm": ("F 1 cm", pct), "F@2cm": ("F 2 cm", pct),
    "F@5cm": ("F 5 cm", pct), "P@1cm": ("P 1 cm", pct),
    "R@1cm": ("R 1 cm", pct), "cloud_pts": ("cloud points", count),
    "cpu_s": ("CPU-s", plain), "rss_mb": ("peak RSS MB", lambda v: plain(v, "{:.0f}")),
}


def family_table(rows):
    cols = list(rows[0].keys())
    header = [FAMILY_COLUMNS.get(c, (c, str))[0] for c in cols]
    body = [[FAMILY_COLUMNS.get(c, (c, str))[1](r[c]) for c in cols] for r in rows]
    return table(header, body)


def first_key(row, names):
    for n in names:
        if n in row:
            return n
    return None


def plot_quality(path, scenes):
    """scenes: list of (name, coverage, within1, off5, background)."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    names = [s[0] for s in scenes]
    x = range(len(names))
    fig, (a, b) = plt.subplots(1, 2, figsize=(11, 3.8))
    w = 0.4
    a.bar([i - w / 2 for i in x], [100 * s[1] for s in scenes], w, label="coverage")
    a.bar([i + w / 2 for i in x], [100 * s[2] for s in scenes], w, label="estimates within 1 %")
    a.set_ylim(0, 118)
    a.set_ylabel("%")
    a.set_title("coverage and accuracy")
    b.bar([i - w / 2 for i in x], [100 * s[3] for s in scenes], w, label="off by more than 5 %",
          color="tab:red")
    b.bar([i + w / 2 for i in x], [100 * s[4] for s in scenes], w,
          label="background / sky estimates", color="tab:gray")
    b.set_ylabel("% of the estimates")
    b.set_title("errors")
    b.set_ylim(0, 1.25 * max([100 * max(s[3], s[4]) for s in scenes] + [0.1]))
    for ax in (a, b):
        ax.set_xticks(list(x))
        ax.set_xticklabels(names, rotation=30, ha="right")
        ax.legend(fontsize=8, loc="upper center", ncol=2)
        ax.grid(axis="y", alpha=0.3)
    fig.tight_layout()
    fig.savefig(path, dpi=90)
    plt.close(fig)


def plot_scale(path, rows):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    views = [int(r["views"]) for r in rows]
    fig, (a, b) = plt.subplots(1, 2, figsize=(10, 3.5))
    a.plot(views, [float(r["cpu_s_per_view"]) for r in rows], "o-", label="whole reconstruct")
    a.plot(views, [float(r["mvs_cpu_s_per_view"]) for r in rows], "s--", label="depth maps only")
    a.set_xlabel("views")
    a.set_ylabel("CPU-s per view")
    a.set_ylim(bottom=0)
    a.legend(fontsize=8)
    b.plot(views, [float(r["peak_rss_mb"]) for r in rows], "o-", color="tab:purple")
    b.set_xlabel("views")
    b.set_ylabel("peak RSS (MB)")
    b.set_ylim(bottom=0)
    for ax in (a, b):
        ax.grid(alpha=0.3)
    fig.tight_layout()
    fig.savefig(path, dpi=90)
    plt.close(fig)


def mechanism_section(abl_dir, default_rows, setting):
    """The ablation table: per switch, each family's mean coverage within 1 %
    and estimates off by more than 5 %, with the default's beside."""
    def means(rows):
        return {r["family"]: r for r in rows if r["scene"] == "MEAN"}
    base = means(default_rows)
    fams = list(base)
    md = [f"`bench/run_ablation.sh --size {setting['size']} --seeds {setting['seeds']}`: "
          "the rendered scene families (images "
          f"{setting['size']}x{int(setting['size']) * 3 // 4}) with the default options, "
          "then with one mechanism switched off (`--ablation.NAME false`, "
          "`core/ablation.h`). Per family: mean coverage within 1 % / estimates off "
          "by more than 5 %. A mechanism is needed on a family where switching it "
          "off loses coverage within 1 % or adds estimates off by more than 5 % "
          "or on the sky; "
          "one needed on no family is deleted (docs/METHODS.md, \"Benchmark "
          "protocol\").", ""]
    header = ["switched off"] + fams + ["needed on"]
    cell = lambda r: f"{pct(r['cmp@1%'], 1)} / {pct(r['off>5%'])}"
    body = [["nothing (defaults)"] + [cell(base[f]) for f in fams] + ["-"]]
    for name in setting["switches"].split():
        rows = read_tsv(os.path.join(abl_dir, f"no_{name}.tsv"))
        if not rows:
            body.append([name] + ["not run"] * len(fams) + ["-"])
            continue
        off = means(rows)
        needed = []
        for f in fams:
            if f not in off:
                continue
            why = []
            if num(off[f]["cmp@1%"]) < num(base[f]["cmp@1%"]):
                why.append("coverage")
            if (num(off[f]["off>5%"]) > num(base[f]["off>5%"]) or
                    num(off[f]["sky"]) > num(base[f]["sky"])):
                why.append("accuracy")
            if why:
                needed.append(f"{f} ({', '.join(why)})")
        body.append([f"`{name}`"] + [cell(off[f]) if f in off else "-" for f in fams] +
                    ["; ".join(needed) or "**none**"])
    return md + [table(header, body), ""]


def thresholds_section(abl_dir, default_rows, setting):
    """The moves table: per numeric option moved one step from its default,
    each family's means beside the default's, and the families where the
    moved value is at least as good."""
    def means(rows):
        return {r["family"]: r for r in rows if r["scene"] == "MEAN"}
    base = means(default_rows)
    fams = list(base)
    moves = [m.split("=", 1) for m in setting.get("moves", "").split()]
    md = [f"`bench/run_ablation.sh --size {setting['size']} --seeds {setting['seeds']}`, "
          "the same scenes: each numeric option of the matching, the filter and the "
          "fusion moved one step from its default (`--KEY VALUE`), the others at "
          "theirs. A value at least as good as the default on every family would "
          "replace it (after the same result on other seeds); one that changes "
          "nothing anywhere marks an option these scenes do not exercise. The "
          "`mvs.*.wide_*` thresholds apply only to images of 1200 px and more.", ""]
    if not moves:
        md += ["Not run.", ""]

    def verdict(rows, keys, better_high, base=base):
        moved = means(rows)
        good, same = [], True
        for f in fams:
            if f not in moved:
                return "-"
            ok = True
            for k, high in zip(keys, better_high):
                a, b = num(moved[f][k]), num(base[f][k])
                if a != b:
                    same = False
                if (a < b) if high else (a > b):
                    ok = False
            if ok:
                good.append(f)
        if same:
            return "no change"
        if len(good) == len(fams):
            return "**every family**"
        return ", ".join(good) or "none"

    groups = [("matching and filter: coverage within 1 % / estimates off by more "
               "than 5 % (a value is at least as good with no less of the first, "
               "no more of the second and no more on the sky)",
               lambda k: not k.startswith("fusion."),
               ["cmp@1%", "off>5%", "sky"], [True, False, False],
               lambda r: f"{pct(r['cmp@1%'], 1)} / {pct(r['off>5%'])}"),
              ("fusion: the cloud's F-score at 1 cm / 5 cm",
               lambda k: k.startswith("fusion."),
               ["F@1cm", "F@5cm"], [True, True],
               lambda r: f"{pct(r['F@1cm'], 1)} / {pct(r['F@5cm'], 1)}")]
    def moves_table(chosen, prefix, base, keys, high, cell):
        """A row per move (OUT/{prefix}set_KEY_VALUE.tsv) below `base`."""
        body = [["defaults"] + [cell(base[f]) for f in fams] + ["-"]]
        for k, v in chosen:
            rows = read_tsv(os.path.join(abl_dir, f"{prefix}set_{k}_{v}.tsv"))
            if not rows:
                body.append([f"`{k}` {v}"] + ["not run"] * len(fams) + ["-"])
                continue
            moved = means(rows)
            body.append([f"`{k}` {v}"] +
                        [cell(moved[f]) if f in moved else "-" for f in fams] +
                        [verdict(rows, keys, high, base)])
        return table(["option, value"] + fams + ["at least as good on"], body)

    for title, member, keys, high, cell in groups:
        chosen = [(k, v) for k, v in moves if member(k)]
        if not chosen:
            continue
        md += [f"Options of the {title}:", "",
               moves_table(chosen, "", base, keys, high, cell), ""]
    md += tracker_moves(abl_dir, setting, means, moves_table)
    md += fountain_moves(abl_dir, setting)
    return md


def tracker_moves(abl_dir, setting, means, moves_table):
    """The tracker's thresholds moved on the families rendered without
    sparse points (the tool makes its own tracks), against that setting's
    default run."""
    moves = [m.split("=", 1) for m in setting.get("tracker_moves", "").split()]
    default_rows = read_tsv(os.path.join(abl_dir, "tracker_default.tsv"))
    if not moves or not default_rows:
        return ["The tracker's thresholds: not run (`--tracker-moves none`).", ""]
    def cell(r):
        return f"{pct(r['cmp@1%'], 1)} / {pct(r['off>5%'])}"
    return ["The tracker's thresholds, on the same families rendered without "
            "sparse points (`bench/run_families.sh --points 0`; the tool makes "
            "its own tracks, `--stages sparse,depth,fuse,mesh`, as from photos "
            "alone): coverage within 1 % / estimates off by more than 5 %, "
            "against the defaults in that setting "
            "(`tracker.features.max_image_size`, 2000 px, does not act on these "
            "images):", "",
            moves_table(moves, "tracker_", means(default_rows),
                        ["cmp@1%", "off>5%", "sky"], [True, False, False], cell), ""]


def fountain_moves(abl_dir, setting):
    """The wide-window thresholds moved on fountain-P11 at 1536 px: coverage
    within 1 % (coverage x within 1 % of the estimates), off > 5 % and
    background beside the default run's."""
    moves = [m.split("=", 1) for m in setting.get("wide_moves", "").split()]
    base = read_tsv(os.path.join(abl_dir, "fountain_default", "fountain.tsv"))
    if not moves or not base:
        return ["The `wide_*` thresholds: not run (fountain-P11 absent or "
                "`--wide-moves none`).", ""]
    keys = ["cmp", "off>5%", "background"]

    def row(rows):
        r = dict(rows[0])
        r["cmp"] = str(num(r["coverage"]) * num(r["within1%"]))
        return r
    b = row(base)
    cell = lambda r: (f"{pct(r['cmp'], 1)} / {pct(r['off>5%'])} / "
                      f"{pct(r['background'])}")
    body = [["defaults", cell(b), "-"]]
    for k, v in moves:
        rows = read_tsv(os.path.join(abl_dir, f"fountain_set_{k}_{v}", "fountain.tsv"))
        if not rows:
            body.append([f"`{k}` {v}", "not run", "-"])
            continue
        r = row(rows)
        a = [round(num(r[x]), 4) for x in keys]
        d = [round(num(b[x]), 4) for x in keys]
        verdict = ("no change" if a == d else
                   "yes" if a[0] >= d[0] and a[1] <= d[1] and a[2] <= d[2] else "no")
        body.append([f"`{k}` {v}", cell(r), verdict])
    return ["The wide-window thresholds (`mvs.*.wide_*`, used from 1200 px) on "
            "fountain-P11 at 1536x1024 (`bench/run_fountain.sh`): coverage within 1 % "
            "(coverage x within 1 % of the estimates) / off by more than 5 % / "
            "background estimates:", "",
            table(["option, value", "fountain-P11", "at least as good"], body), ""]


def read_meta(path):
    rows = read_tsv(path)
    return {r["key"]: r["value"] for r in rows} if rows else None


def reader_command(command):
    """A recorded command as a reader would repeat it (no local output folder)."""
    return re.sub(r" --out \S+| --skip-build", "", command)


def header_rows(meta):
    """The table under a page's title: where and on which code it ran."""
    return ["| | |", "|---|---|",
            f"| machine | {meta['cpu']}, {meta['cores']} cores, {meta['memory']} RAM, "
            f"Linux {meta['kernel']} |",
            f"| commit | {meta['commit']} |", f"| date | {meta['date']} |"]


def write_ablation(out, root, run_all):
    """docs/ABLATION.md from OUT/ablation (run_all: OUT/meta.tsv, or {});
    False when its tables are absent."""
    abl_dir = os.path.join(out, "ablation")
    abl_set = read_tsv(os.path.join(abl_dir, "setting.tsv"))
    abl_def = read_tsv(os.path.join(abl_dir, "default.tsv"))
    meta = read_meta(os.path.join(abl_dir, "meta.tsv")) or run_all or None
    if not (abl_set and abl_def and meta):
        return False
    setting = {r["key"]: r["value"] for r in abl_set}
    md = ["# Ablation", "",
          f"Generated by `bench/run_ablation.sh --size {setting['size']} --seeds "
          f"{setting['seeds']}` and `bench/make_results.py` from its tables; do not "
          "edit by hand (the protocol: [METHODS.md](METHODS.md), \"Benchmark "
          "protocol\"; the product's figures: [RESULTS.md](RESULTS.md)).", ""]
    md += header_rows(meta) + [f"| load | {meta['load']} |", ""]
    if run_all.get("mode") == "quick":
        md += ["> **Quick setting** (`bench/run_all.sh --quick`: one seed, no "
               "fountain moves): these tables check that the ablation runs; they "
               "do not decide a default.", ""]
    md += ["## Mechanisms: each switched off", ""]
    md += mechanism_section(abl_dir, abl_def, setting)
    md += ["## Thresholds: each moved one step", ""]
    md += thresholds_section(abl_dir, abl_def, setting)
    with open(os.path.join(root, "docs", "ABLATION.md"), "w") as f:
        f.write("\n".join(md).rstrip() + "\n")
    return True


def main():
    out, root = sys.argv[1], sys.argv[2]
    meta = read_meta(os.path.join(out, "meta.tsv"))
    wrote_ablation = write_ablation(out, root, meta or {})
    if meta is None:
        if not wrote_ablation:
            sys.exit(f"make_results.py: neither {out}/meta.tsv nor the ablation's "
                     f"tables in {out}/ablation")
        return
    quick = meta.get("mode") == "quick"
    command = reader_command(meta["command"])
    docs = os.path.join(root, "docs")
    md = ["# Results", "",
          f"Generated by `{command}` from one run; do not edit by hand "
          "(how each figure is measured: [METHODS.md](METHODS.md)).", ""]
    if quick:
        md += ["> **Quick setting**: smaller working sizes, smaller collections and "
               "one run each, so that the whole set ends in minutes. These figures check that "
               "the benchmarks work; they are not the full setting's and not "
               "comparable with the peers' figures. `bench/run_all.sh` without "
               "`--quick` gives the full set.", ""]
    md += header_rows(meta) + [f"| setting | {meta['setting']} |",
                               f"| load | {meta['load']} |"]
    # The ablation is on its own page (write_ablation).
    skipped = [s for s in meta.get("skipped", "").split(",") if s and s != "ablation"]
    # A section run_all.sh skipped and its own script ran into OUT later.
    live_meta = read_meta(os.path.join(out, "live", "meta.tsv"))
    if "live" in skipped and live_meta:
        skipped.remove("live")
        command_live = reader_command(live_meta["command"])
        same = live_meta.get("code") and live_meta.get("code") == meta.get("code")
        md.append(f"| live | `{command_live}` into the same folder afterwards: commit "
                  f"{live_meta['commit']} ({'the same' if same else 'other'} code), "
                  f"{live_meta['date']}, "
                  f"{live_meta['load'].split(' at the end')[0]} at its end |")
    if skipped:
        md.append(f"| not run | {', '.join(skipped)} (skipped) |")
    failed = [s for s in meta.get("failed", "").split(",") if s]
    if failed:
        md.append(f"| failed | {', '.join(failed)} (see the run's log) |")
    md += ["", "CPU-s are whole-process user + sys seconds, so they stay comparable "
           "on a shared machine; wall time is not reported.", ""]
    readme = []
    peers_dir = os.path.join(root, "bench", "peers")

    def ran_here(p):  # a peer's figures column when it ran beside wild_mvs
        return f"run here: {p['source']}" if p.get("source") else "run here"

    # --- speed -------------------------------------------------------------
    def state(name):  # what an absent section's table says
        return "Failed in this run." if name in failed else "Not run."
    speed = None if "speed" in failed else read_tsv(os.path.join(out, "speed", "table.tsv"))
    md += ["## Speed: templeSparseRing", ""]
    if speed:
        r = speed[0]
        size = meta.get("temple_size", "640")
        md += [f"Depth stage of `wild_mvs reconstruct` on `data/templeSparseRing` "
               f"(16 views, working size {size} px, default options, "
               f"`--threads {meta['threads']}`), median of {r['runs']} run(s). "
               "Correct = inside the object's bounding box + 5 mm and consistent "
               "with another view's map within 0.5 %.", ""]
        rows = [["wild_mvs", size, plain(r["cpu_s"]), count(r["samples"]),
                 count(r["correct"]), kilo(r["correct_per_cpu_s"]),
                 plain(r["peak_rss_mb"], "{:.0f}"), "run here"]]
        ran = read_tsv(os.path.join(out, "peers", "speed_temple.tsv")) or []
        ran_names = {p["system"] for p in ran}
        for p in ran:
            rows.append([p["system"], p["size"], plain(p["cpu_s"]), count(p["samples"]),
                         count(p["correct"]), kilo(p["correct_per_cpu_s"]),
                         plain(p["peak_rss_mb"], "{:.0f}"), ran_here(p)])
        for p in read_tsv(os.path.join(peers_dir, "speed_temple.tsv")):
            if p["system"] in ran_names:
                continue
            rows.append([p["system"], p["size"], plain(p["cpu_s"]), count(p["samples"]),
                         count(p["correct"]), kilo(p["correct_per_cpu_s"]),
                         plain(p["peak_rss_mb"], "{:.0f}"),
                         f"recorded, not run here: {p['source']}"])
        md += [table(["system", "px", "CPU-s", "samples", "correct",
                      "correct per CPU-s", "peak RSS MB", "figures"], rows), ""]
        readme.append([f"speed, templeSparseRing {size} px",
                       f"{kilo(r['correct_per_cpu_s'])} correct samples per CPU-s "
                       f"({count(r['correct'])} in {plain(r['cpu_s'])} CPU-s), "
                       f"peak RSS {plain(r['peak_rss_mb'], '{:.0f}')} MB"])
    else:
        md += [state("speed"), ""]

    # --- fountain ----------------------------------------------------------
    scenes = []
    fountain = None if "fountain" in failed else read_tsv(
        os.path.join(out, "fountain", "fountain.tsv"))
    md += ["## Quality: fountain-P11", ""]
    if fountain:
        f = fountain[0]
        md += [f"`wild_mvs reconstruct` (depth maps and fused cloud, default options) "
               f"of the 11 views at {f['size']} px on the longer side, against the "
               "dataset's ground-truth depth; the fused cloud against a cloud of "
               "the ground-truth depth (5 mm voxels).", ""]
        def frow(name, r, how):
            return [name, r["size"], pct(r["coverage"]), pct(r["within1%"]),
                    pct(r["off>5%"]), pct(r["background"]),
                    plain(r["median_abs_mm"]), pct(r["F@1cm"], 1), pct(r["F@2cm"], 1),
                    pct(r["F@5cm"], 1), plain(r["cpu_s"]),
                    plain(r["rss_mb"], "{:.0f}"), how]
        rows = [frow("wild_mvs", f, "run here (depth + fusion)")]
        ran = read_tsv(os.path.join(out, "peers", "fountain.tsv")) or []
        ran_names = {p["system"] for p in ran}
        rows += [frow(p["system"], p, ran_here(p)) for p in ran]
        rows += [frow(p["system"], p, f"recorded, not run here: {p['source']}")
                 for p in read_tsv(os.path.join(peers_dir, "fountain.tsv"))
                 if p["system"] not in ran_names]
        md += [table(["system", "px", "coverage", "within 1 %", "off > 5 %",
                      "background", "median error mm", "F 1 cm", "F 2 cm", "F 5 cm",
                      "CPU-s", "peak RSS MB", "figures"], rows), ""]
        scenes.append(("fountain-P11", num(f["coverage"]), num(f["within1%"]),
                       num(f["off>5%"]), num(f["background"])))
        readme.append([f"fountain-P11 {f['size']} px vs ground truth",
                       f"coverage {pct(f['coverage'], 1)}, {pct(f['within1%'], 1)} "
                       f"within 1 %, {pct(f['off>5%'])} off > 5 %; fused cloud F "
                       f"{pct(f['F@1cm'], 1)} / {pct(f['F@2cm'], 1)} / "
                       f"{pct(f['F@5cm'], 1)} at 1 / 2 / 5 cm"])
    else:
        md += [state("fountain"), ""]

    # --- photos only -------------------------------------------------------
    md += ["## Photos only: fountain-P11", ""]
    photos = None if "photos" in failed else read_tsv(
        os.path.join(out, "photos", "photos.tsv"))
    if photos:
        p0 = photos[0]
        md += [f"`bench/run_photos.sh`: `wild_mvs photos` on the 11 photos alone "
               "(Debian's colmap on the CPU finds the cameras), with intrinsics per "
               "photo (the default) and with `--single-camera` (the photos come from "
               "one camera), and `wild_mvs reconstruct` of the same photos on the "
               f"dataset's ground-truth cameras, all at {p0['size']} px. A photos-only "
               "cloud is brought into the ground truth's frame by the similarity "
               "transform that best maps its camera centres onto the true ones (least "
               "squares; centre RMS = what is left); every cloud against the "
               "ground-truth cloud (5 mm voxels).", ""]
        md += [table(["cameras", "px", "registered", "centre RMS mm", "points",
                      "F 1 cm", "F 2 cm", "F 5 cm", "CPU-s"],
                     [[r["cameras"], r["size"], r["registered"], r["centre_rms_mm"],
                       count(r["cloud_pts"]), pct(r["F@1cm"], 1), pct(r["F@2cm"], 1),
                       pct(r["F@5cm"], 1), r["cpu_s"]] for r in photos]), ""]
        by = {r["cameras"]: r for r in photos}
        g = by.get("ground truth")
        pp = by.get("photos only, intrinsics per photo")
        sc = by.get("photos only, --single-camera")
        if g and pp and sc:
            readme.append([f"fountain-P11 {sc['size']} px from photos alone (colmap SfM)",
                           f"F at 2 cm {pct(sc['F@2cm'], 1)} with `--single-camera`, "
                           f"{pct(pp['F@2cm'], 1)} with intrinsics per photo "
                           f"(ground-truth cameras {pct(g['F@2cm'], 1)}); "
                           f"{sc['registered']} photos registered"])
    else:
        md += [meta.get("photos_note") or state("photos"), ""]

    # --- scene families ----------------------------------------------------
    md += ["## Rendered scene families", ""]
    fam_files = [] if "families" in failed else sorted(
        glob.glob(os.path.join(out, "families", "*.tsv")))
    if fam_files:
        md += [meta.get("families_note", ""), ""]
        covs, accs = [], []
        for path in fam_files:
            rows = read_tsv(path)
            if not rows:
                continue
            title = os.path.splitext(os.path.basename(path))[0]
            md += [f"### {title}", "", family_table(rows), ""]
            ck = first_key(rows[0], ["coverage", "complete@1%"])
            ak = first_key(rows[0], ["in1%", "within1%"])
            ok = first_key(rows[0], ["off>5%"])
            sk = first_key(rows[0], ["sky", "background"])
            nk = first_key(rows[0], ["scene", "family"])
            if not (ck and ak and ok and sk):
                continue
            # One bar group per scene (mean over its seeds); the ranges of
            # the README from the MEAN rows where there are any.
            by_scene = {}
            for r in rows:
                if r.get(nk) == "MEAN":
                    continue
                by_scene.setdefault(r[nk] if nk else title, []).append(r)
            for name, rs in by_scene.items():
                mean = [sum(num(r[k]) for r in rs) / len(rs) for k in (ck, ak, ok, sk)]
                label = name if name == title or len(fam_files) == 1 else f"{title}: {name}"
                scenes.append(tuple([label] + mean))
            means = [r for r in rows if r.get(nk) == "MEAN"] or rows
            covs += [num(r[ck]) for r in means]
            accs += [num(r[ak]) for r in means]
        if covs:
            readme.append(["rendered scene families (exact ground truth)",
                           f"coverage {100 * min(covs):.1f}-{100 * max(covs):.1f} %, "
                           f"{100 * min(accs):.1f}-{100 * max(accs):.1f} % of the estimates "
                           "within 1 % (family means)"])
    else:
        md += [state("families"), ""]
    if scenes:
        plot_quality(os.path.join(docs, "results_quality.png"), scenes)
        md += ["![coverage and errors per scene](results_quality.png)", ""]

    # --- mechanisms and thresholds: their own page --------------------------------
    md += ["## Mechanisms and thresholds", "",
           "Each mechanism switched off and each threshold moved one step, on the "
           "same families at 320x240: [ABLATION.md](ABLATION.md), written from "
           "`bench/run_ablation.sh`'s tables by `bench/make_results.py` on its own schedule "
           "(the ablation takes longer than the rest of the set together); its "
           "header names the code it measured.", ""]

    # --- scale ---------------------------------------------------------------
    md += ["## Scale: synthetic photo collections", ""]
    scale = None if "scale" in failed else read_tsv(os.path.join(out, "scale", "scale.tsv"))
    if scale:
        md += [f"`bench/run_scale.sh {meta.get('scale_args', '')}`: whole "
               "`wild_mvs reconstruct` (depth, consistency filter, fusion) of "
               "collections of random viewpoints, 320-1600 px JPEGs, changing light "
               "and clutter.", ""]
        md += [table(["views", "CPU-s", "CPU-s per view", "depth maps: CPU-s per view",
                      "peak RSS MB", "samples", "fused points"],
                     [[r["views"], plain(r["cpu_s"]), plain(r["cpu_s_per_view"], "{:.3f}"),
                       plain(r["mvs_cpu_s_per_view"], "{:.3f}"),
                       plain(r["peak_rss_mb"], "{:.0f}"), count(r["samples"]),
                       count(r["fused_points"])] for r in scale]), ""]
        plot_scale(os.path.join(docs, "results_scale.png"), scale)
        md += ["![CPU time and memory against the number of views](results_scale.png)", ""]
        lo, hi = scale[0], scale[-1]
        readme.append([f"scale, {lo['views']}-{hi['views']} synthetic views",
                       f"{plain(lo['cpu_s_per_view'], '{:.2f}')}-"
                       f"{plain(hi['cpu_s_per_view'], '{:.2f}')} CPU-s per view, peak RSS "
                       f"{plain(lo['peak_rss_mb'], '{:.0f}')}-"
                       f"{plain(hi['peak_rss_mb'], '{:.0f}')} MB"])
    else:
        md += [state("scale"), ""]

    # --- live against offline -------------------------------------------------
    md += ["## Live against offline", ""]
    live_tsv = os.path.join(out, "live", "live.tsv")
    live = None if "live" in failed or not os.path.exists(live_tsv) else read_tsv(live_tsv)
    if live:
        md += [f"`bench/run_live.sh`: each scene (images {meta.get('scene_size', '')}, "
               "seed 101) reconstructed by `wild_mvs reconstruct` and, written as a bag "
               "(`wild_mvs to-bag`, one view per second, and one per 4 s where "
               "named: a slower robot, or a machine with cores to spare), played "
               "through `reconstruct_bag.launch` with default parameters; the offline "
               "tool also without the dataset's sparse points (own tracks: it computes "
               "its SIFT tracks from the images, as the depth node's tracker does). "
               "The depth maps the depth node published (its first revisions; its "
               "revisions 1: matched again once 2 later keyframes exist, checked "
               "against the maps its neighbours have then; its final revisions: "
               "checked against its neighbours' final matches, the offline "
               "consistency step) and the saved fused cloud, against the ground "
               "truth. Views = views with a depth map; CPU-s of the live run include "
               "ROS. First depth s: from an image to its keyframe's first depth view "
               "(median / max, the bag's clock, which runs on 5 s past the last "
               "view; a stream's first keyframe waits for the second); revised after: "
               "how many newer keyframes got their first depth view before a "
               "keyframe's revision 1 (its row) or final revision (median / max). "
               "A final revision waits for a full neighbourhood (10 other keyframes) "
               "and for its neighbours' final matches (40 s and more at 0.25 "
               "views/s); the fusion node holds a keyframe's earlier revisions "
               "for it while the depth node still sends.", ""]
        md += [table(["scene", "seed", "run", "views", "coverage", "within 1 %",
                      "off > 5 %", "F 1 cm", "F 5 cm", "CPU-s", "first depth s",
                      "revised after"],
                     [[r["scene"], r["seed"], r["run"], r["views"], r["coverage"],
                       r["in1%"], r["off>5%"], r["F@1cm"], r["F@5cm"], r["cpu_s"],
                       r.get("first_s", "-"), r.get("revised_after", "-")]
                      for r in live]), ""]
        by = {(r["scene"], r["run"]): r for r in live}
        cells = []
        for scene in dict.fromkeys(r["scene"] for r in live):
            o, f = by.get((scene, "offline")), by.get((scene, "live final revisions"))
            own = by.get((scene, "offline, own tracks"))
            if o and f:
                extra = (f"; own tracks {own['coverage']} / {own['in1%']}"
                         if own else "")
                cells.append(f"{scene} {f['coverage']} / {f['in1%']} "
                             f"(offline {o['coverage']} / {o['in1%']}{extra})")
        if cells:
            readme.append(["live depth node, final revisions: coverage / within 1 %",
                           "; ".join(cells)])
    else:
        md += [meta.get("live_note") or state("live"), ""]

    with open(os.path.join(docs, "RESULTS.md"), "w") as f:
        f.write("\n".join(md).rstrip() + "\n")

    # --- README block ----------------------------------------------------------
    readme_path = os.path.join(root, "README.md")
    text = open(readme_path).read()
    if BEGIN in text and END in text:
        block = [BEGIN, ""]
        if quick:
            block += ["*Quick setting (smaller sizes, one run): see the note in "
                      "docs/RESULTS.md.*", ""]
        block += [table(["benchmark", "today"], readme), "",
                  f"{meta['cores']} cores ({meta['cpu']}), `--threads {meta['threads']}`; "
                  "every table, the peers and the plots: "
                  "[docs/RESULTS.md](docs/RESULTS.md), produced by "
                  "`bash bench/run_all.sh`.", "", END]
        pre, rest = text.split(BEGIN, 1)
        post = rest.split(END, 1)[1]
        with open(readme_path, "w") as f:
            f.write(pre + "\n".join(block) + post)


if __name__ == "__main__":
    main()
