#!/usr/bin/env bash
# Sets everything up, builds, and renders the bundled demo scene to out/demo.png (and .exr).
set -euo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)
bash "$here/scripts/setup.sh"
mkdir -p "$here/out"
"$here/build/rlpbrt" "$here/scenes/demo/demo.pbrt" --outfile "$here/out/demo.exr" "$@"
"$here/build/rlpbrt-imgtool" convert "$here/out/demo.exr" "$here/out/demo.png"
echo "demo: wrote $here/out/demo.exr and $here/out/demo.png"
