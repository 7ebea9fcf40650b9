"""How far gridtrace's normal-mapped diffuse departs from Cycles' as the map tilts the normal.

Run from the repository root after `cargo build --release`, with the PyPI `bpy` package
(Blender as a Python module), numpy and OpenEXR (the Blender virtual environment has all):

    .blender-venv/bin/python tools/blender/normal_tilt_study.py [--tilts none 0 5 15 45] [--spp 1024]
    .blender-venv/bin/python tools/blender/normal_tilt_study.py --furnace black|white [--spp 1024]

For each tilt, builds principled_normals' room with its two panels (Blender's default
material, base colour (0.8, 0.7, 0.5)) normal-mapped by that many degrees away from the
camera ("none": no normal map; 0: a flat map), exports it through Blender's glTF exporter,
renders it with Cycles and with gridtrace at the same samples (128×128, box filter, 64
bounces) and prints each panel's mean over Cycles', per channel. Files go to a temporary
folder.

With `--furnace black`, renders instead a black Principled ball of Blender's defaults (the
4 % specular layer alone) in a white world, seen from far away, and prints both renderers'
radiance by the cosine μ between the view and the surface: the share of light the
specular layer keeps at each viewing angle. With `--furnace white` the ball is white, and
a renderer that conserves energy shows 1 at every angle: what it falls short of 1 is what
its diffuse base loses beyond what the layer above keeps. (Bins below μ = 0.2 hold the
silhouette's pixels, which the white world partly covers.)
"""

import argparse
import math
import os
import subprocess
import sys
import tempfile

import bpy
import numpy as np
import OpenEXR

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import make_principled as principled  # noqa: E402
from make_cornell import export, reset, sphere  # noqa: E402
from make_references import ROOT, SIZE, add_camera, render  # noqa: E402

# Pixel rows and columns of each panel and of the wall, in the 128×128 image.
REGIONS = {"left panel": (80, 108, 8, 56), "right panel": (80, 108, 72, 120), "wall": (8, 40, 0, 128)}


def build(scene, tilt):
    """The room and two panels mapped `tilt` degrees away from the camera (None: no map)."""
    principled.room(scene)
    for name, x0 in (("Left", -1.7), ("Right", 0.1)):
        principled.normal_mapped_panel(name, x0, tilt)


def read_rgb(path):
    channels = OpenEXR.File(path).parts[0].channels
    key = "RGBA" if "RGBA" in channels else "RGB"
    return np.asarray(channels[key].pixels, dtype=np.float64)[..., :3]


def render_both(scene, work, label, spp, binary, extra=()):
    """Exports `scene`, renders it with Cycles and gridtrace; their images."""
    glb = os.path.join(work, f"{label}.glb")
    export(glb)
    cycles = os.path.join(work, f"{label}_cycles.exr")
    render(scene, cycles, spp, 1, scene.world is not None, ("BOX", 1.0))
    ours = os.path.join(work, f"{label}_gridtrace.exr")
    subprocess.run([binary, glb, "-o", ours, "-q", "--spp", str(spp), "--width", str(SIZE),
                    "--height", str(SIZE), "--max-depth", "64", "--filter", "box", *extra],
                   check=True)
    return read_rgb(ours), read_rgb(cycles)


def furnace(work, spp, binary, base):
    """A ball of base colour `base` (0 or 1) in a white world, by viewing angle."""
    scene = reset()
    colour = (base, base, base)
    sphere("Ball", principled.blender_default("Ball", colour), 1.0, (0.0, 0.0, 0.0))
    distance, fov = 60.0, 2.0
    add_camera(scene, (0.0, -distance, 0.0), (0.0, 0.0, 0.0), fov)
    world = bpy.data.worlds.new("White")
    world.use_nodes = True
    world.node_tree.nodes["Background"].inputs["Color"].default_value = (1.0, 1.0, 1.0, 1.0)
    scene.world = world
    g, c = render_both(scene, work, "furnace", spp, binary, ("--environment", "1,1,1"))
    g, c = g.mean(axis=2), c.mean(axis=2)
    # Nearly orthographic: a pixel's distance from the centre is the sine of its view angle.
    pixels_per_unit = (SIZE / 2) / (distance * math.tan(math.radians(fov / 2)))
    y, x = np.mgrid[0:SIZE, 0:SIZE] + 0.5
    r = np.hypot(x - SIZE / 2, y - SIZE / 2) / pixels_per_unit
    mu = np.sqrt(np.clip(1.0 - r * r, 0.0, 1.0))
    for lo, hi in ((0.1, 0.15), (0.15, 0.2), (0.2, 0.3), (0.3, 0.5), (0.5, 0.8), (0.8, 1.0)):
        m = (r < 0.995) & (mu >= lo) & (mu < hi)
        print(f"mu {lo}-{hi}: gridtrace {g[m].mean():.4f}, Cycles {c[m].mean():.4f}")


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--tilts", nargs="+", default=["none", "0", "5", "15", "45"])
    parser.add_argument("--spp", type=int, default=1024)
    parser.add_argument("--gridtrace", default=os.path.join(ROOT, "target", "release", "gridtrace"))
    parser.add_argument("--furnace", choices=["black", "white"],
                        help="a black or white ball in a white world instead of the panels")
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as work:
        if args.furnace:
            furnace(work, args.spp, args.gridtrace, 1.0 if args.furnace == "white" else 0.0)
            return 0
        for label in args.tilts:
            scene = reset()
            build(scene, None if label == "none" else float(label))
            g, c = render_both(scene, work, f"tilt_{label}", args.spp, args.gridtrace)
            for region, (y0, y1, x0, x1) in REGIONS.items():
                ratio = g[y0:y1, x0:x1].mean(axis=(0, 1)) / c[y0:y1, x0:x1].mean(axis=(0, 1))
                print(f"tilt {label}: {region} gridtrace / Cycles {np.round(ratio, 4)}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
