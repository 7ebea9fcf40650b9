#!/usr/bin/env bash
# How long the full Stanford dragon takes to be ready to render in each format a user brings
# ("prepared in": reading, scene setup, lights, the grid), beside its file size and the
# grid build alone (the accel benchmark's median), all in one run.
#
#   tools/dev/first-pixel.sh [RUNS]     (after tools/dev/make_dragon_formats.py)
set -euo pipefail
cd "$(dirname "$0")/../.."
runs=${1:-5}
cargo build --release --quiet
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
echo "| file | MB | prepared in, median of $runs (s) | range |"
echo "|---|---|---|---|"
for f in dragon.glb dragon.ply dragon.usdc dragon_vrip.ply.gz; do
    path=data/dragon/$f
    times=$(for _ in $(seq "$runs"); do
        target/release/gridtrace "$path" -o "$out/x.exr" --spp 1 --width 64 --height 64 2>&1 |
            grep -o 'prepared in [0-9.]*' | awk '{print $3}'
    done | sort -n)
    median=$(echo "$times" | awk '{a[NR]=$1} END {print a[int((NR+1)/2)]}')
    range=$(echo "$times" | awk 'NR==1{lo=$1} {hi=$1} END {print lo "–" hi}')
    size=$(stat -c %s "$path" | awk '{printf "%.1f", $1/1e6}')
    echo "| $f | $size | $median | $range |"
done
ACCEL_BENCH_MODELS=dragon_vrip.ply.gz ACCEL_BENCH_RUNS=5 ACCEL_BENCH_RAYS=20000 \
    cargo bench --quiet --bench accel 2>/dev/null | grep -o 'build s grid [0-9.]*' |
    awk '{print "grid build alone (median of 5): " $4 " s"}'
