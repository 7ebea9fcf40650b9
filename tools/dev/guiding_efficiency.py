"""Path guiding on and off, in one run: error against each Cycles reference versus time.

Run from the repository root after `cargo build --release`, with numpy and OpenEXR (the
Blender virtual environment has both):

    .blender-venv/bin/python tools/dev/guiding_efficiency.py caustic:64 principled_lamp_shade:64

For each NAME:SPP, renders tests/data/scenes/NAME.glb at the reference's size with
`--guiding off` and `--guiding on`, alternately, twice each (the timings are noisy:
interleaving keeps the machine's state alike for both). Time is the whole process, so the
guide's training counts. Error is the mean squared error against the mean of the
reference's two halves less the reference's own noise. Prints both and the ratio of
efficiencies, 1 / (MSE x time), guided over unguided.
"""

import subprocess
import sys
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


def measure(name, spp, work):
    a = read_rgb(f"tests/data/references/{name}_a.exr")
    b = read_rgb(f"tests/data/references/{name}_b.exr")
    reference, own_noise = (a + b) / 2, np.mean((a - b) ** 2) / 4
    height, width = reference.shape[:2]
    runs = {"off": [], "on": []}
    for mode in ["off", "on", "off", "on"]:
        out = f"{work}/{name}_{mode}.exr"
        start = time.time()
        subprocess.run([GRIDTRACE, f"tests/data/scenes/{name}.glb", "-o", out, "-q",
                        "--width", str(width), "--height", str(height), "--spp", str(spp),
                        "--max-depth", "64", "--guiding", mode, "--seed", "3"], check=True)
        seconds = time.time() - start
        runs[mode].append((np.mean((read_rgb(out) - reference) ** 2) - own_noise, seconds))
    efficiency = {}
    for mode, values in runs.items():
        mse = np.mean([m for m, _ in values])
        seconds = np.mean([s for _, s in values])
        efficiency[mode] = 1 / (mse * seconds)
        print(f"{name} {spp} spp, guiding {mode}: MSE {mse:.3e}, {seconds:.2f} s")
    print(f"{name} {spp} spp: efficiency guided / unguided {efficiency['on'] / efficiency['off']:.2f}")


def main():
    with tempfile.TemporaryDirectory() as work:
        for arg in sys.argv[1:]:
            name, spp = arg.split(":")
            measure(name, int(spp), work)


if __name__ == "__main__":
    main()
