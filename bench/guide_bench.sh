#!/usr/bin/env bash
# Equal-time comparison of guiding backends against plain path tracing.
#   bench/guide_bench.sh SECONDS [scene-id ...]     (default: every surface scene)
# For each scene of ../shared/references/manifest.tsv: renders with --time SECONDS for
# each backend of $BACKENDS (default "none hemi"; e.g. BACKENDS="none hemi vdb") (extra
# rlpbrt options from $ARGS, e.g. ARGS="--guide-param mix=0.3"), and prints spp, relMSE against pbrt-v3's reference, the ratio hemi/none,
# zero-contribution fraction, mean path length and guide memory, as a markdown table.
set -euo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)
shared=${SHARED:-${RLPBRT_SHARED:-$here/../shared}}
bin=${RLPBRT:-$here/build/rlpbrt}
tool=${IMGTOOL:-$here/build/rlpbrt-imgtool}
secs=${1:?usage: $0 SECONDS [scene-id ...]}; shift
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
want=" $* "

echo "| scene | backend | spp | relMSE | ratio to none | zero-contribution | mean path length | guide MiB |"
echo "|---|---|---:|---:|---:|---:|---:|---:|"
tail -n +2 "$shared/references/manifest.tsv" | while IFS=$'\t' read -r id scene w h rspp rs rsec s64 rel64 bb64 media; do
    [ "$media" = "1" ] && continue
    [ $# -gt 0 ] && [[ "$want" != *" $id "* ]] && continue
    base=""
    for g in ${BACKENDS:-none hemi}; do
        # shellcheck disable=SC2086
        "$bin" "$shared/scenes/$scene" --time "$secs" --guide "$g" ${ARGS:-} --quiet \
            -o "$tmp/$g.exr" --stats "$tmp/$g.json" > /dev/null 2>&1
        rel=$("$tool" compare "$tmp/$g.exr" "$shared/references/$id.exr" | grep -oP '"relmse_trim": \K[0-9.e+-]+')
        read -r spp zero len mib < <(python3 -c "import json;d=json.load(open('$tmp/$g.json'));print(d['spp'],round(d['zero_contribution_fraction'],3),round(d['mean_path_length'],2),round(d['guide_bytes']/1048576,1))")
        [ "$g" = none ] && base=$rel
        ratio=$(python3 -c "print(round($rel/$base,3))")
        echo "| $id | $g | $spp | $rel | $ratio | $zero | $len | $mib |"
    done
done
