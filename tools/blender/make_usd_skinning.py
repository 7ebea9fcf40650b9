"""A Blender armature animation through Blender's USD exporter: a bending column skinned to
a two-bone armature, exported once with its skeleton and animation (UsdSkel), and once per
checked frame as the mesh Blender itself deforms (armature applied, no skeleton). gridtrace
skins the first at `--frame F`; `tests/usd_pipeline.rs` compares with the second.

    /tmp/bpyenv/bin/python tools/blender/make_usd_skinning.py tests/data/scenes/usd_pipeline
"""

import math
import os
import sys

import bpy

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from make_gltf_animation import skinned_column  # noqa: E402

FRAMES = (1, 9, 17)


def build():
    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    scene.frame_start, scene.frame_end = 1, 17
    _, rig = skinned_column("Column", (0.0, 0.0, 0.0), vertices=8, cuts=6)
    bpy.ops.object.mode_set(mode="POSE")
    for frame, bend in ((1, 0.0), (9, 50.0), (17, -30.0)):
        scene.frame_set(frame)
        for name, angle in (("Lower", 0.4 * bend), ("Upper", bend)):
            bone = rig.pose.bones[name]
            bone.rotation_mode = "XYZ"
            bone.rotation_euler = (math.radians(angle), 0.0, math.radians(0.3 * angle))
            bone.keyframe_insert("rotation_euler", frame=frame)
    bpy.ops.object.mode_set(mode="OBJECT")


def main():
    out = sys.argv[-1]
    build()
    scene = bpy.context.scene
    path = os.path.join(out, "skinned.usdc")
    if os.path.exists(path):
        os.remove(path)  # USD appends to an existing crate file
    bpy.ops.wm.usd_export(filepath=path, export_animation=True, export_armatures=True,
                          export_materials=False)
    print(f"wrote {path} ({os.path.getsize(path)} bytes)")
    for frame in FRAMES:
        scene.frame_set(frame)
        path = os.path.join(out, f"skinned_frame_{frame}.usdc")
        if os.path.exists(path):
            os.remove(path)
        bpy.ops.wm.usd_export(filepath=path, export_animation=False, export_armatures=False,
                              export_materials=False, selected_objects_only=False)
        print(f"wrote {path} ({os.path.getsize(path)} bytes)")


if __name__ == "__main__":
    main()
