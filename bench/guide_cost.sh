#!/usr/bin/env bash
# Guiding's cost on every reference scene (or the given scene ids), from --stats
# (render/guide_clock.h): the guide's memory, the vertices that had a guide, the guide's
# time per such vertex, the updates between passes and their share of the render.
#   bench/guide_cost.sh [SPP] [scene-id ...]       (default 32 spp, every manifest scene)
# Each render runs alone with every core ($BACKENDS, default "hemi vdb"; extra rlpbrt
# options from $ARGS). Prints a Markdown table.
set -euo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)
shared=${SHARED:-${RLPBRT_SHARED:-$here/../shared}}
bin=${RLPBRT:-$here/build/rlpbrt}
spp=${1:-32}
[[ $# -gt 0 ]] && shift
want=" $* "
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
echo "# $(date -u +%Y-%m-%dT%H:%MZ), $(nproc) cores, $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | xargs), commit $(git -C "$here" rev-parse --short HEAD), $spp spp"
echo "| scene | backend | guide MiB | guided vertices per path | ns per guided vertex | end-pass s | guide share of render time | render s |"
echo "|---|---|---:|---:|---:|---:|---:|---:|"
tail -n +2 "$shared/references/manifest.tsv" | while IFS=$'\t' read -r id scene w h rspp rs rsec s64 rel64 bb64 media; do
    [ $# -gt 0 ] && [[ "$want" != *" $id "* ]] && continue
    for g in ${BACKENDS:-hemi vdb}; do
        # shellcheck disable=SC2086
        "$bin" "$shared/scenes/$scene" --spp "$spp" --guide "$g" ${ARGS:-} --quiet \
            -o "$tmp/out.exr" --stats "$tmp/s.json" > /dev/null 2>&1 || { echo "| $id | $g | failed |"; continue; }
        python3 - "$tmp/s.json" "${id%%__*}" "$g" <<'PY'
import json, sys
d = json.load(open(sys.argv[1]))
print(f"| {sys.argv[2]} | {sys.argv[3]} | {d['guide_bytes'] / 1048576:.1f} | "
      f"{d['guide_guided_vertices'] / max(1, d['paths']):.2f} | {d['guide_ns_per_guided_vertex']:.0f} | "
      f"{d['guide_end_pass_seconds']:.2f} | {100 * d['guide_time_share']:.0f}% | {d['seconds']:.1f} |")
PY
    done
done
