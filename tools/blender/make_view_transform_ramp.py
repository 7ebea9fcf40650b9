"""Blender's own AgX output of a linear test ramp, for the view-transform test
(tests/view_transform.rs).

Run from the repository root with the PyPI `bpy` package (Blender as a Python module):

    pip install bpy==5.0.1
    python3 tools/blender/make_view_transform_ramp.py

Writes `tests/data/references/view_ramp.exr`, a linear Rec.709 image whose columns step
exposure from 12 stops under to 10 stops over middle grey (0.18) and whose rows are
grey and a set of saturated and unsaturated colours, and
`tests/data/references/view_ramp_agx.png`, that EXR saved by Blender "as render" through
the sRGB display's AgX view (Blender 5's default), exposure 0, gamma 1, no look.
"""

import os
import sys

import bpy

WIDTH = 89  # -12 .. +10 stops in quarter stops
COLOURS = [
    (1.0, 1.0, 1.0),
    (1.0, 0.0, 0.0),
    (0.0, 1.0, 0.0),
    (0.0, 0.0, 1.0),
    (1.0, 1.0, 0.0),
    (0.0, 1.0, 1.0),
    (1.0, 0.0, 1.0),
    (1.0, 0.3, 0.02),
    (0.8, 0.5, 0.35),
    (0.2, 0.4, 0.9),
    (0.35, 0.6, 0.3),
    (0.9, 0.85, 0.7),
]


def ramp_pixels():
    """RGBA floats, bottom row first (Blender's pixel order)."""
    rows = []
    for colour in COLOURS:
        row = []
        for x in range(WIDTH):
            scale = 0.18 * 2.0 ** (-12.0 + x * 0.25)
            row.extend([c * scale for c in colour] + [1.0])
        rows.append(row)
    return [v for row in reversed(rows) for v in row]


def main():
    root = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..")
    out = os.path.join(root, "tests", "data", "references")
    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    image = bpy.data.images.new("view_ramp", WIDTH, len(COLOURS), alpha=True, float_buffer=True)
    image.colorspace_settings.name = "Linear Rec.709"
    image.pixels.foreach_set(ramp_pixels())

    scene.render.image_settings.file_format = "OPEN_EXR"
    scene.render.image_settings.color_depth = "32"
    scene.render.image_settings.exr_codec = "ZIP"
    # save_render writes float formats linear, exactly as set (image.save() does not).
    image.save_render(os.path.join(out, "view_ramp.exr"), scene=scene)

    scene.display_settings.display_device = "sRGB"
    scene.view_settings.view_transform = "AgX"
    scene.view_settings.look = "None"
    scene.view_settings.exposure = 0.0
    scene.view_settings.gamma = 1.0
    scene.render.image_settings.file_format = "PNG"
    scene.render.image_settings.color_mode = "RGB"
    scene.render.image_settings.color_depth = "8"
    image.save_render(os.path.join(out, "view_ramp_agx.png"), scene=scene)
    print("wrote", os.path.join(out, "view_ramp.exr"), "and view_ramp_agx.png")
    return 0


if __name__ == "__main__":
    sys.exit(main())
