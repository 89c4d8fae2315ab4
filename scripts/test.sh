#!/usr/bin/env bash
# Sets everything up, builds, and runs the whole test suite (CTest); extra arguments go to
# ctest (e.g. -R Parser). The last lines say how many tests were skipped and why.
# Tests that need the shared test data (pbrt-v3 scenes and references, README.md "Test
# scenes") skip when it is missing, and fail when CI=true. Its place: RLPBRT_SHARED, else the
# CMake cache variable RLPBRT_SHARED_DIR (default ../shared beside the checkout).
set -euo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)
t0=$(date +%s)
bash "$here/scripts/setup.sh"
echo "test: setup and build took $(( $(date +%s) - t0 )) s"
cd "$here/build"
log=$(mktemp)
trap 'rm -f "$log"' EXIT
rc=0
ctest --output-on-failure --timeout 1200 -j "$(nproc)" "$@" 2>&1 | tee "$log" || rc=$?

# The skipped tests: CTest lists them as "<n> - <name> (Skipped)" under "did not run".
skipped=$(grep -E '^[[:space:]]*[0-9]+ - .* \(Skipped\)$' "$log" | sed -E 's/^[[:space:]]*[0-9]+ - //; s/ \(Skipped\)$//' || true)
count=0
[ -n "$skipped" ] && count=$(printf '%s\n' "$skipped" | wc -l)
shared=${RLPBRT_SHARED:-}
[ -z "$shared" ] && shared=$(sed -n 's/^RLPBRT_SHARED_DIR:[A-Z]*=//p' CMakeCache.txt)
echo
if [ "$count" -eq 0 ]; then
    echo "test: no test skipped (shared test data: $shared)"
elif [ ! -f "$shared/references/manifest.tsv" ]; then
    echo "test: $count tests skipped: they need the shared test data (pbrt-v3 scenes and"
    echo "test: reference images), which is not at $shared. README.md, \"Test scenes\", says"
    echo "test: how to get it; then run RLPBRT_SHARED=/path/to/it bash scripts/test.sh"
else
    echo "test: $count tests skipped (ctest -R NAME -V prints the reason):"
    printf '%s\n' "$skipped" | sed 's/^/test:   /'
fi
exit "$rc"
