#!/usr/bin/env bash
# Error per sample: each configuration renders each scene at a fixed sample count, with each
# seed, alone on the machine with every core, and is compared with pbrt-v3's reference.
#   bench/persample.sh SPP OUTDIR scene-id...
# Configurations: $CONFIGS (space-separated NAME=ARGS entries, ARGS with commas for spaces, as
# bench/curves.sh takes them); seeds: $SEEDS (default "1 2"). Appends one line per render to
# OUTDIR/results.tsv: scene id, configuration, seed, wall seconds (the whole process), relMSE
# (relmse_trim of `rlpbrt-imgtool compare`). The images go to OUTDIR too: keep it out of git.
# RLPBRT: the binary (default build/rlpbrt); SHARED: the shared data (default ../shared).
set -euo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)
shared=${SHARED:-${RLPBRT_SHARED:-$here/../shared}}
bin=${RLPBRT:-$here/build/rlpbrt}
imgtool=$(dirname "$bin")/rlpbrt-imgtool
[[ -x $imgtool ]] || imgtool=$here/build/rlpbrt-imgtool
usage="usage: $0 SPP OUTDIR scene-id..."
spp=${1:?$usage}
out=${2:?$usage}
shift 2
[[ $# -gt 0 ]] || { echo "$usage" >&2; exit 2; }
: "${CONFIGS:?set CONFIGS, e.g. CONFIGS=\"none=--guide,none hemi=--guide,hemi\"}"
mkdir -p "$out"
for id in "$@"; do
    scene=$(awk -F'\t' -v id="$id" '$1 == id { print $2 }' "$shared/references/manifest.tsv")
    [[ -n $scene ]] || { echo "$0: no scene $id in the manifest" >&2; exit 2; }
    for seed in ${SEEDS:-1 2}; do
        for c in $CONFIGS; do
            name=${c%%=*}
            args=${c#*=}
            img=$out/$id-$name-s$seed.exr
            t0=$(date +%s.%N)
            # shellcheck disable=SC2086
            "$bin" "$shared/scenes/$scene" --spp "$spp" -q --seed "$seed" ${args//,/ } -o "$img"
            t1=$(date +%s.%N)
            err=$("$imgtool" compare "$img" "$shared/references/$id.exr" |
                sed -n 's/.*"relmse_trim": *\([^,}]*\).*/\1/p')
            printf '%s\t%s\t%s\t%.2f\t%s\n' "$id" "$name" "$seed" "$(echo "$t1 - $t0" | bc)" \
                "$err" | tee -a "$out/results.tsv"
        done
    done
done
