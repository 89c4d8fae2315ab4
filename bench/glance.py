#!/usr/bin/python3
"""The tables and plots of docs/BENCHMARKS.md's "results at a glance", from stored runs.

    bench/glance.py [--plots]
    bench/glance.py --study120      (the 120-s study's table, issue 30)

Reads the bench/curves.sh runs named below (each run twice, A and B with the configurations'
core order reversed), prints per scene and backend the relMSE ratio to plain path tracing at
equal time and the overhead per sample (one table), the break-even time and the guide's
memory (another) as markdown,
and with --plots writes docs/img/curves.png (relMSE against seconds, log-log, one panel per
scene, plain and hemi, both runs) and docs/img/equal-time.png (the ratios as bars). Plots
need Debian's python3-matplotlib (installed on request: run with /usr/bin/python3). Not part
of CI.
"""
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import curves_report as cr  # noqa: E402

HERE = os.path.dirname(os.path.abspath(__file__))
RESULTS = os.path.join(HERE, "results")
# backend -> (run A, run B) of `none` against that backend, 30 s of a core per render.
RUNS = {
    "hemi": ("curves-2026-12-03-s18-run2-A", "curves-2026-12-03-s18-run2-B"),
    "vdb": ("curves-2026-12-02-s10-vdb-A", "curves-2026-12-02-s10-vdb-B"),
}


def summary(run, config):
    """{scene: dict(ratio, break_even, overhead, mib)} of one run against its `none`."""
    out = {}
    for scene, configs in cr.load_runs(os.path.join(RESULTS, run)).items():
        if "none" not in configs or config not in configs:
            continue
        (base, bstats), (curve, stats) = configs["none"], configs[config]
        t_end = min(base[-1][0], curve[-1][0])
        out[scene.split("__")[0]] = dict(
            ratio=cr.interp(curve, t_end) / cr.interp(base, t_end),
            break_even=cr.break_even(curve, base),
            overhead=(stats["seconds"] / stats["spp"]) / (bstats["seconds"] / bstats["spp"]) - 1,
            mib=stats.get("guide_bytes", 0) / 2**20)
    return out


def table():
    """Prints two markdown tables: equal time (ratio, overhead) and break-even with memory."""
    data = {b: [summary(r, b) for r in runs] for b, runs in RUNS.items()}
    be = lambda v: "never" if v is None else "{:.2g}".format(v)
    columns = (
        ("relMSE ratio at 30 s | overhead/sample", lambda a, c: "{:.2f} / {:.2f} | {:+.0%} / {:+.0%}".format(
            a["ratio"], c["ratio"], a["overhead"], c["overhead"])),
        ("break-even s | guide MiB", lambda a, c: "{} / {} | {:.1f}".format(
            be(a["break_even"]), be(c["break_even"]), a["mib"])),
    )
    for head, cell in columns:
        print("| scene | " + " | ".join(
            " | ".join("{} {}".format(b, h) for h in head.split(" | ")) for b in RUNS) + " |")
        print("|---|" + "---:|---:|" * len(RUNS))
        for scene in sorted(data["hemi"][0]):
            cells = []
            for b in RUNS:
                a, c = data[b][0].get(scene), data[b][1].get(scene)
                cells.append(cell(a, c) if a and c else "- | -")
            print("| {} | {} |".format(scene, " | ".join(cells)))
        print()
    return data


