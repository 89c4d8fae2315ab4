#!/usr/bin/env bash
# Sets everything up, builds, and shows what guiding buys: renders scenes/demo/door.pbrt (a
# room lit through a door ajar) for the same time plain (--guide none) and guided (the
# default, hemi), measures both against the bundled reference, and writes
#   out/demo.png           the guided render
#   out/demo-compare.png   plain and guided side by side, each with its error
# Usage: scripts/demo.sh [SECONDS per render, default 20] [rlpbrt options for both renders]
set -euo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)
secs=20
if [ $# -gt 0 ] && [[ $1 =~ ^[0-9]+([.][0-9]+)?$ ]]; then secs=$1; shift; fi
bash "$here/scripts/setup.sh"
bin=$here/build/rlpbrt
tool=$here/build/rlpbrt-imgtool
scene=$here/scenes/demo/door.pbrt
ref=$here/scenes/demo/door-ref.exr
out=$here/out
mkdir -p "$out"

# Renders one configuration; prints "spp relmse".
render() {
    local name=$1; shift
    "$bin" "$scene" --time "$secs" --quiet -o "$out/demo-$name.exr" --stats "$out/demo-$name.json" "$@"
    local spp rel
    spp=$(sed -n 's/^ *"spp": \([0-9]*\).*/\1/p' "$out/demo-$name.json")
    rel=$("$tool" compare "$out/demo-$name.exr" "$ref" | sed -n 's/.*"relmse_trim": \([^,]*\),.*/\1/p')
    echo "$spp $rel"
}
echo "demo: rendering $scene for $secs s plain, then $secs s guided ..."
read -r spp_plain rel_plain < <(render plain --guide none "$@")
read -r spp_guided rel_guided < <(render guided --guide hemi "$@")
if [ -z "${rel_plain:-}" ] || [ -z "${rel_guided:-}" ]; then
    echo "demo: a render or its comparison failed (messages above)" >&2
    exit 1
fi
"$tool" convert "$out/demo-guided.exr" "$out/demo.png"
ratio=$(awk -v a="$rel_plain" -v b="$rel_guided" 'BEGIN { printf "%.1f", a / b }')
fmt() { awk -v v="$1" 'BEGIN { printf "%.4f", v }'; }
"$tool" side-by-side "$out/demo-plain.exr" "$out/demo-guided.exr" "$out/demo-compare.png" \
    "PLAIN ${secs} S, $spp_plain SPP|RELMSE $(fmt "$rel_plain")" \
    "GUIDED ${secs} S, $spp_guided SPP|RELMSE $(fmt "$rel_guided")|${ratio}x LESS ERROR"
echo "demo: plain  $secs s, $spp_plain spp: relMSE $(fmt "$rel_plain") against the reference"
echo "demo: guided $secs s, $spp_guided spp: relMSE $(fmt "$rel_guided"), ${ratio}x less error at equal time"
echo "demo: wrote $out/demo.png (guided) and $out/demo-compare.png (plain | guided)"
