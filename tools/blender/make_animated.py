"""Build a small animated scene in Blender and export it with Blender's USD exporter.

Run from the repository root with the PyPI `bpy` package (Blender as a Python module):

    pip install bpy==5.0.1
    python3 tools/blender/make_animated.py

Writes `tests/data/scenes/animated.usdc`: over frames 1–11 (linear keys), a cube slides 2 m
along Blender's +X, the camera's focal length goes from 50 mm to 25 mm and a point light's
power from 100 W to 300 W, under a still emissive panel. Blender's USD exporter writes
every animated attribute as time samples, one per frame; `tests/usd_loader.rs` reads it at
several frames with `--frame`.
"""

import os

import bpy

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
OUT = os.path.join(ROOT, "tests", "data", "scenes", "animated.usdc")


def animate(data_block, prop, first, last):
    """Keys `prop` to `first` at frame 1 and `last` at frame 11, linearly in between, so
    frame 6 is exactly halfway."""
    setattr(data_block, prop, first)
    data_block.keyframe_insert(prop, frame=1)
    setattr(data_block, prop, last)
    data_block.keyframe_insert(prop, frame=11)
    action = data_block.animation_data.action
    # Blender 4.4+ keeps F-curves in layered actions; older ones directly on the action.
    curves = []
    if hasattr(action, "layers"):
        for layer in action.layers:
            for strip in layer.strips:
                for bag in strip.channelbags:
                    curves.extend(bag.fcurves)
    else:
        curves.extend(action.fcurves)
    for curve in curves:
        for key in curve.keyframe_points:
            key.interpolation = "LINEAR"


def main():
    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    scene.frame_start = 1
    scene.frame_end = 11

    bpy.ops.mesh.primitive_cube_add(size=0.5, location=(0.0, 0.0, 0.25))
    cube = bpy.context.active_object
    cube.name = "Mover"
    animate(cube, "location", (0.0, 0.0, 0.25), (2.0, 0.0, 0.25))

    bpy.ops.mesh.primitive_plane_add(size=1.0, location=(1.0, 0.0, 3.0))
    panel = bpy.context.active_object
    panel.name = "Panel"
    glow = bpy.data.materials.new("Glow")
    glow.use_nodes = True
    bsdf = glow.node_tree.nodes["Principled BSDF"]
    bsdf.inputs["Emission Color"].default_value = (1.0, 1.0, 1.0, 1.0)
    bsdf.inputs["Emission Strength"].default_value = 5.0
    panel.data.materials.append(glow)

    light_data = bpy.data.lights.new("Lamp", type="POINT")
    light_data.shadow_soft_size = 0.0
    animate(light_data, "energy", 100.0, 300.0)
    lamp = bpy.data.objects.new("Lamp", light_data)
    lamp.location = (0.0, -1.0, 2.0)
    scene.collection.objects.link(lamp)

    camera_data = bpy.data.cameras.new("Camera")
    camera_data.sensor_fit = "VERTICAL"
    camera_data.sensor_height = 24.0
    animate(camera_data, "lens", 50.0, 25.0)
    camera = bpy.data.objects.new("Camera", camera_data)
    camera.location = (1.0, -8.0, 1.0)
    camera.rotation_euler = (1.5708, 0.0, 0.0)
    scene.collection.objects.link(camera)
    scene.camera = camera

    bpy.ops.wm.usd_export(filepath=OUT, export_animation=True)
    print(f"wrote {OUT}")


if __name__ == "__main__":
    main()
