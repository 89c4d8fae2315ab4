#!/usr/bin/env bash
# A/B speed of two rlpbrt binaries (or two option sets) on one scene, robust to a shared VM:
#   bench/ab.sh BIN_A BIN_B SCENE [PAIRS] [SPP] -- [rlpbrt options...]
# Runs PAIRS (default 8) pairs: A and B render the same SCENE (a path, or a scene id of
# ../shared/references/manifest.tsv) at the same time, one thread each, pinned to cores 0 and 1,
# swapping the cores every pair, each for SPP samples per pixel (default 128). Prints each pair's
# ratio of render seconds B / A (and of mean path length, from --stats), then geometric means with
# 95% intervals (t distribution over the log ratios) of the path length, of the seconds per path
# vertex (what B's vertices cost against A's, apart from longer or shorter paths) and, last, of the
# seconds (the overhead per sample). Pairs, not sequential runs: the VM's speed drifts by up to 40%
# between minutes, but the two renders of a pair share it. A ratio's interval that contains 1 is no
# difference. Environment: OPTS_A / OPTS_B (extra options for one side), SHARED (default ../shared),
# SEED (default 3), SEQUENTIAL=1: each render alone with all cores (the renderer's default threads),
# A then B, B then A on alternate pairs: the time a user's render takes, serial work between passes
# included (a one-thread render has none).
set -euo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)
shared=${SHARED:-${RLPBRT_SHARED:-$here/../shared}}
usage="usage: $0 BIN_A BIN_B SCENE [PAIRS] [SPP] -- [options...]"
a=${1:?$usage}
b=${2:?$usage}
scene=${3:?$usage}
shift 3
pairs=8
spp=128
[[ $# -gt 0 && $1 != -- ]] && { pairs=$1; shift; }
[[ $# -gt 0 && $1 != -- ]] && { spp=$1; shift; }
[[ $# -gt 0 && $1 == -- ]] && shift
if [[ ! -f $scene ]]; then
    path=$(awk -F'\t' -v id="$scene" '$1 == id { print $2 }' "$shared/references/manifest.tsv")
    [[ -n $path ]] || { echo "$0: no scene file or manifest id '$scene'" >&2; exit 2; }
    scene=$shared/scenes/$path
fi
[[ $(nproc) -ge 2 ]] || { echo "$0: needs two cores" >&2; exit 2; }
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
run() {  # core binary tag extra-options
    local pin=(taskset -c "$1") threads=(--nthreads 1)
    [[ ${SEQUENTIAL:-0} == 1 ]] && pin=() threads=()
    # shellcheck disable=SC2086
    "${pin[@]}" "$2" "$scene" --spp "$spp" "${threads[@]}" --quiet --seed "${SEED:-3}" \
        -o "$tmp/$3.exr" --stats "$tmp/$3.json" "${@:5}" $4 >/dev/null 2>"$tmp/$3.log"
}
ratios=()
for ((i = 0; i < pairs; i++)); do
    ca=$((i % 2)); cb=$((1 - i % 2))
    if [[ ${SEQUENTIAL:-0} == 1 ]]; then
        order=(A B)
        ((i % 2 == 1)) && order=(B A)
        for side in "${order[@]}"; do
            if [[ $side == A ]]; then bin=$a opts=${OPTS_A:-}; else bin=$b opts=${OPTS_B:-}; fi
            run - "$bin" "$side" "$opts" "$@" || { cat "$tmp/$side.log" >&2; exit 1; }
        done
    else
        run "$ca" "$a" A "${OPTS_A:-}" "$@" &
        pa=$!
        run "$cb" "$b" B "${OPTS_B:-}" "$@" &
        pb=$!
        wait "$pa" || { cat "$tmp/A.log" >&2; exit 1; }
        wait "$pb" || { cat "$tmp/B.log" >&2; exit 1; }
    fi
    # Seconds and mean path length (surface vertices per path, --stats), B / A.
    read -r r v < <(/usr/bin/python3 -c 'import json,sys
a, b = (json.load(open(f)) for f in sys.argv[1:3])
la, lb = a["mean_path_length"], b["mean_path_length"]
print("%.4f %.4f" % (b["seconds"] / a["seconds"], lb / la if la > 0 and lb > 0 else 1.0))' \
        "$tmp/A.json" "$tmp/B.json")
    if [[ ${SEQUENTIAL:-0} == 1 ]]; then
        echo "pair $((i + 1)) (${order[0]} first): B / A = $r (path length $v)"
    else
        echo "pair $((i + 1)) (A on core $ca): B / A = $r (path length $v)"
    fi
    ratios+=("$r:$v")
done
# Geometric means with 95% intervals: path length, seconds per path vertex (seconds over path
# length: what a vertex of B costs against one of A, apart from B's paths being longer or
# shorter), and seconds (the overhead per sample; last, as before).
/usr/bin/python3 - "${ratios[@]}" <<'EOF'
import math, sys
pairs = [tuple(float(x) for x in a.split(":")) for a in sys.argv[1:]]
# Two-sided 95% t quantiles for n - 1 degrees of freedom (1..30; beyond: normal).
T = [12.71, 4.30, 3.18, 2.78, 2.57, 2.45, 2.36, 2.31, 2.26, 2.23, 2.20, 2.18, 2.16, 2.14,
     2.13, 2.12, 2.11, 2.10, 2.09, 2.09, 2.08, 2.07, 2.07, 2.06, 2.06, 2.06, 2.05, 2.05,
     2.05, 2.04]


def summary(label, values):
    logs = [math.log(x) for x in values]
    n = len(logs)
    mean = sum(logs) / n
    if n == 1:
        return "%s: %.4f (1 pair)" % (label, math.exp(mean))
    sd = math.sqrt(sum((x - mean) ** 2 for x in logs) / (n - 1))
    q = T[n - 2] if n - 2 < len(T) else 1.96
    half = q * sd / math.sqrt(n)
    return "%s: %.4f (95%%: %.4f .. %.4f, %d pairs)" % (
        label, math.exp(mean), math.exp(mean - half), math.exp(mean + half), n)


print(summary("B / A path length", [v for _, v in pairs]))
print(summary("B / A seconds per path vertex", [r / v for r, v in pairs]))
print(summary("B / A seconds", [r for r, _ in pairs]))
EOF
