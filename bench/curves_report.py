#!/usr/bin/python3
"""Summarises a bench/curves.sh run: a markdown table and (with matplotlib) plots.

    bench/curves_report.py OUTDIR [--plots]

Per scene and configuration: relMSE at the common end time (the shortest run's last pass,
log-log interpolation of each curve), its ratio to `none`, the break-even time (from when on
the configuration's curve stays below none's), the overhead per sample (seconds per spp
relative to none) and per path vertex (the same divided by the mean path lengths' ratio:
what a vertex costs, apart from paths that grow or shrink), the overhead at plain path
length (the overhead per sample divided by max(1, path length / none's): per vertex where
the configuration's paths are longer than none's, per sample where they are not, so that
longer paths that carry light are not charged as the guide's cost; docs/BENCHMARKS_HISTORY.md,
session 18), the zero-contribution fraction, mean path length and guide memory.
With --plots: OUTDIR/curves.png (relMSE against seconds, log-log, one panel per scene) and
OUTDIR/images.png (the final images side by side with the reference, all at equal time;
needs build/rlpbrt-imgtool to convert EXR to PNG; the images are read from $IMAGES, default
bench/out/<OUTDIR's name>, where bench/curves.sh writes them).
"""
import csv
import glob
import json
import math
import os
import subprocess
import sys


def read_curve(path):
    rows = []
    with open(path) as f:
        for r in csv.DictReader(f):
            t, e = float(r["seconds"]), float(r["relmse"])
            if t > 0 and e > 0 and math.isfinite(e):
                rows.append((t, int(r["spp"]), e))
    return rows


def interp(curve, t):
    """relMSE at time t, linear in log-log between passes; None outside the curve."""
    if not curve or t < curve[0][0] or t > curve[-1][0]:
        return None
    for (t0, _, e0), (t1, _, e1) in zip(curve, curve[1:]):
        if t0 <= t <= t1:
            if t1 == t0:
                return e1
            a = (math.log(t) - math.log(t0)) / (math.log(t1) - math.log(t0))
            return math.exp((1 - a) * math.log(e0) + a * math.log(e1))
    return curve[-1][2]


def break_even(curve, base):
    """First time from which curve stays at or below base (on base's pass times)."""
    times = [t for t, _, _ in base if curve and curve[0][0] <= t <= curve[-1][0]]
    result = None
    for t in times:
        e, b = interp(curve, t), interp(base, t)
        if e is None or b is None:
            continue
        if e <= b:
            if result is None:
                result = t
        else:
            result = None
    return result


def load_runs(out):
    """{scene id: {config: (curve, stats)}} of a bench/curves.sh run's OUTDIR."""
    runs = {}
    for path in sorted(glob.glob(os.path.join(out, "*__*.csv"))):
        stem = os.path.basename(path)[:-4]
        scene, config = stem.rsplit("__", 1)
        stats = {}
        if os.path.exists(path[:-4] + ".json"):
            with open(path[:-4] + ".json") as f:
                stats = json.load(f)
        runs.setdefault(scene, {})[config] = (read_curve(path), stats)
    return runs


