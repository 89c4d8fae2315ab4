#!/usr/bin/python3
"""docs/BENCHMARKS.md's "At a glance" tables from an every-scene study.

    bench/study_table.py RUN30 RUN120 [RUN30-OWN RUN120-OWN]     (the ratios)
    bench/study_table.py --cost RUN [RUN ...]                      (the guide's cost)

Each RUN is a bench/curves.sh output directory whose configurations are `none-sN` and
`def-sN` (plain and the defaults, two seeds) and which holds bench/pair_error.py's table as
pairs.md. Per scene: the default's error over plain's by pairs at both lengths, the same
per seed against the reference, the guided renders' samples over plain's, the error per
sample (pairs' relMSE x mean spp, default over plain) and the guide's verdicts read from
`guide_summary` in every default render's --stats. --cost: per scene the guide's memory,
guided vertices per camera path, ns per guided vertex, share of the time and end-pass
seconds of each default render.
"""
import collections
import glob
import json
import os
import re
import sys


def pair_rows(run):
    """scene -> {config: (ratio per seed, ratio by pairs, pairs' relMSE)} from pairs.md."""
    out = collections.defaultdict(dict)
    path = os.path.join(run, "pairs.md")
    if not os.path.exists(path):
        return out
    for line in open(path):
        c = [x.strip() for x in line.strip().strip("|").split("|")]
        if len(c) >= 5 and c[1] in ("none", "def"):
            out[c[0]][c[1]] = (c[2], c[3], c[4])
    return out


def stats(run):
    """scene -> {config: --stats json}."""
    out = collections.defaultdict(dict)
    for f in glob.glob(os.path.join(run, "*.json")):
        scene, cfg = os.path.basename(f)[:-5].rsplit("__", 1)
        out[scene][cfg] = json.load(open(f))
    return out


def verdict(j):
    s = j.get("guide_summary", "")
    m = re.search(r"judge [\d.]+: predicted .* at confidence [\d.]+, ([a-z ]+)", s)
    v = m.group(1) if m else "?"
    spots = re.search(r"spot judge [\d.]+: worth [\d.e+-]+, lobes (\w+)", s)
    return v + (", lobes " + spots.group(1) if v == "guiding" and spots else "")


def mean_spp(runs, prefix):
    v = [j["spp"] for k, j in runs.items() if k.startswith(prefix)]
    return sum(v) / len(v) if v else 0.0


def spp_ratio(runs):
    seeds = sorted({k.split("-s")[1] for k in runs})
    r = ["%.2f" % (runs["def-s" + s]["spp"] / runs["none-s" + s]["spp"])
         for s in seeds if "def-s" + s in runs and "none-s" + s in runs]
    return " / ".join(r) or "-"


def per_sample(pairs, runs):
    if "def" not in pairs or "none" not in pairs or not runs:
        return "-"
    d, n = float(pairs["def"][2]), float(pairs["none"][2])
    return "%.2f" % (d * mean_spp(runs, "def-") / (n * mean_spp(runs, "none-")))


def ratios(groups):
    print("| scene | **30 s** | **120 s** | 30 s against the reference (per seed) | 120 s against "
          "the reference | guided spp / plain's, 30 s | 120 s | error per sample, guided / "
          "plain (30 s; 120 s) | the guide's verdicts (every render) |")
    print("|---|---:|---:|---:|---:|---:|---:|---:|---|")
    rows = []
    for run30, run120 in groups:
        p30, p120, s30, s120 = pair_rows(run30), pair_rows(run120), stats(run30), stats(run120)
        for scene in s30:
            a = p30[scene].get("def", ("-", "-", "-"))
            b = p120[scene].get("def", ("-", "-", "-"))
            every = list(s30[scene].items()) + list(s120.get(scene, {}).items())
            verdicts = sorted({verdict(j) for k, j in every if k.startswith("def")})
            bold = lambda x: "**%s**" % x if x != "-" else x
            rows.append((float(a[1]) if a[1] != "-" else float("inf"),
                         "| %s | %s | %s | %s | %s | %s | %s | %s; %s | %s |" % (
                             scene.split("__")[0], bold(a[1]), bold(b[1]), a[0], b[0],
                             spp_ratio(s30[scene]), spp_ratio(s120.get(scene, {})),
                             per_sample(p30[scene], s30[scene]),
                             per_sample(p120[scene], s120.get(scene, {})), "; ".join(verdicts))))
    for _, row in sorted(rows):
        print(row)


def cost(runs):
    print("| scene | guide MiB | guided vertices per path | ns per guided vertex | guide share "
          "of render time | end-pass s |")
    print("|---|---:|---:|---:|---:|---:|")
    rows = collections.defaultdict(list)
    for run in runs:
        for scene, cfgs in stats(run).items():
            rows[scene] += [j for k, j in sorted(cfgs.items()) if k.startswith("def")]
    for scene, js in sorted(rows.items()):
        col = lambda f: " / ".join(f(j) for j in js)
        print("| %s | %s | %s | %s | %s | %s |" % (
            scene.split("__")[0],
            col(lambda j: "%.1f" % (j["guide_bytes"] / 2**20)),
            col(lambda j: "%.2f" % (j["guide_guided_vertices"] / j["paths"])),
            col(lambda j: "%.0f" % j["guide_ns_per_guided_vertex"]),
            col(lambda j: "%.0f%%" % (100 * j["guide_time_share"])),
            col(lambda j: "%.2f" % j["guide_end_pass_seconds"])))


def main(argv):
    if argv and argv[0] == "--cost":
        cost(argv[1:])
    elif len(argv) in (2, 4):
        ratios([(argv[0], argv[1])] + ([(argv[2], argv[3])] if len(argv) == 4 else []))
    else:
        sys.exit(__doc__)


if __name__ == "__main__":
    main(sys.argv[1:])
