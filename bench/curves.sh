#!/usr/bin/env bash
# Error-versus-time curves per scene and guiding configuration (the speed/accuracy study).
#   bench/curves.sh SECONDS OUTDIR [scene-id ...]      (default: every manifest scene)
# Each configuration of a scene renders once for SECONDS with --curve against pbrt-v3's
# reference, so one run gives relMSE at every pass (the whole ladder of time budgets). The
# configurations of one scene run at the same time, one thread each, so that they share
# whatever else the machine is doing; compare them with each other, not across scenes run
# at different times. SEQUENTIAL=1 instead renders the configurations of a scene one after
# another, each with every core (--nthreads 0): a user's render, each alone on the machine
# (its caches and memory bandwidth unshared). PIN=1 pins the k-th configuration to core
# k mod nproc (a VM's cores can run at different speeds: run twice with the order reversed
# and compare both). Configurations: $CONFIGS (space-separated NAME=ARGS entries, ARGS with
# commas for spaces), default none, hemi, vdb and one variation of each main parameter.
# Writes OUTDIR/<scene>__<config>.{csv,json,log} and the images, <scene>__<config>.exr, to
# $IMAGES (default bench/out/<OUTDIR's name>, ignored by git: images stay out of the tracked
# tree); bench/curves_report.py summarises them. MANIFEST: another table of scenes with the
# manifest's columns (default ../shared/references/manifest.tsv); a row with a 12th column,
# the reference's path, is one of our own scenes (bench/study-scenes.tsv): its scene and
# reference paths are relative to the repository.
set -euo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)
shared=${SHARED:-${RLPBRT_SHARED:-$here/../shared}}
bin=${RLPBRT:-$here/build/rlpbrt}
secs=${1:?usage: $0 SECONDS OUTDIR [scene-id ...]}
out=${2:?usage: $0 SECONDS OUTDIR [scene-id ...]}
shift 2
images=${IMAGES:-$here/bench/out/$(basename "$out")}
mkdir -p "$out" "$images"
want=" $* "
# The backends and their main parameters: strata, points / voxel size, mix.
default="none=--guide,none hemi=--guide,hemi vdb=--guide,vdb"
default="$default hemi-strata4x4=--guide,hemi,--guide-param,strata=4x4"
default="$default hemi-points32768=--guide,hemi,--guide-param,points=32768"
default="$default vdb-voxel32=--guide,vdb,--guide-param,voxel=32"
default="$default hemi-mix0.25=--guide,hemi,--guide-param,mix=0.25"
default="$default hemi-mix0.75=--guide,hemi,--guide-param,mix=0.75"
configs=${CONFIGS:-$default}
sequential=${SEQUENTIAL:-0}
threads=1
[ "$sequential" = 1 ] && threads=0
{
    echo "date: $(date -u +%Y-%m-%dT%H:%MZ)"
    echo "machine: $(nproc) cores, $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | xargs)"
    echo "seconds: $secs"
    echo "configs: $configs"
    echo "sequential: $sequential (threads per render: $threads, 0 = all); pinned: ${PIN:-0}"
    echo "commit: $(git -C "$here" rev-parse --short HEAD 2>/dev/null || echo unknown)"
    echo "images: $images"
} > "$out/run.txt"

manifest=${MANIFEST:-$shared/references/manifest.tsv}
tail -n +2 "$manifest" | while IFS=$'\t' read -r id scene w h rspp rs rsec s64 rel64 bb64 media ownref; do
    [ $# -gt 0 ] && [[ "$want" != *" $id "* ]] && continue
    scenefile=$shared/scenes/$scene
    ref=$shared/references/$id.exr
    if [ -n "${ownref:-}" ]; then scenefile=$here/$scene; ref=$here/$ownref; fi
    pids=()
    k=0
    for cfg in $configs; do
        name=${cfg%%=*}
        args=${cfg#*=}
        # shellcheck disable=SC2086
        pin=()
        [ "${PIN:-0}" = 1 ] && pin=(taskset -c $((k % $(nproc))))
        k=$((k + 1))
        "${pin[@]}" "$bin" "$scenefile" --time "$secs" --nthreads "$threads" --quiet ${args//,/ } \
            --ref "$ref" --curve "$out/${id}__$name.csv" \
            --stats "$out/${id}__$name.json" -o "$images/${id}__$name.exr" \
            > /dev/null 2> "$out/${id}__$name.log" &
        if [ "$sequential" = 1 ]; then
            wait "$!" || echo "warning: $id $name failed (see $out/${id}__$name.log)" >&2
        else
            pids+=($!)
        fi
    done
    for p in "${pids[@]+"${pids[@]}"}"; do wait "$p" || echo "warning: a run of $id failed (see $out/${id}__*.log)" >&2; done
    echo "$id done" >&2
done
