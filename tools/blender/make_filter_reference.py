"""Render the Cornell box's Cycles reference with Cycles' default pixel filter,
Blackman-Harris 1.5 px, for the pixel-filter comparison (tests/pixel_filter.rs).

Run from the repository root with the PyPI `bpy` package (Blender as a Python module):

    pip install bpy==5.0.1
    python3 tools/blender/make_filter_reference.py [--samples N]

The scene is make_references.py's `cornell_box` (its glTF is `assets/cornell_box.glb`, not
rewritten here), with the same exact material models and unbiased settings; only the filter
differs. Writes `tests/data/references/cornell_box_blackman_harris_{a,b}.exr`.
"""

import argparse
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import bpy  # noqa: E402
from make_cornell import reset  # noqa: E402
from make_references import SCENE_TABLE, render_reference, use_exact_models  # noqa: E402


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--samples", type=int, default=2048, help="total Cycles samples per pixel")
    args = parser.parse_args()
    scene = reset()
    build, _, _ = SCENE_TABLE["cornell_box"]
    build(scene)
    for mat in bpy.data.materials:
        if mat.node_tree and mat.node_tree.nodes.get("Principled BSDF"):
            use_exact_models(mat)
    render_reference(scene, "cornell_box_blackman_harris", args.samples,
                     pixel_filter=("BLACKMAN_HARRIS", 1.5))
    return 0


if __name__ == "__main__":
    sys.exit(main())
