#!/usr/bin/env bash
# The accelerator benchmark (benches/accel.rs) of a commit against the working tree's, in
# fresh processes that alternate between the two, and per model and ray set the grid/Embree
# median of each process, the median over each side's processes and the after/before ratio.
#
#   tools/dev/accel-bench-ab.sh BASE [ROUNDS]      (default 3: six processes)
#
# Why alternate: speeds change from one process to the next on the shared development
# machine (mostly the speed of memory), so sides measured one after the other would differ
# by when they ran. The ACCEL_BENCH_* variables are passed on (for example
# ACCEL_BENCH_MODELS=dragon_vrip_res4.ply.gz,dragon_vrip.ply.gz ACCEL_BENCH_RUNS=3). BASE is
# built in a worktree under target/accel-ab with its own target folder (minutes the first
# time), sharing this checkout's Embree and dragons; the worktree is removed at the end.
set -euo pipefail
root=$(git rev-parse --show-toplevel)
base=$(git -C "$root" rev-parse --verify "${1:?usage: tools/dev/accel-bench-ab.sh BASE [ROUNDS]}^{commit}")
rounds=${2:-3}
work=$root/target/accel-ab
export LD_LIBRARY_PATH="$root/.embree4${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}"
mkdir -p "$work"
git -C "$root" worktree remove --force "$work/base" 2>/dev/null || rm -rf "$work/base"
git -C "$root" worktree add --quiet --detach "$work/base" "$base"
trap 'git -C "$root" worktree remove --force "$work/base"' EXIT
ln -s "$root/.embree4" "$work/base/.embree4"
ln -s "$root/data" "$work/base/data"

# Builds the benchmark in folder $1 with target folder $2 and copies it to $3.
build() {
  local built
  built=$(cd "$1" && CARGO_TARGET_DIR=$2 cargo bench --bench accel --no-run --quiet \
    --message-format=json | sed -n 's/.*"executable":"\([^"]*\)".*/\1/p' | tail -n 1)
  [ -x "$built" ] || {
    echo "accel-bench-ab: could not build the benchmark in $1" >&2
    exit 1
  }
  cp "$built" "$3"
}
echo "accel-bench-ab: building $(git -C "$root" rev-parse --short "$base") and the working tree" >&2
build "$work/base" "$work/target-base" "$work/accel-before"
build "$root" "$root/target" "$work/accel-after"

rows=$work/rows
: > "$rows"
for ((r = 1; r <= rounds; r++)); do
  for side in before after; do
    echo "accel-bench-ab: round $r of $rounds, $side" >&2
    # Table rows: | model | triangles | set | grid | Embree | CWBVH | grid/Embree median (range) | ...
    "$work/accel-$side" --bench 2>/dev/null |
      awk -F'|' -v side="$side" '$2 ~ /\.ply/ && $4 !~ /rays/ {
          gsub(/ /, "", $2); gsub(/ /, "", $4); split($8, r, " "); print side, $2, $4, r[1] }' \
        >> "$rows"
  done
done

echo "| model | set | before: each process | median | after: each process | median | after/before |"
echo "|---|---|---|---|---|---|---|"
awk '{ key = $2 " " $3; if (!(key in seen)) { seen[key] = 1; order[++n] = key }
       values[$1 " " key] = values[$1 " " key] " " $4 }
     function median(list,   v, m, a, b, x) {
       m = split(substr(list, 2), v, " ")
       for (a = 2; a <= m; a++) { x = v[a]; for (b = a - 1; b >= 1 && v[b] > x; b--) v[b + 1] = v[b]; v[b + 1] = x }
       return (m % 2) ? v[(m + 1) / 2] : (v[m / 2] + v[m / 2 + 1]) / 2
     }
     END {
       for (i = 1; i <= n; i++) {
         key = order[i]; split(key, k, " ")
         b = median(values["before " key]); a = median(values["after " key])
         printf "| %s | %s |%s | %.2f |%s | %.2f | %.3f |\n", k[1], k[2],
           values["before " key], b, values["after " key], a, a / b
       }
     }' "$rows"
