"""Export a product model whose only emitters are small details: a toy car (a grey body,
dark wheels) with two emissive headlights, a camera, and no lamps and no world, as a user
exports a downloaded model from Blender.

Run from the repository root with the PyPI `bpy` package (Blender as a Python module):

    python3 tools/blender/make_product.py

Writes `tests/data/scenes/product_emitters.glb` and `.usdc` (tests/environment_cli.rs).
"""

import os
import sys

import bpy

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from make_cornell import box, export, principled, reset  # noqa: E402
from make_references import SCENES, add_camera, export_usd  # noqa: E402


def build_product(scene):
    body = principled("Body", (0.6, 0.62, 0.65), roughness=0.4, specular=0.5)
    tyre = principled("Tyre", (0.03, 0.03, 0.03), roughness=0.8)
    lamp = principled("Headlight", (0.0, 0.0, 0.0), emission=(1.0, 0.95, 0.8), strength=5.0)
    box("Body", body, (2.0, 0.9, 0.5), (0.0, 0.0, 0.2), 0.0)
    box("Cabin", body, (1.0, 0.8, 0.4), (-0.2, 0.0, 0.7), 0.0)
    for x in (-0.65, 0.65):
        for y in (-0.5, 0.5):
            bpy.ops.mesh.primitive_cylinder_add(vertices=16, radius=0.22, depth=0.15,
                                                location=(x, y, 0.22), rotation=(1.5708, 0.0, 0.0))
            bpy.context.active_object.data.materials.append(tyre)
    for y in (-0.3, 0.3):
        box("Headlight", lamp, (0.02, 0.15, 0.08), (1.0, y, 0.5), 0.0)
    add_camera(scene, (4.0, -3.5, 2.2), (0.0, 0.0, 0.4), 25.0)


def main():
    scene = reset()
    build_product(scene)
    export(os.path.join(SCENES, "product_emitters.glb"))
    export_usd(os.path.join(SCENES, "product_emitters.usdc"))
    return 0


if __name__ == "__main__":
    sys.exit(main())
