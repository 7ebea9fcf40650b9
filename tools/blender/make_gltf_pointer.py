"""A cube that moves while its material's Emission Strength is animated, exported by
Blender's glTF exporter with its experimental "Animation Pointer" option, which writes the
material animation as `KHR_animation_pointer` channels (no node) beside the cube's node
channel.

    python3 tools/blender/make_gltf_pointer.py

Writes `tests/data/scenes/gltf_animation/pointer.glb`: the cube's x goes from 0.1 at frame
1 to 2.0 at frame 20, its Emission Strength from 0 to 5.
"""

import os

import bpy

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
OUT = os.path.join(ROOT, "tests", "data", "scenes", "gltf_animation", "pointer.glb")


def main():
    bpy.ops.wm.read_factory_settings(use_empty=True)
    bpy.ops.mesh.primitive_cube_add(size=1.0)
    cube = bpy.context.active_object
    cube.name = "Cube"
    material = bpy.data.materials.new("Glow")
    material.use_nodes = True
    strength = material.node_tree.nodes["Principled BSDF"].inputs["Emission Strength"]
    cube.data.materials.append(material)
    for frame, x, glow in ((1, 0.1, 0.0), (20, 2.0, 5.0)):
        cube.location.x = x
        cube.keyframe_insert("location", frame=frame)
        strength.default_value = glow
        strength.keyframe_insert("default_value", frame=frame)
    bpy.ops.export_scene.gltf(filepath=OUT, export_format="GLB", export_pointer_animation=True,
                              export_animation_mode="SCENE")
    print(f"wrote {OUT} ({os.path.getsize(OUT)} bytes)")


if __name__ == "__main__":
    main()
