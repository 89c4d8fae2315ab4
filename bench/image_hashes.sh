#!/usr/bin/env bash
# Proof that a refactoring changed nothing: renders every scene of the references' manifests
# with every guiding backend at 8 spp, seed 1, and prints one line per render: the scene id,
# the backend and the SHA-256 of the image's pixels (PFM: raw floats, no metadata).
#   bench/image_hashes.sh > before.txt; (change); bench/image_hashes.sh | diff before.txt -
#   bench/image_hashes.sh --check FILE    # the same, and exit 1 on any difference
# Renders are deterministic for a seed whatever the thread count (tiles merge in a fixed
# order), so the hashes are bit-for-bit. Images go to out/hashes/ (ignored by git).
# The training schemes other than the default are covered on a few scenes (EXTRA_SCENES) with
# the configurations EXTRA (backend,key=value,...: Eq. 1's targets, the learned selection,
# pbrt-v3's roulette, independent passes).
# SHARED (default ../shared beside the checkout), RLPBRT (the binary), SPP (default 8),
# GUIDES (default "none hemi vdb"), EXTRA, EXTRA_SCENES.
set -euo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)
shared=${SHARED:-$here/../shared}
bin=${RLPBRT:-$here/build/rlpbrt}
spp=${SPP:-8}
guides=${GUIDES:-none hemi vdb}
extra=${EXTRA:-hemi,target=sum hemi,target=sample hemi,mix=learn hemi,rr=pbrt,samples=independent vdb,target=sample,mix=learn vdb,mix=1}
extraScenes=" ${EXTRA_SCENES:-cornell-box__scene veach-bidir__bidir cloud__cloud volume-boundary__boundary} "
check=""
if [ "${1:-}" = "--check" ]; then check=${2:?usage: $0 [--check FILE]}; fi
out=$here/out/hashes
mkdir -p "$out"
result=$(mktemp)
trap 'rm -f "$result"' EXIT
for manifest in "$shared/references/manifest.tsv" "$shared/references/features/manifest.tsv"; do
    [ -f "$manifest" ] || continue
    tail -n +2 "$manifest" | while IFS=$'\t' read -r id scene _; do
        [ -f "$shared/scenes/$scene" ] || continue
        configs=$guides
        [[ "$extraScenes" == *" $id "* ]] && configs="$configs $extra"
        for g in $configs; do
            IFS=, read -r -a parts <<< "$g"
            args=(--guide "${parts[0]}")
            for kv in "${parts[@]:1}"; do args+=(--guide-param "$kv"); done
            img="$out/${id}__$g.pfm"
            if "$bin" "$shared/scenes/$scene" "${args[@]}" --spp "$spp" --seed 1 -q -o "$img" \
                2>/dev/null; then
                echo "$id $g $(sha256sum "$img" | cut -c1-16)"
            else
                echo "$id $g failed"
            fi
        done
    done
done | tee "$result"
if [ -n "$check" ]; then
    if diff "$check" "$result" >&2; then
        echo "image_hashes: identical to $check" >&2
    else
        echo "image_hashes: DIFFERENT from $check" >&2
        exit 1
    fi
fi
