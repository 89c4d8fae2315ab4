#!/usr/bin/python3
"""Equal-time ratios without the references' own noise, from renders of two or more seeds.

    bench/pair_error.py IMAGEDIR [--base none] [--manifest bench/study-scenes.tsv]

IMAGEDIR holds a bench/curves.sh run's images, named <scene-id>__<config>-s<seed>.exr (the
CONFIGS names end in -s1, -s2, ...: for example "none-s1=--guide,none,--seed,1"). For every
scene and configuration with at least two seeds, `rlpbrt-imgtool pair` compares each pair
of seeds: two renders of one estimator differ only by their own noise, so half their
weighted squared difference (pairRelMse, src/render/metrics.h) is one render's error without
the reference's, and a render's relmse_trim against the reference less it estimates the
reference's own error. Prints a markdown table per scene:

- the configuration's relMSE over --base's against the reference, per seed (what the
  benchmark tables report),
- the same ratio from the pairs' errors (no reference noise in either),
- the reference's own error as each configuration's renders see it, next to their error.

Both estimators must be unbiased (the reference tests check it). Heavy-tailed renders
(fireflies that neither seed drew) read low by the pairs, plain path tracing most, so the
pairs' ratio leans against the guided configuration there.
"""
import argparse
import glob
import itertools
import json
import os
import re
import subprocess
import sys

HERE = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def references(manifest, shared):
    """scene id -> reference image path, as bench/curves.sh finds them."""
    refs = {}
    with open(manifest) as f:
        header = f.readline().rstrip("\n").split("\t")
        for line in f:
            cols = dict(zip(header, line.rstrip("\n").split("\t")))
            own = cols.get("ref", "")
            refs[cols["id"]] = (os.path.join(HERE, own) if own else
                                os.path.join(shared, "references", cols["id"] + ".exr"))
    return refs


def pair(tool, a, b, ref):
    out = subprocess.run([tool, "pair", a, b, ref], capture_output=True, text=True, check=True)
    return json.loads(out.stdout)


def fmt(x):
    return "%.3g" % x if x == x else "-"


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("images")
    ap.add_argument("--base", default="none", help="the configuration the ratios divide by")
    ap.add_argument("--manifest", default=None)
    ap.add_argument("--shared", default=os.path.join(os.path.dirname(HERE), "shared"))
    ap.add_argument("--tool", default=os.path.join(HERE, "build", "rlpbrt-imgtool"))
    args = ap.parse_args()
    manifest = args.manifest or os.path.join(args.shared, "references", "manifest.tsv")
    refs = references(manifest, args.shared)

    runs = {}  # (scene, config) -> {seed: path}
    for path in sorted(glob.glob(os.path.join(args.images, "*.exr"))):
        m = re.match(r"(.+)__(.+)-s(\d+)\.exr$", os.path.basename(path))
        if m and m.group(1) in refs:
            runs.setdefault((m.group(1), m.group(2)), {})[int(m.group(3))] = path
    if not runs:
        sys.exit("%s: error: no images named <scene>__<config>-s<seed>.exr of a manifest scene"
                 % args.images)

    print("| scene | config | relMSE / %s against the reference, per seed | by pairs "
          "| pairs' relMSE | the reference's own error, as these renders see it |" % args.base)
    print("|---|---|---|---:|---:|---:|")
    for scene in sorted({s for s, _ in runs}):
        stats = {}
        for (s, config), seeds in runs.items():
            if s != scene or len(seeds) < 2:
                continue
            own, errs, referrs = {}, [], []  # each seed's relMSE, each pair's figures
            for i, j in itertools.combinations(sorted(seeds), 2):
                p = pair(args.tool, seeds[i], seeds[j], refs[scene])
                own.setdefault(i, p["relmse_a"])
                own.setdefault(j, p["relmse_b"])
                errs.append(p["pair_relmse"])
                referrs.append(p["reference_error"])
            stats[config] = (own, sum(errs) / len(errs), sum(referrs) / len(referrs))
        base = stats.get(args.base)
        for config in sorted(stats, key=lambda c: (c != args.base, c)):
            own, err, referr = stats[config]
            if base and config != args.base:
                per_seed = " / ".join(
                    "%.2f" % (own[k] / base[0][k]) for k in sorted(own) if k in base[0])
                by_pairs = "%.2f" % (err / base[1])
            else:
                per_seed, by_pairs = "-", "-"
            print("| %s | %s | %s | %s | %s | %s |" % (scene, config, per_seed, by_pairs,
                                                      fmt(err), fmt(referr)))


if __name__ == "__main__":
    main()
