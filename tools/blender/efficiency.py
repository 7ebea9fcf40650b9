"""Sampling efficiency against Cycles: error against each Cycles reference versus time.

Run from the repository root after `cargo build --release`, with the PyPI `bpy` package
(Blender as a Python module) and numpy and OpenEXR:

    pip install bpy==5.0.1 numpy OpenEXR
    python3 tools/blender/efficiency.py [--spp 16 64] [--only NAME] [--gridtrace PATH] [--guiding]

For each reference scene of make_references.py (128x128, box filter, 64 bounces, black
world, materials replaced by gridtrace's models), both renderers render it at each sample
count in this one run, on the same cores (Cycles: CPU, threads auto; gridtrace: one thread
per core). Error is the mean squared error against the reference's mean (the two halves in
tests/data/references), less the reference's own noise (the halves' squared difference / 4);
time is the time spent sampling: gridtrace's reported render time (loading excluded), and
for Cycles the time of the N-sample render less that of a 1-sample render (scene sync and
BVH build), scaled by N / (N - 1). The renderers take turns seed by seed; error is the
mean over the seeds, time the median (one slow spell of the shared machine moves a mean by
a third). Efficiency is 1 / (MSE x time); the table gives both
renderers' figures and their ratio (gridtrace / Cycles, higher is better). With
`--guiding`, gridtrace also renders every measurement with `--guiding on` in the same run,
and the table gains the guided figures and their ratio to Cycles.
"""

import argparse
import os
import re
import subprocess
import sys
import tempfile
import time

import numpy as np
import OpenEXR

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import bpy  # noqa: E402
from make_cornell import reset  # noqa: E402
from make_references import (  # noqa: E402
    REFERENCES, ROOT, SCENE_TABLE, configure_cycles, use_exact_models,
)


def read_rgb(path):
    f = OpenEXR.File(path)
    channels = f.parts[0].channels
    if "RGBA" in channels:
        return np.asarray(channels["RGBA"].pixels, dtype=np.float64)[..., :3]
    if "RGB" in channels:
        return np.asarray(channels["RGB"].pixels, dtype=np.float64)
    return np.stack([np.asarray(channels[c].pixels, dtype=np.float64) for c in "RGB"], axis=-1)


def reference(name):
    a = read_rgb(os.path.join(REFERENCES, f"{name}_a.exr"))
    b = read_rgb(os.path.join(REFERENCES, f"{name}_b.exr"))
    return 0.5 * (a + b), float(np.mean((a - b) ** 2) / 4.0)


def cycles_render(scene, spp, seed, out):
    configure_cycles(scene, spp, seed)
    scene.render.filepath = out
    start = time.perf_counter()
    bpy.ops.render.render(write_still=True)
    return time.perf_counter() - start


def gridtrace_render(binary, scene_file, spp, seed, out, guiding="off"):
    result = subprocess.run(
        [binary, scene_file, "-o", out, "--spp", str(spp), "--seed", str(seed),
         "--max-depth", "64", "--width", "128", "--height", "128", "--guiding", guiding],
        capture_output=True, text=True, check=True)
    seconds = re.search(r" in ([0-9.]+) s:", result.stderr)
    return float(seconds.group(1))


def scene_file(name):
    _, directory, _ = SCENE_TABLE[name]
    return os.path.join(directory, f"{name}.glb")


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--spp", type=int, nargs="+", default=[16, 64])
    parser.add_argument("--only", action="append", help="scene name (repeatable)")
    parser.add_argument("--repeats", type=int, default=2, help="renders per measurement (seeds)")
    parser.add_argument("--gridtrace", default=os.path.join(ROOT, "target", "release", "gridtrace"))
    parser.add_argument("--guiding", action="store_true",
                        help="also render gridtrace with --guiding on, in the same run")
    args = parser.parse_args()
    renderers = ("gridtrace", "guided", "cycles") if args.guiding else ("gridtrace", "cycles")
    names = [n for n, (_, _, s) in SCENE_TABLE.items() if s > 0 and (not args.only or n in args.only)]
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        out = os.path.join(tmp, "out.exr")
        for name in names:
            ref, ref_noise = reference(name)
            scene = reset()
            SCENE_TABLE[name][0](scene)
            for mat in bpy.data.materials:
                if mat.node_tree and mat.node_tree.nodes.get("Principled BSDF"):
                    use_exact_models(mat)
            overhead = min(cycles_render(scene, 1, 100 + r, out) for r in range(args.repeats))
            for spp in args.spp:
                errors = {who: [] for who in renderers}
                times = {who: [] for who in renderers}
                # The renderers take turns, seed by seed, so that a slow spell of the shared
                # machine falls on all of them.
                for r in range(args.repeats):
                    seed = 10 + r
                    for who in renderers:
                        if who == "cycles":
                            t = (cycles_render(scene, spp, seed, out) - overhead) * spp / (spp - 1)
                        else:
                            guiding = "on" if who == "guided" else "off"
                            t = gridtrace_render(args.gridtrace, scene_file(name), spp, seed, out,
                                                 guiding)
                        errors[who].append(
                            max(np.mean((read_rgb(out) - ref) ** 2) - ref_noise, 1e-12))
                        times[who].append(max(t, 1e-3))
                measured = {}
                for who in renderers:
                    mse, seconds = float(np.mean(errors[who])), float(np.median(times[who]))
                    measured[who] = (mse, seconds, 1.0 / (mse * seconds))
                rows.append((name, spp, measured))
                g, c = measured["gridtrace"], measured["cycles"]
                print(f"{name} {spp} spp: gridtrace MSE {g[0]:.3g} in {g[1]:.2f} s, "
                      f"Cycles MSE {c[0]:.3g} in {c[1]:.2f} s, efficiency ratio {g[2] / c[2]:.2f}"
                      + (f"; guided MSE {measured['guided'][0]:.3g} in {measured['guided'][1]:.2f} s, "
                         f"efficiency ratio {measured['guided'][2] / c[2]:.2f}" if args.guiding else ""),
                      flush=True)
    print()
    guided_head = " guided MSE | guided s | guided efficiency ratio |" if args.guiding else ""
    print("| scene | spp | gridtrace MSE | gridtrace s | Cycles MSE | Cycles s | MSE ratio (Cycles / gridtrace) | efficiency ratio (gridtrace / Cycles) |" + guided_head)
    print("|---|---|---|---|---|---|---|---|" + ("---|---|---|" if args.guiding else ""))
    for name, spp, m in rows:
        g, c = m["gridtrace"], m["cycles"]
        guided = ""
        if args.guiding:
            h = m["guided"]
            guided = f" {h[0]:.3g} | {h[1]:.2f} | {h[2] / c[2]:.2f} |"
        print(f"| {name} | {spp} | {g[0]:.3g} | {g[1]:.2f} | {c[0]:.3g} | {c[1]:.2f} | "
              f"{c[0] / g[0]:.2f} | {g[2] / c[2]:.2f} |" + guided)
    return 0


if __name__ == "__main__":
    sys.exit(main())
