"""Build an animated scene in Blender and export it with Blender's glTF exporter, with
Blender's own evaluation of chosen frames beside it.

Run from the repository root with the PyPI `bpy` package (Blender as a Python module):

    pip install bpy==5.0.1
    python3 tools/blender/make_gltf_animation.py

Writes `tests/data/scenes/gltf_animation/animated.glb` and, for frames 1, 7, 13 and 24,
`frame_F.glb`. Over frames 1–24 (Bezier keys, which the exporter bakes one sample per
frame):

- object animation: a cube moves, turns and grows;
- shape keys: a subdivided plane whose "Bump" key goes from 0 to 1 and back;
- an armature: a cylinder skinned to a chain of two bones, the upper bending 90°;

with a camera and a sun that do not move. `animated.glb` is exported with the exporter's
default animation mode, one glTF animation per action (three here, on different nodes;
keyframe times are frame ÷ 24 s, Blender's rule); each `frame_F.glb` is the
same scene exported at frame F with animation, skins and shape keys off and modifiers
applied and the current frame as the rest state: the scene as Blender evaluates it at that
frame, which
`tests/gltf_animation.rs` compares with gridtrace's own evaluation of `animated.glb`.
"""

import math
import os

import bpy

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
OUT = os.path.join(ROOT, "tests", "data", "scenes", "gltf_animation")
FRAMES = [1, 7, 13, 24]


def key(data_block, prop, frame, value):
    setattr(data_block, prop, value)
    data_block.keyframe_insert(prop, frame=frame)


def object_animation():
    bpy.ops.mesh.primitive_cube_add(size=0.6, location=(-2.0, 0.0, 0.3))
    cube = bpy.context.active_object
    cube.name = "Mover"
    key(cube, "location", 1, (-2.0, 0.0, 0.3))
    key(cube, "location", 24, (-2.0, 1.5, 1.2))
    key(cube, "rotation_euler", 1, (0.0, 0.0, 0.0))
    key(cube, "rotation_euler", 24, (0.4, 0.0, math.radians(120)))
    key(cube, "scale", 1, (1.0, 1.0, 1.0))
    key(cube, "scale", 24, (1.5, 0.8, 1.2))


def shape_keys():
    bpy.ops.mesh.primitive_grid_add(x_subdivisions=8, y_subdivisions=8, size=1.6, location=(0.0, 0.0, 0.0))
    grid = bpy.context.active_object
    grid.name = "Sheet"
    grid.shape_key_add(name="Basis")
    bump = grid.shape_key_add(name="Bump")
    # A bump over the middle only, so most vertices do not move (a sparse target).
    for point in bump.data:
        r = math.hypot(point.co.x, point.co.y)
        if r < 0.45:
            point.co.z += 0.6 * math.cos(r / 0.45 * math.pi / 2) ** 2
    key(bump, "value", 1, 0.0)
    key(bump, "value", 13, 1.0)
    key(bump, "value", 24, 0.3)


def skinned_column(name, location, vertices, cuts):
    """An open column 2 m tall standing at `location` (no caps, whose subdivided fans would
    hold zero-area triangles), `cuts` rings along its height so a bend is smooth, skinned
    with automatic weights to an armature "Rig" of two bones, Lower and Upper."""
    x, y, z = location
    bpy.ops.mesh.primitive_cylinder_add(
        vertices=vertices, radius=0.2, depth=2.0, end_fill_type="NOTHING", location=(x, y, z + 1.0)
    )
    tube = bpy.context.active_object
    tube.name = name
    bpy.ops.object.mode_set(mode="EDIT")
    bpy.ops.mesh.select_all(action="SELECT")
    bpy.ops.mesh.subdivide(number_cuts=cuts)
    bpy.ops.object.mode_set(mode="OBJECT")
    bpy.ops.object.armature_add(location=location)
    rig = bpy.context.active_object
    rig.name = "Rig"
    bpy.ops.object.mode_set(mode="EDIT")
    lower = rig.data.edit_bones[0]
    lower.name = "Lower"
    lower.head, lower.tail = (0.0, 0.0, 0.0), (0.0, 0.0, 1.0)
    upper = rig.data.edit_bones.new("Upper")
    upper.head, upper.tail = (0.0, 0.0, 1.0), (0.0, 0.0, 2.0)
    upper.parent = lower
    upper.use_connect = True
    bpy.ops.object.mode_set(mode="OBJECT")
    bpy.ops.object.select_all(action="DESELECT")
    tube.select_set(True)
    rig.select_set(True)
    bpy.context.view_layer.objects.active = rig
    bpy.ops.object.parent_set(type="ARMATURE_AUTO")
    return tube, rig


def armature():
    _, rig = skinned_column("Tube", (2.0, 0.0, 0.0), vertices=12, cuts=8)
    bone = rig.pose.bones["Upper"]
    bone.rotation_mode = "XYZ"
    key(bone, "rotation_euler", 1, (0.0, 0.0, 0.0))
    key(bone, "rotation_euler", 24, (math.radians(90), 0.0, 0.0))


def camera_and_sun():
    bpy.ops.object.camera_add(location=(0.0, -7.5, 3.0), rotation=(math.radians(72), 0.0, 0.0))
    bpy.context.scene.camera = bpy.context.active_object
    bpy.ops.object.light_add(type="SUN", rotation=(math.radians(40), math.radians(20), 0.0))
    bpy.context.active_object.data.energy = 3.0


def export(path, animated):
    common = dict(filepath=path, export_format="GLB", export_cameras=True, export_lights=True, export_yup=True)
    if animated:
        bpy.ops.export_scene.gltf(
            **common,
            export_animations=True,
            export_skins=True,
            export_morph=True,
        )
    else:
        bpy.ops.export_scene.gltf(
            **common,
            export_animations=False,
            export_skins=False,
            export_morph=False,
            export_apply=True,
            export_current_frame=True,
        )


def main():
    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    scene.render.fps = 24
    scene.frame_start = 1
    scene.frame_end = 24
    object_animation()
    shape_keys()
    armature()
    camera_and_sun()
    os.makedirs(OUT, exist_ok=True)
    scene.frame_set(1)
    export(os.path.join(OUT, "animated.glb"), animated=True)
    for frame in FRAMES:
        scene.frame_set(frame)
        depsgraph = bpy.context.evaluated_depsgraph_get()
        # The exporter writes a mesh with shape keys in its basis shape when morph targets
        # are off, so each mesh is replaced by Blender's evaluation of it at this frame
        # (shape keys and the armature applied), then restored.
        originals = {}
        for obj in [o for o in scene.objects if o.type == "MESH"]:
            evaluated = bpy.data.meshes.new_from_object(obj.evaluated_get(depsgraph))
            originals[obj.name] = (obj.data, [(m.name, m.object) for m in obj.modifiers if m.type == "ARMATURE"])
            obj.data = evaluated
            for modifier in list(obj.modifiers):
                obj.modifiers.remove(modifier)
        export(os.path.join(OUT, f"frame_{frame}.glb"), animated=False)
        for name, (data, armatures) in originals.items():
            obj = scene.objects[name]
            obj.data = data
            for modifier_name, rig in armatures:
                obj.modifiers.new(modifier_name, "ARMATURE").object = rig


if __name__ == "__main__":
    main()
