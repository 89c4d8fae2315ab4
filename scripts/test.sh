#!/usr/bin/env bash
# Sets everything up, builds, and runs the whole test suite (CTest).
# Tests that need ../shared/scenes fail (not skip) when CI=true and it is missing.
set -euo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)
t0=$(date +%s)
bash "$here/scripts/setup.sh"
echo "test: setup and build took $(( $(date +%s) - t0 )) s"
cd "$here/build"
ctest --output-on-failure --timeout 1200 -j "$(nproc)" "$@"
