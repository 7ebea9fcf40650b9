#!/usr/bin/env bash
# Instructions and mispredicted branches of whole renders by gridtrace binaries, counted on
# valgrind's simulated processor (cachegrind): the same count in every run, so a change of
# a percent or two shows where wall-clock pairs on the shared machine scatter by a third.
# Instructions are not time (cache misses and mispredictions cost more than their count),
# so read both, and confirm a large change with tools/dev/efficiency_ab.py.
#
#   tools/dev/render-instructions.sh SCENE BINARY...
#   tools/dev/render-instructions.sh assets/cornell_spheres.glb /tmp/before target/release/gridtrace
#
# Each binary renders SCENE at 64 x 64, 16 spp, seed 1, 64 bounces, on one thread
# (RENDER_SPP and RENDER_SIZE change the first two); about half a minute per binary for the
# bundled scenes. RENDER_TOP=N also prints each binary's N costliest functions (columns:
# instructions, conditional branches and their mispredictions, indirect branches and theirs).
set -euo pipefail
scene=${1:?usage: tools/dev/render-instructions.sh SCENE BINARY...}
shift
[ $# -gt 0 ] || { echo "render-instructions: name at least one binary" >&2; exit 1; }
command -v valgrind > /dev/null || {
  echo "render-instructions: valgrind is not installed (apt-get install valgrind)" >&2
  exit 1
}
spp=${RENDER_SPP:-16}
size=${RENDER_SIZE:-64}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
printf '%-40s %16s %14s\n' binary instructions mispredicted
for binary in "$@"; do
  valgrind --tool=cachegrind --cache-sim=no --branch-sim=yes \
    --cachegrind-out-file="$work/counts" --log-file="$work/log" \
    "$binary" "$scene" -o "$work/out.exr" --spp "$spp" --width "$size" --height "$size" \
    --max-depth 64 --seed 1 --threads 1 --quiet > /dev/null 2>&1 || {
    echo "render-instructions: $binary failed on $scene" >&2
    cat "$work/log" >&2
    exit 1
  }
  instructions=$(grep -E 'I +refs:' "$work/log" | awk '{print $NF}')
  mispredicted=$(grep -E 'Mispredicts:' "$work/log" | awk '{print $3}')
  printf '%-40s %16s %14s\n' "$binary" "$instructions" "$mispredicted"
  if [ -n "${RENDER_TOP:-}" ]; then
    cg_annotate "$work/counts" 2> /dev/null | grep -E '^ *[0-9,]+ \(' | sed -n "2,$((RENDER_TOP + 1))p"
  fi
done
