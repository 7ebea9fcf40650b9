#!/usr/bin/env bash
# Counts what the grid's and Embree's queries do per ray, on a simulated processor:
# instructions, level-1 data-cache misses, last-level misses and mispredicted conditional
# branches (valgrind's callgrind, its cache and branch simulations, counting only inside
# benches/counters.rs's `counted_pass`). For where a query's time goes on a machine whose
# processor exposes no counters (`perf stat -e cycles true`: not supported).
#
#   tools/dev/accel-counters.sh [MODEL] [SETS]
#   tools/dev/accel-counters.sh dragon_vrip.ply.gz outside,bounce
#
# The simulated caches are this machine's per core: 32 KiB of L1 data (8-way), and as the
# last level the 2 MiB L2 (16-way) — the L3 is shared with other machines and holds little
# of a process's data (docs/design/grid.md, "The walk"). COUNTERS_RAYS rays per set (default
# 10,000), traced once unseen and once counted. Prints a table per structure and set, then
# the grid's counts by the source file the code was inlined from. About two minutes per
# structure and set on the full dragon; two run at once. COUNTERS_REPORT_ONLY=1 prints the
# tables again from the last runs' files (target/counters/out) without running anything.
set -euo pipefail
root=$(git rev-parse --show-toplevel)
model=${1:-dragon_vrip.ply.gz}
sets=${2:-outside,camera,bounce,shadow}
rays=${COUNTERS_RAYS:-10000}
out=$root/target/counters/out
mkdir -p "$out"
export LD_LIBRARY_PATH="$root/.embree4${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}"
command -v valgrind > /dev/null || {
  echo "accel-counters: valgrind is not installed (apt-get install valgrind)" >&2
  exit 1
}
if [ -z "${COUNTERS_REPORT_ONLY:-}" ]; then
  # Line tables, so that the counts can be told apart by source file; in a target directory
  # of their own, so that the ordinary builds are not redone.
  binary=$(cd "$root" && CARGO_PROFILE_BENCH_DEBUG=line-tables-only cargo bench --bench counters \
    --no-run --target-dir target/counters --message-format=json 2> "$out/build.log" |
    python3 -c 'import json, sys
for line in sys.stdin:
    m = json.loads(line)
    if m.get("reason") == "compiler-artifact" and m.get("executable") and m["target"]["name"] == "counters":
        print(m["executable"])') || {
    cat "$out/build.log" >&2
    exit 1
  }
  [ -x "$binary" ] || {
    echo "accel-counters: no counters binary built (see $out/build.log)" >&2
    exit 1
  }

  run() {
    local structure=$1 set=$2
    COUNTERS_MODEL=$model COUNTERS_STRUCTURE=$structure COUNTERS_SET=$set COUNTERS_RAYS=$rays \
      valgrind --tool=callgrind --collect-atstart=no --toggle-collect='*counted_pass*' \
      --cache-sim=yes --branch-sim=yes --I1=32768,8,64 --D1=32768,8,64 --LL=2097152,16,64 \
      --callgrind-out-file="$out/${model%%.*}-$structure-$set.out" "$binary" \
      > "$out/${model%%.*}-$structure-$set.log" 2>&1 || {
      echo "accel-counters: $structure on $set failed (see $out/${model%%.*}-$structure-$set.log)" >&2
      return 1
    }
  }

  jobs=()
  for set in ${sets//,/ }; do
    for structure in grid embree; do
      run "$structure" "$set" &
      jobs+=($!)
      if [ $(( ${#jobs[@]} % 2 )) -eq 0 ]; then
        for j in "${jobs[@]}"; do wait "$j"; done
        jobs=()
      fi
    done
  done
  for j in "${jobs[@]}"; do wait "$j"; done
fi

python3 - "$out" "$model" "$sets" "$rays" <<'PY'
import re, sys
from collections import defaultdict

out, model, sets, rays = sys.argv[1], sys.argv[2], sys.argv[3].split(","), int(sys.argv[4])

def read(path):
    """Totals per event, and per source file (the file a cost line's code came from, an
    inlined function's own file included), from a callgrind output file."""
    events, positions = [], 1
    totals, by_file = defaultdict(int), defaultdict(lambda: defaultdict(int))
    names, current, skip_next = {}, "?", False
    for line in open(path):
        line = line.rstrip("\n")
        if line.startswith("events:"):
            events = line.split()[1:]
        elif line.startswith("positions:"):
            positions = len(line.split()[1:])
        elif re.match(r"^c?(fl|fi|fe)=", line):
            # File names are numbered where first given, in any of these lines (the called
            # function's file `cfi`/`cfl` included); `fl`, `fi` and `fe` set the file of
            # the cost lines that follow.
            m = re.match(r"^(c?)(?:fl|fi|fe)=\((\d+)\)(?: (.*))?$", line)
            if m:
                if m.group(3):
                    names[m.group(2)] = m.group(3)
                if not m.group(1):
                    current = names.get(m.group(2), "?")
        elif line.startswith("calls="):
            skip_next = True  # the next cost line is the call's inclusive cost
        elif line and (line[0].isdigit() or line[0] in "+-*"):
            if skip_next:
                skip_next = False
                continue
            fields = line.split()[positions:]
            for event, value in zip(events, fields):
                v = int(value)
                totals[event] += v
                by_file[current][event] += v
    return totals, by_file

print(f"{model}, {rays} rays per set, counted on their second pass (callgrind; L1d 32 KiB, last level 2 MiB)")
print()
print("| set | structure | instructions | L1d misses | last-level misses | branches | mispredicted |")
print("|---|---|---|---|---|---|---|")
grid_files = {}
for s in sets:
    for structure in ("grid", "embree"):
        totals, by_file = read(f"{out}/{model.split('.')[0]}-{structure}-{s}.out")
        per = lambda *names: sum(totals.get(n, 0) for n in names) / rays
        print(f"| {s} | {structure} | {per('Ir'):.0f} | {per('D1mr', 'D1mw'):.1f} | "
              f"{per('DLmr', 'DLmw'):.1f} | {per('Bc'):.0f} | {per('Bcm'):.1f} |")
        if structure == "grid":
            grid_files[s] = by_file
print()
for s, by_file in grid_files.items():
    ranked = sorted(by_file.items(), key=lambda kv: -kv[1].get("Ir", 0))
    parts = []
    for name, costs in ranked[:12]:
        short = "/".join(name.split("/")[-2:])
        parts.append(f"{short} {costs.get('Ir', 0) / rays:.0f} instr, "
                     f"{(costs.get('D1mr', 0) + costs.get('D1mw', 0)) / rays:.1f} L1d, "
                     f"{(costs.get('DLmr', 0) + costs.get('DLmw', 0)) / rays:.1f} LL, "
                     f"{costs.get('Bcm', 0) / rays:.1f} mispredicted")
    print(f"grid, {s} rays, per ray by source file: " + "; ".join(parts))
PY
