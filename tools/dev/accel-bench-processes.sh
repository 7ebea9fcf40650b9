#!/usr/bin/env bash
# Runs the accelerator benchmark (benches/accel.rs) in several fresh processes and prints,
# per model and ray set, the grid/Embree median of each process and the median and range
# over the processes; then the same for the build times.
#
#   tools/dev/accel-bench-processes.sh [PROCESSES]      (default 7)
#
# Why: on the development VM the speed of all three structures changes from one process to
# the next (Embree's on the full dragon's outside rays from 2.0 to 4.1 Mrays/s, the grid's
# from 1.4 to 2.1), far more than between the runs inside one process, which share one
# placement of every structure in memory. One process's median is one draw; this gives the
# spread of the draws. The ACCEL_BENCH_* variables are passed on (for example
# ACCEL_BENCH_MODELS=dragon_vrip.ply.gz ACCEL_BENCH_RUNS=3 ACCEL_BENCH_RAYS=50000); the
# processes run one after another, so keep the machine otherwise idle. The benchmark is
# built once and that copy is what every process runs: sources edited during the run do not
# change what is measured (each process used to run `cargo bench`, which rebuilt them).
set -euo pipefail
root=$(git rev-parse --show-toplevel)
processes=${1:-7}
export LD_LIBRARY_PATH="$root/.embree4${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}"
cd "$root"
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
# The benchmark's own executable (the build also lists the gridtrace binary's).
built=$(cargo bench --bench accel --no-run --quiet --message-format=json |
  sed -n 's/.*"executable":"\([^"]*\/deps\/accel-[^"]*\)".*/\1/p' | tail -n 1)
[ -x "$built" ] || {
  echo "accel-bench-processes: could not find the built benchmark" >&2
  exit 1
}
cp "$built" "$work/accel"
echo "accel-bench-processes: $(git rev-parse --short HEAD)$(git diff --quiet HEAD -- src benches tests/support/oracles Cargo.toml Cargo.lock || echo ' with uncommitted changes'), built once" >&2
rows=$work/rows
warm=$work/warm
builds=$work/builds
for ((p = 1; p <= processes; p++)); do
  echo "accel-bench-processes: process $p of $processes" >&2
  # Table rows: | model | triangles | set | grid | Embree | CWBVH | grid/Embree median (range) | ...
  "$work/accel" --bench 2>/dev/null > "$work/out"
  awk -F'|' -v p="$p" '$2 ~ /\.ply/ && $4 !~ /rays/ {
      gsub(/ /, "", $2); gsub(/ /, "", $4); split($8, r, " ");
      gsub(/ /, "", $6); print p, $2, $4, r[1], $6 }' "$work/out" >> "$rows"
  # "MODEL, SET rays, ns per ray cold / warm (...): grid C / W, Embree C / W, ...": Embree's
  # warm time over the grid's, each ray traced several times in a row (computation alone).
  sed -n 's/^\([^,]*\), \([a-z]*\) rays, ns per ray cold \/ warm[^:]*: grid [0-9.]* \/ \([0-9.]*\), Embree [0-9.]* \/ \([0-9.]*\),.*/\1 \2 \3 \4/p' \
    "$work/out" | awk -v p="$p" '{ printf "%d %s %s %.2f\n", p, $1, $2, $4 / $3 }' >> "$warm"
  # "MODEL: build s grid G, Embree E, ...": the grid's build time over Embree's.
  sed -n 's/^\([^:]*\): build s grid \([0-9.]*\), Embree \([0-9.]*\),.*/\1 \2 \3/p' "$work/out" |
    awk -v p="$p" '{ printf "%d %s build %.2f %s\n", p, $1, $2 / $3, $3 }' >> "$builds"
done
# Prints a table of the rows in file $1: per model and set, the values of each process, their
# median and range, and each process's speed ($2 and $3 head the columns).
report() {
  # Embree's speed per process tells how fast memory was in it (the grid's ratio is lower
  # where memory is fast: docs/benchmarks.md).
  echo "| model | set | $2 | median | range | $3 |"
  echo "|---|---|---|---|---|---|"
  awk '{ key = $2 " " $3; if (!(key in seen)) { seen[key] = 1; order[++n] = key }
         values[key] = values[key] " " $4; speeds[key] = speeds[key] " " $5 }
       END {
         for (i = 1; i <= n; i++) {
           key = order[i]; m = split(substr(values[key], 2), v, " ");
           # Insertion sort of the m values.
           for (a = 2; a <= m; a++) { x = v[a]; for (b = a - 1; b >= 1 && v[b] > x; b--) v[b + 1] = v[b]; v[b + 1] = x }
           median = (m % 2) ? v[(m + 1) / 2] : (v[m / 2] + v[m / 2 + 1]) / 2
           split(key, k, " ")
           printf "| %s | %s |%s | %.2f | %.2f–%.2f |%s |\n", k[1], k[2], values[key], median, v[1], v[m], speeds[key]
         }
       }' "$1"
}
report "$rows" "grid/Embree median of each process" "Embree Mrays/s of each process"
echo
echo "Warm (each ray traced several times in a row: the computation alone, memory aside):"
awk '{ print $1, $2, $3, $4, "-" }' "$warm" > "$work/warm_rows"
report "$work/warm_rows" "Embree/grid warm ns per ray, each process" "-"
echo
echo "Build (median of five builds in each process; below 1 the grid builds faster):"
report "$builds" "grid/Embree build time, each process" "Embree build s of each process"