def main():
    out = sys.argv[1]
    plots = "--plots" in sys.argv
    runs = load_runs(out)
    print("| scene | config | spp | relMSE at equal time | ratio to none | break-even s "
          "| overhead/sample | overhead/vertex | overhead at plain path length "
          "| zero-contribution | mean path length | guide MiB |")
    print("|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|")
    for scene, configs in runs.items():
        curves = [c for c, _ in configs.values() if c]
        if not curves:
            continue
        t_end = min(c[-1][0] for c in curves)
        base_curve, base_stats = configs.get("none", ([], {}))
        base_e = interp(base_curve, t_end) if base_curve else None
        base_sps = (base_stats["seconds"] / base_stats["spp"]
                    if base_stats.get("spp") else None)
        base_len = base_stats.get("mean_path_length")
        order = sorted(configs, key=lambda k: (k != "none", k))
        for config in order:
            curve, st = configs[config]
            e = interp(curve, t_end)
            ratio = e / base_e if e and base_e else None
            be = break_even(curve, base_curve) if config != "none" and base_curve else None
            sps = st["seconds"] / st["spp"] if st.get("spp") else None
            over = sps / base_sps - 1 if sps and base_sps else None
            length = st.get("mean_path_length")
            over_v = ((sps / length) / (base_sps / base_len) - 1
                      if sps and base_sps and length and base_len else None)
            over_p = ((1 + over) / max(1.0, length / base_len) - 1
                      if over is not None and length and base_len else None)
            fmt = lambda v, f: ("-" if v is None else f.format(v))
            print("| {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} |".format(
                scene.split("__")[0], config, st.get("spp", "-"), fmt(e, "{:.4g}"),
                fmt(ratio, "{:.2f}"),
                ("never" if config != "none" and be is None and base_curve else fmt(be, "{:.2g}")),
                fmt(over, "{:+.0%}"), fmt(over_v, "{:+.0%}"), fmt(over_p, "{:+.0%}"),
                fmt(st.get("zero_contribution_fraction"), "{:.3f}"),
                fmt(st.get("mean_path_length"), "{:.2f}"),
                fmt(st.get("guide_bytes", 0) / 2**20 if st else None, "{:.1f}")))
        print("| | equal time: {:.1f} s | | | | | | | | | | |".format(t_end))
    if not plots:
        return
    try:
        import matplotlib
    except ImportError:
        sys.exit("plots need Debian's python3-matplotlib (run with /usr/bin/python3)")
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    scenes = list(runs)
    cols = 3
    rows = (len(scenes) + cols - 1) // cols
    fig, axes = plt.subplots(rows, cols, figsize=(5 * cols, 3.6 * rows), squeeze=False)
    for ax, scene in zip(axes.flat, scenes):
        for config in sorted(runs[scene], key=lambda k: (k != "none", k)):
            curve = runs[scene][config][0]
            if curve:
                ax.loglog([t for t, _, _ in curve], [e for _, _, e in curve], label=config,
                          lw=1.5 if config in ("none", "hemi", "vdb") else 0.8)
        ax.set_title(scene.split("__")[0], fontsize=10)
        ax.set_xlabel("seconds (1 thread)")
        ax.set_ylabel("relMSE")
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=7)
    for ax in list(axes.flat)[len(scenes):]:
        ax.axis("off")
    fig.tight_layout()
    fig.savefig(os.path.join(out, "curves.png"), dpi=90)
    # Final images at equal time, next to the reference.
    here = os.path.dirname(os.path.abspath(__file__))
    tool = os.environ.get("IMGTOOL", os.path.join(here, "..", "build", "rlpbrt-imgtool"))
    shared = os.environ.get("SHARED", os.environ.get("RLPBRT_SHARED",
                                                     os.path.join(here, "..", "..", "shared")))
    images = os.environ.get("IMAGES", os.path.join(here, "out",
                                                   os.path.basename(os.path.normpath(out))))
    os.makedirs(images, exist_ok=True)
    configs = ["reference"] + sorted({c for s in runs.values() for c in s},
                                     key=lambda k: (k != "none", k))
    fig, axes = plt.subplots(len(scenes), len(configs),
                             figsize=(2.2 * len(configs), 2.0 * len(scenes)), squeeze=False)
    for i, scene in enumerate(scenes):
        for j, config in enumerate(configs):
            ax = axes[i][j]
            ax.axis("off")
            src = (os.path.join(shared, "references", scene + ".exr") if config == "reference"
                   else os.path.join(images, "{}__{}.exr".format(scene, config)))
            png = os.path.join(images, "{}__{}.png".format(scene, config))
            if not os.path.exists(src):
                continue
            subprocess.run([tool, "convert", src, png], check=False,
                           stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
            if os.path.exists(png):
                ax.imshow(plt.imread(png))
            if i == 0:
                ax.set_title(config, fontsize=8)
            if j == 0:
                ax.text(-0.05, 0.5, scene.split("__")[0], transform=ax.transAxes,
                        rotation=90, va="center", ha="right", fontsize=7)
    fig.tight_layout()
    fig.savefig(os.path.join(out, "images.png"), dpi=90)


if __name__ == "__main__":
    main()
