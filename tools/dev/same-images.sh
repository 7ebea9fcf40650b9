#!/usr/bin/env bash
# Shows that a change left the renderer's behaviour alone: renders the bundled and test
# scenes (glTF, USD, PLY; AOVs, motion blur, depth of field, a pixel filter, environments,
# adaptive sampling, a split render and its merge) with two gridtrace binaries and compares
# every output (images by header and sample bits), the messages, the --inspect report and
# the options --help lists. Needs python3 with the PyPI packages OpenEXR and numpy.
#
#   tools/dev/same-images.sh BEFORE_BINARY AFTER_BINARY [WORK_DIR]
#
# Prints one line per case and exits 1 if any output differs. Small images and few
# samples: the point is identity, not quality (about a minute on 2 cores).
set -euo pipefail
cd "$(dirname "$0")/../.."
before=$(realpath "$1")
after=$(realpath "$2")
work=${3:-$(mktemp -d)}
mkdir -p "$work/before" "$work/after"
ply=$(ls data/dragon/*res4*.ply* 2>/dev/null | head -n1 || true)

# name|arguments (the scene first); OUT is replaced by each side's output path.
cases=(
  "box_glb|assets/cornell_box.glb --spp 8 --width 96 -o OUT.exr"
  "box_png_agx|assets/cornell_box.glb --spp 4 --width 64 --view-transform agx --exposure 0.5 -o OUT.png"
  "box_usdc|assets/cornell_box.usdc --spp 8 --width 96 -o OUT.exr"
  "box_usdz|tests/data/scenes/cornell_box.usdz --spp 4 --width 64 -o OUT.exr"
  "spheres_aov|assets/cornell_spheres.glb --spp 8 --width 96 --aov all -o OUT.exr"
  "spheres_filter|assets/cornell_spheres.glb --spp 4 --width 64 --filter blackman-harris -o OUT.exr"
  "textured|tests/data/scenes/textured.glb --spp 8 --width 96 -o OUT.exr"
  "principled_usdc|tests/data/scenes/principled_textured.usdc --spp 4 --width 96 -o OUT.exr"
  "glass|tests/data/scenes/principled_glass.glb --spp 4 --width 96 --max-depth 32 -o OUT.exr"
  "punctual|tests/data/scenes/punctual_lights.usdc --spp 4 --width 96 -o OUT.exr"
  "lamps|tests/data/scenes/lighting_lamps.usdc --spp 4 --width 96 -o OUT.exr"
  "hdr_env|tests/data/scenes/lighting_hdr.glb --spp 4 --width 96 --environment tests/data/scenes/textures/lighting_sky.hdr --environment-rotation 30 -o OUT.exr"
  "sun_env|tests/data/scenes/lighting_sun_sky.glb --spp 4 --width 96 --environment 0.3,0.45,0.7 --hide-environment -o OUT.exr"
  "dof_usd|tests/data/scenes/lighting_dof.usdc --spp 4 --width 96 -o OUT.exr"
  "dof_flags|assets/cornell_spheres.glb --spp 4 --width 64 --fstop 1.4 --focus-distance 3 -o OUT.exr"
  "motion_usd|tests/data/scenes/animated.usdc --frame 6 --shutter=-0.5..0.5 --motion-steps 3 --spp 4 --width 64 -o OUT.exr"
  "gltf_anim|tests/data/scenes/gltf_animation/animated.glb --frame 7 --shutter=-0.25..0.25 --spp 4 --width 64 -o OUT.exr"
  "adaptive|assets/cornell_box.glb --spp 64 --noise-threshold 0.05 --width 48 -o OUT.exr"
  "part0|assets/cornell_box.glb --samples 0..4 --width 64 -o OUT.exr"
  "part1|assets/cornell_box.glb --samples 4..8 --width 64 -o OUT.exr"
  "default_light|tests/data/scenes/material_details.glb --spp 4 --width 64 -o OUT.exr"
)
if [[ -n "$ply" ]]; then
  cases+=("ply|$ply --spp 4 --width 64 -o OUT.exr")
else
  echo "note: no dragon under data/dragon (tools/dev/fetch-dragon.sh); the PLY case is skipped"
fi

status=0
# EXRs by their header and the bits of every sample (tools/dev/exr-same.py: a binary that
# writes blocks in unspecified order can write one image as different bytes); everything
# else byte for byte.
compare() { # name file_before file_after
  local same
  if [[ $2 == *.exr ]]; then
    python3 tools/dev/exr-same.py "$2" "$3" >/dev/null && same=1
  else
    cmp -s "$2" "$3" && same=1
  fi
  if [[ -n ${same:-} ]]; then echo "same     $1"; else echo "DIFFERS  $1"; status=1; fi
}
for case in "${cases[@]}"; do
  name=${case%%|*}
  args=${case#*|}
  for side in before after; do
    bin=$before; [[ $side == after ]] && bin=$after
    # shellcheck disable=SC2086
    "$bin" ${args//OUT/$work/$side/$name} -q --threads 2 >"$work/$side/$name.log" 2>&1 || true
  done
  out=$(ls "$work/before/$name".exr "$work/before/$name".png 2>/dev/null | head -n1 || true)
  if [[ -z "$out" ]]; then echo "NO IMAGE $name (see $work/before/$name.log)"; status=1; continue; fi
  compare "$name" "$out" "$work/after/$(basename "$out")"
  compare "$name (messages)" "$work/before/$name.log" "$work/after/$name.log"
done
for side in before after; do
  bin=$before; [[ $side == after ]] && bin=$after
  "$bin" merge "$work/$side/part0.exr" "$work/$side/part1.exr" --samples 0..8 -q \
    -o "$work/$side/merged.exr" >"$work/$side/merged.log" 2>&1 || true
  "$bin" --inspect tests/data/scenes/principled_textured.glb >"$work/$side/inspect.log" 2>&1 || true
  # Help may be reworded or regrouped; the options it offers may not change.
  for command in "" merge denoise; do
    # shellcheck disable=SC2086
    "$bin" $command --help 2>&1 | grep -oE -- '--[a-z][a-z0-9-]*' | sort -u
  done >"$work/$side/options.log"
done
compare merge "$work/before/merged.exr" "$work/after/merged.exr"
compare inspect "$work/before/inspect.log" "$work/after/inspect.log"
compare "options in --help" "$work/before/options.log" "$work/after/options.log"
exit $status
