#!/usr/bin/env bash
# The guide's overhead per sample on every reference scene (or the given scene ids), at a
# fixed spp, split into path length and time per path vertex:
#   bench/overhead.sh BIN [PAIRS] [SPP] [scene-id ...]
# For each scene runs bench/ab.sh BIN BIN SCENE PAIRS SPP with A = --guide none and
# B = --guide hemi (override with OPTS_A / OPTS_B; SEQUENTIAL=1 as in ab.sh) and prints one
# Markdown table row: B / A path length, seconds per path vertex and seconds per sample, each
# a geometric mean over the pairs with its 95% interval. Defaults: 4 pairs, 64 spp, every
# scene of ../shared/references/manifest.tsv.
set -euo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)
shared=${SHARED:-${RLPBRT_SHARED:-$here/../shared}}
bin=${1:?usage: $0 BIN [PAIRS] [SPP] [scene-id ...]}
shift
pairs=${1:-4}
[[ $# -gt 0 ]] && shift
spp=${1:-64}
[[ $# -gt 0 ]] && shift
ids=("$@")
if [[ ${#ids[@]} -eq 0 ]]; then
    mapfile -t ids < <(awk -F'\t' 'NR > 1 { print $1 }' "$shared/references/manifest.tsv")
fi
export OPTS_A=${OPTS_A:---guide none} OPTS_B=${OPTS_B:---guide hemi}
echo "# $(date -u +%Y-%m-%dT%H:%MZ), $(nproc) cores, $pairs pairs at $spp spp;" \
    "A: $OPTS_A; B: $OPTS_B; sequential: ${SEQUENTIAL:-0}"
echo "| scene | path length B / A | seconds per path vertex | seconds per sample |"
echo "|---|---:|---:|---:|"
for id in "${ids[@]}"; do
    out=$("$here/bench/ab.sh" "$bin" "$bin" "$id" "$pairs" "$spp")
    field() {  # the summary line with this label, as "mean (low .. high)"
        sed -n "s/^B \/ A $1: \([0-9.]*\) (95%: \([0-9.]*\) \.\. \([0-9.]*\),.*/\1 (\2 .. \3)/p;
                s/^B \/ A $1: \([0-9.]*\) (1 pair)/\1/p" <<<"$out"
    }
    echo "| ${id%%__*} | $(field 'path length') | $(field 'seconds per path vertex') |" \
        "$(field 'seconds') |"
done
