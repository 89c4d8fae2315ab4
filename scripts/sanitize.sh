#!/usr/bin/env bash
# Builds rlpbrt with AddressSanitizer and UndefinedBehaviorSanitizer (build-asan/) and runs
# the fast test label there (the long, statistical label is too slow under the sanitizers).
# Any sanitizer report fails the run.
# The fast tests run as one process per test binary, each binary split into $nproc shards
# (GoogleTest's GTEST_TOTAL_SHARDS), not one process per test as CTest starts them: a
# sanitized process costs about a second to start and end, and the label has a thousand
# tests. RLPBRT_SANITIZE_CTEST=1 runs them through CTest instead (one process per test).
set -euo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)
build=${1:-$here/build-asan}
bash "$here/scripts/setup.sh" >/dev/null  # packages (and the normal build)
cmake -S "$here" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DRLPBRT_SANITIZE=ON \
    -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1 -g1" >/dev/null
cmake --build "$build" --parallel "$(nproc)" --target rlpbrt rlpbrt_oiio rlpbrt-imgtool \
    rlpbrt_tests rlpbrt_image_tests
export ASAN_OPTIONS=detect_leaks=1:abort_on_error=1:strict_string_checks=1
export UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
export LSAN_OPTIONS=suppressions=$here/tests/lsan.supp
if [ "${RLPBRT_SANITIZE_CTEST:-0}" = 1 ]; then
    cd "$build"
    ctest -L fast --output-on-failure --timeout 600 -j "$(nproc)"
    exit
fi
# CTest runs the tests in the tests' build directory; so do the shards.
cd "$build/tests"
shards=$(nproc)
logs=$(mktemp -d)
trap 'rm -rf "$logs"' EXIT
status=0
for bin in rlpbrt_tests rlpbrt_image_tests; do
    pids=()
    for ((i = 0; i < shards; ++i)); do
        GTEST_TOTAL_SHARDS=$shards GTEST_SHARD_INDEX=$i timeout 1800 "./$bin" --gtest_brief=1 \
            > "$logs/$bin.$i.log" 2>&1 &
        pids+=($!)
    done
    for ((i = 0; i < shards; ++i)); do
        if wait "${pids[$i]}"; then
            tail -n 2 "$logs/$bin.$i.log"
        else
            status=1
            echo "sanitize: $bin shard $i of $shards FAILED; its log:" >&2
            cat "$logs/$bin.$i.log" >&2
        fi
    done
done
[ $status -eq 0 ] && echo "sanitize: every fast test passed under ASan and UBSan"
exit $status
