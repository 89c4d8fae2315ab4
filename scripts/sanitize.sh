#!/usr/bin/env bash
# Builds rlpbrt with AddressSanitizer and UndefinedBehaviorSanitizer (build-asan/) and runs
# the fast test label there (the long, statistical label is too slow under the sanitizers).
# Any sanitizer report fails the run.
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
cd "$build"
ctest -L fast --output-on-failure --timeout 600 -j "$(nproc)"