def plots(data):
    try:
        import matplotlib
    except ImportError:
        sys.exit("plots need Debian's python3-matplotlib: sudo apt-get install "
                 "python3-matplotlib, then run with /usr/bin/python3")
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    img = os.path.join(HERE, "..", "docs", "img")
    os.makedirs(img, exist_ok=True)
    # Error against time, plain and hemi, both runs.
    a, b = (cr.load_runs(os.path.join(RESULTS, r)) for r in RUNS["hemi"])
    scenes = sorted(a)
    cols = 5
    rows = (len(scenes) + cols - 1) // cols
    fig, axes = plt.subplots(rows, cols, figsize=(2.6 * cols, 2.3 * rows), squeeze=False)
    for ax, scene in zip(axes.flat, scenes):
        for runs, style in ((a, "-"), (b, "--")):
            for config, colour in (("none", "0.45"), ("hemi", "tab:blue")):
                curve = runs.get(scene, {}).get(config, ([], {}))[0]
                if curve:
                    ax.loglog([t for t, _, _ in curve], [e for _, _, e in curve], style,
                              color=colour, lw=1.2,
                              label=(config if style == "-" else None))
        ax.set_title(scene.split("__")[0], fontsize=8)
        ax.tick_params(labelsize=6)
        ax.grid(True, which="both", alpha=0.3)
    axes.flat[0].legend(fontsize=7)
    for ax in axes[-1]:
        ax.set_xlabel("seconds (1 core)", fontsize=7)
    for row in axes:
        row[0].set_ylabel("relMSE", fontsize=7)
    fig.suptitle("Error against time: plain (none) and guided (hemi); solid run A, dashed run B",
                 fontsize=9)
    fig.tight_layout()
    fig.savefig(os.path.join(img, "curves.png"), dpi=72)
    # Ratios at equal time.
    scenes = sorted(data["hemi"][0], key=lambda s: data["hemi"][0][s]["ratio"])
    fig, ax = plt.subplots(figsize=(6.5, 3.6))
    height = 0.38
    for k, (backend, colour) in enumerate((("hemi", "tab:blue"), ("vdb", "tab:orange"))):
        ys = [i + (k - 0.5) * height for i in range(len(scenes))]
        vals = [((data[backend][0][s]["ratio"] * data[backend][1][s]["ratio"]) ** 0.5
                 if s in data[backend][0] and s in data[backend][1] else 0) for s in scenes]
        ax.barh(ys, vals, height, color=colour, label=backend)
    ax.axvline(1.0, color="k", lw=0.8)
    ax.set_yticks(range(len(scenes)))
    ax.set_yticklabels(scenes, fontsize=8)
    ax.set_xlabel("relMSE at equal time / plain's (below 1: guiding pays)", fontsize=8)
    ax.tick_params(labelsize=7)
    ax.legend(fontsize=8, loc="lower right")
    ax.set_title("Guided against plain path tracing at 30 s (geometric mean of runs A and B)",
                 fontsize=9)
    fig.tight_layout()
    fig.savefig(os.path.join(img, "equal-time.png"), dpi=72)


# The 120-s study (issue 30): hemi against none for 120 s of a core each, runs A and B.
STUDY_120 = ("study-120-2026-12-04-s22-A", "study-120-2026-12-04-s22-B")
SHARED = os.environ.get("RLPBRT_SHARED", os.path.join(HERE, "..", "..", "shared"))


def reference_error():
    """{scene: rough relMSE of pbrt-v3's reference itself}: pbrt-v3's own 64-spp error scaled
    by 64 / the reference's spp (1/N convergence; Sobol sampling converges faster on smooth
    pixels, so this overestimates where the light is simple)."""
    import csv
    out = {}
    with open(os.path.join(SHARED, "references", "manifest.tsv")) as f:
        for row in csv.DictReader(f, delimiter="\t"):
            out[row["id"].split("__")[0]] = (float(row["pbrt_64spp_relmse_trim"]) * 64 /
                                             float(row["ref_spp"]))
    # Sharpened with a long bdpt render; its noise as references/README.md estimates it.
    out["veach-bidir"] = 0.001
    return out


def study120():
    """Prints the 120-s study's table beside the 30-s ratios (RUNS["hemi"])."""
    long = [summary(r, "hemi") for r in STUDY_120]
    short = [summary(r, "hemi") for r in RUNS["hemi"]]
    plain = [{s: v for s, v in cr.load_runs(os.path.join(RESULTS, r)).items()}
             for r in STUDY_120]
    ref = reference_error()
    print("| scene | hemi / none at 30 s | hemi / none at 120 s | none relMSE at 120 s | "
          "reference's own error (rough) |")
    print("|---|---:|---:|---:|---:|")
    for scene in sorted(long[0]):
        p = []
        for run in plain:
            for key, configs in run.items():
                if key.split("__")[0] == scene:
                    p.append(configs["none"][0][-1][2])
        cell = lambda d: " / ".join("{:.2f}".format(x[scene]["ratio"]) if scene in x else "-"
                                    for x in d)
        print("| {} | {} | {} | {} | {:.2g} |".format(
            scene, cell(short), cell(long), " / ".join("{:.3g}".format(v) for v in p),
            ref.get(scene, float("nan"))))


if __name__ == "__main__":
    if "--study120" in sys.argv:
        study120()
        sys.exit()
    d = table()
    if "--plots" in sys.argv:
        plots(d)
