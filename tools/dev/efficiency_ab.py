"""Two ways of rendering, A and B, in one run: error against each Cycles reference versus time.

Run from the repository root after `cargo build --release`, with numpy and OpenEXR (the
Blender virtual environment has both):

    .blender-venv/bin/python tools/dev/efficiency_ab.py [--a BINARY] [--b BINARY]
        [--a-args "OPTIONS"] [--b-args "OPTIONS"] [--seeds N] NAME:SPP...

    # path guiding off against on:
    .blender-venv/bin/python tools/dev/efficiency_ab.py --b-args "--guiding on" caustic:64
    # a saved binary against the current one:
    .blender-venv/bin/python tools/dev/efficiency_ab.py --a /tmp/before caustic:64

For each NAME:SPP, renders NAME.glb (from tests/data/scenes or assets) at the reference's size with A and
with B, alternately, once per seed (the timings are noisy: interleaving keeps the machine's
state alike for both). Time is the whole process, so loading and any training count. Error
is the mean squared error against the mean of the reference's two halves less the
reference's own noise, averaged over the seeds. Prints both and the ratio of efficiencies,
1 / (MSE x time), B over A.
"""

import argparse
import os
import shlex
import subprocess
import tempfile
import time

import numpy as np
import OpenEXR

GRIDTRACE = "target/release/gridtrace"


def read_rgb(path):
    channels = OpenEXR.File(path).parts[0].channels
    if "RGBA" in channels:
        return np.asarray(channels["RGBA"].pixels, dtype=np.float64)[..., :3]
    return np.asarray(channels["RGB"].pixels, dtype=np.float64)


def scene_file(name):
    """The scene of a reference: a test scene, or one of the bundled ones."""
    for directory in ("tests/data/scenes", "assets"):
        path = f"{directory}/{name}.glb"
        if os.path.exists(path):
            return path
    raise SystemExit(f"no scene {name}.glb in tests/data/scenes or assets")


def measure(name, spp, sides, seeds, work):
    a = read_rgb(f"tests/data/references/{name}_a.exr")
    b = read_rgb(f"tests/data/references/{name}_b.exr")
    reference, own_noise = (a + b) / 2, np.mean((a - b) ** 2) / 4
    height, width = reference.shape[:2]
    runs = {side: [] for side in sides}
    for seed in range(1, seeds + 1):
        for side, (binary, extra) in sides.items():
            out = f"{work}/{name}_{side}.exr"
            start = time.time()
            subprocess.run([binary, scene_file(name), "-o", out, "-q",
                            "--width", str(width), "--height", str(height), "--spp", str(spp),
                            "--max-depth", "64", "--seed", str(seed)] + extra, check=True)
            seconds = time.time() - start
            runs[side].append((np.mean((read_rgb(out) - reference) ** 2) - own_noise, seconds))
    efficiency = {}
    for side, values in runs.items():
        mse = np.mean([m for m, _ in values])
        seconds = np.mean([s for _, s in values])
        efficiency[side] = 1 / (mse * seconds)
        print(f"{name} {spp} spp, {side}: MSE {mse:.3e}, {seconds:.2f} s")
    print(f"{name} {spp} spp: efficiency B / A {efficiency['B'] / efficiency['A']:.2f}")


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--a", default=GRIDTRACE, help="binary A")
    parser.add_argument("--b", default=GRIDTRACE, help="binary B")
    parser.add_argument("--a-args", default="", help="options A adds")
    parser.add_argument("--b-args", default="", help="options B adds")
    parser.add_argument("--seeds", type=int, default=2, help="renders per side and scene")
    parser.add_argument("scenes", nargs="+", metavar="NAME:SPP")
    args = parser.parse_args()
    sides = {"A": (args.a, shlex.split(args.a_args)), "B": (args.b, shlex.split(args.b_args))}
    with tempfile.TemporaryDirectory() as work:
        for scene in args.scenes:
            name, spp = scene.split(":")
            measure(name, int(spp), sides, args.seeds, work)


if __name__ == "__main__":
    main()
