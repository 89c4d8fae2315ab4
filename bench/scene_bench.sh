#!/usr/bin/env bash
# Scripted benchmarks against pbrt-v3's figures in ../shared/references/manifest.tsv.
#   bench/scene_bench.sh parse   parse+build of conference-room (8x8 image, 1 spp, 1 thread),
#                                the issue's comparison with pbrt-v3's ~1.5 s
#   bench/scene_bench.sh render  every manifest scene at 64 spp with 2 threads, --guide none:
#                                wall time against pbrt-v3's 64-spp wall time (both include
#                                parsing)
# Prints a markdown table; runs each measurement REPEAT times (default 3) and keeps the median.
set -euo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)
shared=${SHARED:-${RLPBRT_SHARED:-$here/../shared}}
bin=${RLPBRT:-$here/build/rlpbrt}
repeat=${REPEAT:-3}
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT

median() { sort -g | awk '{a[NR]=$1} END {print a[int((NR+1)/2)]}'; }
wall() {  # wall seconds of a command
    local s e
    s=$(date +%s.%N); "$@" > /dev/null 2>&1; e=$(date +%s.%N)
    echo "$e - $s" | bc -l
}

case "${1:-render}" in
parse)
    scene=$tmp/conference_8x8.pbrt
    sed -e 's/^Film .*/Film "image" "integer xresolution" [8] "integer yresolution" [8]/' \
        -e 's/^Sampler .*/Sampler "sobol" "integer pixelsamples" [1]/' \
        -e "s|^Include \"conference_room-world.pbrt\"|Include \"$shared/scenes/conference-room/conference_room-world.pbrt\"|" \
        "$shared/scenes/conference-room/conference_room.small.pbrt" > "$scene"
    t=$(for i in $(seq "$repeat"); do wall "$bin" "$scene" --guide none --nthreads 1 -o "$tmp/o.exr" --quiet; done | median)
    p=$("$bin" --parse-only "$scene" --nthreads 1 | grep -oP 'parse: \K[0-9.]+ s, build: [0-9.]+')
    printf "| conference-room 8x8, 1 spp, 1 thread | %.3f s | 1.5 s | %.1fx | %s s |\n" "$t" "$(echo "1.5 / $t" | bc -l)" "$p"
    ;;
render)
    echo "| scene | rlpbrt 64 spp (s) | pbrt-v3 64 spp (s) | speed-up |"
    echo "|---|---:|---:|---:|"
    tail -n +2 "$shared/references/manifest.tsv" | while IFS=$'\t' read -r id scene w h rspp rs rsec s64 rel64 bb64 media; do
        [ "$media" = "1" ] && [ "${MEDIA:-1}" = "0" ] && continue  # MEDIA=0: surface scenes only
        t=$(for i in $(seq "$repeat"); do wall "$bin" "$shared/scenes/$scene" --guide none --spp 64 --nthreads 2 -o "$tmp/o.exr" --quiet; done | median)
        printf '| %s | %.2f | %.2f | %.2fx |\n' "$id" "$t" "$s64" "$(echo "$s64 / $t" | bc -l)"
    done
    ;;
*) echo "usage: $0 parse|render" >&2; exit 2 ;;
esac
