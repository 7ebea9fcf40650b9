#!/usr/bin/env bash
# Times the grid of the working tree against the grid of another commit, in one process, on
# the same dragon and the same rays (tools/dev/grid-ab/main.rs says how). For measuring a change
# to the grid of a few per cent, which separate runs on a shared machine cannot resolve.
#
#   tools/dev/grid-ab.sh BASE [MODEL] [SETS] [ROUNDS]
#   tools/dev/grid-ab.sh HEAD dragon_vrip.ply.gz outside,camera,bounce,shadow 5
#
# BASE is any commit; MODEL a file of data/dragon (tools/dev/fetch-dragon.sh); SETS a
# comma-separated choice of outside, camera, bounce, shadow, light and seen (pairs: a camera
# ray, then the light segment from its hit, traced in that order); GRID_AB_RAYS rays per set
# (default 50,000); GRID_AB_CHUNK rays per chunk (default 10,000; a few hundred
# time the queries warm, in cache); GRID_AB_DENSITY builds this tree's grid at that many cells per
# triangle instead of the density it chooses (the base keeps its choice). Prints, per set,
# how many answers differ (there should be none unless the change means them to) and the
# time of this tree over the base's, median and range of the rounds. The base is copied
# under target/grid-ab as a crate of another name; the first build takes minutes, later
# ones only rebuild the two copies of gridtrace.
set -euo pipefail
root=$(git rev-parse --show-toplevel)
base=${1:?usage: tools/dev/grid-ab.sh BASE [MODEL] [SETS] [ROUNDS]}
commit=$(git -C "$root" rev-parse --verify "$base^{commit}")
work=$root/target/grid-ab
rm -rf "$work/base" "$work/harness/src"
mkdir -p "$work/base" "$work/harness/src"
git -C "$root" archive "$commit" | tar -x -C "$work/base"
sed -i '0,/^name = "gridtrace"$/s//name = "gridtrace_base"/' "$work/base/Cargo.toml"
grep -q '^name = "gridtrace_base"$' "$work/base/Cargo.toml" || {
  echo "grid-ab: could not rename the package in $commit's Cargo.toml" >&2
  exit 1
}
glam=$(sed -n 's/^glam = "\(.*\)"$/\1/p' "$root/Cargo.toml")
cat > "$work/harness/Cargo.toml" <<TOML
[package]
name = "grid-ab"
version = "0.0.0"
edition = "2024"
publish = false

[dependencies]
gridtrace = { path = "$root" }
gridtrace_base = { path = "$work/base" }
glam = "$glam"

[workspace]
TOML
cp "$root/tools/dev/grid-ab/main.rs" "$work/harness/src/main.rs"
cp "$root/tests/support/oracles/rays.rs" "$work/harness/src/rays.rs"
cp "$root/Cargo.lock" "$work/harness/Cargo.lock"
echo "grid-ab: this tree against $commit; building" >&2
cargo build --release --quiet --manifest-path "$work/harness/Cargo.toml" \
  --target-dir "$work/target"
GRID_AB_DATA=$root/data/dragon "$work/target/release/grid-ab" "${@:2}"
