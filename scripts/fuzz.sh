#!/usr/bin/env bash
# Builds the libFuzzer targets of fuzz/ with clang (ASan + UBSan) and runs each for SECONDS
# (default 60). Fails if any target crashes, leaks, times out on one input or runs out of
# memory; the reproducer is left in the run directory and its path printed.
# Usage: scripts/fuzz.sh [SECONDS] [TARGET...]     (targets: fuzz_parser fuzz_ply fuzz_spd)
# Environment: RLPBRT_FUZZ_BUILD (build dir, default build-fuzz), RLPBRT_FUZZ_JOBS (parallel
# fuzzing processes per target, default 1), RLPBRT_FUZZ_WORK (run directory, default
# $RLPBRT_FUZZ_BUILD/run).
set -euo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)
seconds=${1:-60}
shift || true
targets=("$@")
[ ${#targets[@]} -gt 0 ] || targets=(fuzz_parser fuzz_ply fuzz_spd)
build=${RLPBRT_FUZZ_BUILD:-$here/build-fuzz}
work=${RLPBRT_FUZZ_WORK:-$build/run}
jobs=${RLPBRT_FUZZ_JOBS:-1}

cxx=${CXX:-}
if [ -z "$cxx" ] || ! "$cxx" --version 2>/dev/null | grep -q clang; then
  cxx=$(command -v clang++ || command -v clang++-14 || true)
fi
[ -n "$cxx" ] || { echo "fuzz: clang++ not found (scripts/setup.sh installs it)" >&2; exit 1; }
cc=${cxx/clang++/clang}

gen=(); command -v ninja >/dev/null && gen=(-G Ninja)
cmake -S "$here" -B "$build" "${gen[@]}" -DRLPBRT_FUZZ=ON -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DCMAKE_CXX_COMPILER="$cxx" -DCMAKE_C_COMPILER="$cc" >/dev/null
cmake --build "$build" --parallel 2 --target "${targets[@]}"

# One target: fuzz it for $seconds; its summary (or, on a failure, the end of its log and
# its artifacts) goes to $work/$t/report.txt and its status to the exit code.
fuzz_one() {
  local t=$1 seeds dict
  case $t in
    fuzz_parser) seeds=("$here/fuzz/corpus/parser" "$here/fuzz/regressions/parser" "$here/tests/data/bad"); dict=$here/fuzz/pbrt.dict ;;
    fuzz_ply) seeds=("$here/fuzz/corpus/ply" "$here/fuzz/regressions/ply" "$here/tests/data/ply" "$here/tests/data/bad/ply"); dict=$here/fuzz/ply.dict ;;
    fuzz_spd) seeds=("$here/fuzz/corpus/spd"); dict= ;;
    *) echo "fuzz: unknown target $t" >&2; return 2 ;;
  esac
  local existing=() s
  for s in "${seeds[@]}"; do [ -d "$s" ] && existing+=("$s"); done
  # New inputs go to a scratch corpus (first directory); the seeds in the tree stay as they are.
  local corpus=$work/$t/corpus
  mkdir -p "$corpus" "$work/$t/artifacts"
  local args=(-max_total_time="$seconds" -timeout=10 -rss_limit_mb=2048 -malloc_limit_mb=1024
        -max_len=65536 -print_final_stats=1 -artifact_prefix="$work/$t/artifacts/")
  [ -n "$dict" ] && [ -f "$dict" ] && args+=(-dict="$dict")
  [ "$jobs" -gt 1 ] && args+=(-fork="$jobs")
  echo "fuzz: $t for ${seconds}s (corpus $corpus, seeds ${existing[*]})" >&2
  local log=$work/$t/log.txt report=$work/$t/report.txt
  if (cd "$work/$t" && "$build/fuzz/$t" "${args[@]}" "$corpus" "${existing[@]}") >"$log" 2>&1; then
    { echo "fuzz: $t passed:"
      grep -E "^(stat::number_of_executed_units|stat::average_exec_per_sec|#[0-9]+ *DONE)" "$log" || true
    } > "$report"
  else
    { echo "fuzz: $t FAILED; last lines of $log:"; tail -n 40 "$log"; ls "$work/$t/artifacts/"; } > "$report"
    return 1
  fi
}

# The targets run side by side, as many at a time as the cores hold (a target's fuzzing
# processes are single-threaded: each still gets a core for its $seconds).
status=0
slots=$(( $(nproc) / jobs ))
[ "$slots" -ge 1 ] || slots=1
pids=()
names=()
for t in "${targets[@]}"; do
  fuzz_one "$t" &
  pids+=($!)
  names+=("$t")
  if [ ${#pids[@]} -ge "$slots" ]; then
    wait "${pids[0]}" || status=1
    cat "$work/${names[0]}/report.txt" >&2 2>/dev/null || true
    pids=("${pids[@]:1}")
    names=("${names[@]:1}")
  fi
done
for i in "${!pids[@]}"; do
  wait "${pids[$i]}" || status=1
  cat "$work/${names[$i]}/report.txt" >&2 2>/dev/null || true
done
[ $status -eq 0 ] && echo "fuzz: all targets ran ${seconds}s without a crash" >&2
exit $status
