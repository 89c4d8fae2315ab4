#!/usr/bin/env bash
# The exchange's share of a distributed render on one machine (docs/DISTRIBUTED.md, issue 31
# item 6): 1 process x 2 threads against `mpirun -np 2` x 1 thread, per scene and guide.
#   bench/mpi_share.sh OUTDIR [RUNS]
# Renders each small variant at $SPP (default 64) spp, seed 1, RUNS times (default 2), one
# render at a time, and prints a table row per scene and guide: the render seconds of both,
# rank 0's exchange seconds (the collectives) and of those the waiting for the other rank,
# the passes, the bytes per pass and the exchange's share of the 2-rank render. The --stats
# files stay in OUTDIR. Needs Open MPI (as root: OMPI_ALLOW_RUN_AS_ROOT=1 and
# OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1).
set -euo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)
shared=${SHARED:-${RLPBRT_SHARED:-$here/../shared}}
bin=${RLPBRT:-$here/build/rlpbrt}
out=${1:?usage: $0 OUTDIR [RUNS]}
runs=${2:-2}
spp=${SPP:-64}
mkdir -p "$out"
{
    echo "date: $(date -u +%Y-%m-%dT%H:%MZ)"
    echo "machine: $(nproc) cores, $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | xargs)"
    echo "commit: $(git -C "$here" rev-parse --short HEAD 2>/dev/null || echo unknown)"
    echo "load before: $(cut -d' ' -f1-3 /proc/loadavg)"
} > "$out/run.txt"
cat "$out/run.txt"
scenes="cornell-box=cornell-box/scene.small.pbrt veach-bidir=veach-bidir/bidir.small.pbrt"
echo "| scene | guide | 1x2 s | 2x1 s | 2x1 exchange s | of which waiting s | passes | MB per pass | exchange share |"
echo "|---|---|---:|---:|---:|---:|---:|---:|---:|"
for entry in $scenes; do
    id=${entry%%=*}
    scene=$shared/scenes/${entry#*=}
    for guide in none hemi vdb; do
        for ((r = 1; r <= runs; ++r)); do
            base=$out/$id-$guide-$r
            "$bin" "$scene" --guide "$guide" --spp "$spp" --seed 1 --nthreads 2 \
                -o "$base-1x2.exr" --stats "$base-1x2.json" > /dev/null 2>&1
            mpirun --oversubscribe -np 2 "$bin" "$scene" --guide "$guide" --spp "$spp" \
                --seed 1 --nthreads 1 -o "$base-2x1.exr" --stats "$base-2x1.json" \
                > /dev/null 2>&1
            rm -f "$base-1x2.exr" "$base-2x1.exr"
        done
        python3 - "$out" "$id" "$guide" "$runs" <<'EOF'
import json, sys
out, id, guide, runs = sys.argv[1], sys.argv[2], sys.argv[3], int(sys.argv[4])
one = [json.load(open(f"{out}/{id}-{guide}-{r}-1x2.json")) for r in range(1, runs + 1)]
two = [json.load(open(f"{out}/{id}-{guide}-{r}-2x1.json")) for r in range(1, runs + 1)]
j = lambda xs, f: " / ".join(f(x) for x in xs)
print(f"| {id} | {guide} | {j(one, lambda s: '%.2f' % s['seconds'])} | "
      f"{j(two, lambda s: '%.2f' % s['seconds'])} | "
      f"{j(two, lambda s: '%.3f' % s['exchange_seconds'])} | "
      f"{j(two, lambda s: '%.3f' % s['exchange_wait_seconds'])} | {two[0]['passes']} | "
      f"{two[0]['bytes_exchanged_per_pass'] / 1e6:.2f} | "
      f"{j(two, lambda s: '%.1f%%' % (100 * s['exchange_seconds'] / s['seconds']))} |")
EOF
    done
done
