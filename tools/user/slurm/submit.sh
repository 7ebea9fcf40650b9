#!/usr/bin/env bash
# Submits one image to Slurm as K render tasks (a job array) and a merge that runs when
# they have all succeeded. Prints the two job ids: "ARRAY_JOB_ID MERGE_JOB_ID".
#
#   tools/user/slurm/submit.sh [--tasks K] [--spp N] SCENE OUTPUT.exr [gridtrace options]
#
# Parts and logs go to OUTPUT.parts/ beside the output. Extra sbatch options (partition,
# account, --cpus-per-task, …) go in $SBATCH_OPTIONS. The scene, the output folder and the
# gridtrace binary ($GRIDTRACE, or gridtrace on the PATH) must be visible at the same paths
# on every node, as on any shared-filesystem cluster.
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
tasks=4
spp=256
while [ $# -gt 0 ]; do
  case $1 in
    --tasks) tasks=$2; shift 2 ;;
    --spp) spp=$2; shift 2 ;;
    *) break ;;
  esac
done
if [ $# -lt 2 ]; then
  echo "usage: $0 [--tasks K] [--spp N] SCENE OUTPUT.exr [gridtrace options]" >&2
  exit 2
fi
scene=$(realpath "$1")
output=$(realpath -m "$2")
shift 2
parts="$output.parts"
mkdir -p "$parts"
# Parts of an earlier submission to the same output would not merge with these.
rm -f "$parts"/part-*.exr
# shellcheck disable=SC2086 # SBATCH_OPTIONS is a list of options
array=$(sbatch --parsable ${SBATCH_OPTIONS:-} --array="0-$((tasks - 1))" \
  --output="$parts/render-%a.log" \
  "$here/render-part.sbatch" "$scene" "$spp" "$tasks" "$parts" "$@")
array=${array%%;*}
# shellcheck disable=SC2086
merge=$(sbatch --parsable ${SBATCH_OPTIONS:-} --dependency="afterok:$array" \
  --output="$parts/merge.log" \
  "$here/merge.sbatch" "$parts" "$spp" "$output")
merge=${merge%%;*}
echo "$array $merge"
