"""Build the bundled Cornell box scenes in Blender and export them with Blender's own glTF exporter.

Run from the repository root with the PyPI `bpy` package (Blender as a Python module):

    pip install bpy==5.0.1
    python3 tools/blender/make_cornell.py

Writes `assets/cornell_box.glb` (two diffuse boxes, also as `assets/cornell_box.usdc` and
`tests/data/scenes/cornell_box.usdz` through Blender's USD exporter) and `assets/cornell_spheres.glb` (a mirror sphere and a glass sphere). Blender is Z-up; the exporter converts to glTF's Y-up.
The wall colours are the usual Cornell box reflectances; the light is an emissive quad that
fills an opening in the ceiling, exported through KHR_materials_emissive_strength.
"""

import math
import os
import sys

import bpy

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
ASSETS = os.path.join(ROOT, "assets")
TEST_SCENES = os.path.join(ROOT, "tests", "data", "scenes")

WHITE = (0.725, 0.71, 0.68)
RED = (0.63, 0.065, 0.05)
GREEN = (0.14, 0.45, 0.091)
LIGHT_COLOUR = (1.0, 0.85, 0.6)
LIGHT_STRENGTH = 12.0


def reset():
    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    scene.render.resolution_x = 512
    scene.render.resolution_y = 512
    return scene


def principled(name, colour, metallic=0.0, roughness=1.0, transmission=0.0, ior=1.5,
               emission=None, strength=0.0, specular=0.0):
    """A Principled BSDF material; its inputs are what Blender's glTF exporter reads.

    "Specular IOR Level" defaults to 0 here (Blender's own default is 0.5): these scenes are
    the ideal-material ones, whose Cycles references replace the Principled BSDF by a pure
    Diffuse BSDF, and level 0 exports as `KHR_materials_specular.specularFactor` 0 (USD
    `specular` 0), which is exactly that Lambertian for gridtrace too."""
    mat = bpy.data.materials.new(name)
    mat.use_nodes = True
    bsdf = mat.node_tree.nodes["Principled BSDF"]
    bsdf.inputs["Specular IOR Level"].default_value = specular
    bsdf.inputs["Base Color"].default_value = (*colour, 1.0)
    bsdf.inputs["Metallic"].default_value = metallic
    bsdf.inputs["Roughness"].default_value = roughness
    bsdf.inputs["Transmission Weight"].default_value = transmission
    bsdf.inputs["IOR"].default_value = ior
    if emission is not None:
        bsdf.inputs["Emission Color"].default_value = (*emission, 1.0)
        bsdf.inputs["Emission Strength"].default_value = strength
    return mat


def mesh_object(name, verts, faces, material, smooth=False):
    mesh = bpy.data.meshes.new(name)
    mesh.from_pydata(verts, [], faces)
    mesh.update()
    for poly in mesh.polygons:
        poly.use_smooth = smooth
    mesh.materials.append(material)
    obj = bpy.data.objects.new(name, mesh)
    bpy.context.scene.collection.objects.link(obj)
    return obj


def quad(name, corners, material):
    """A single quad; corners are listed so that the normal faces into the box."""
    return mesh_object(name, corners, [(0, 1, 2, 3)], material)


def box(name, material, size, location, angle_deg):
    """An axis-aligned box of `size` (x, y, z) standing on the floor, turned about Z."""
    sx, sy, sz = (s / 2 for s in size)
    verts = [(x, y, z) for z in (0.0, 2 * sz) for y in (-sy, sy) for x in (-sx, sx)]
    faces = [(0, 2, 3, 1), (4, 5, 7, 6), (0, 1, 5, 4), (2, 6, 7, 3), (0, 4, 6, 2), (1, 3, 7, 5)]
    obj = mesh_object(name, verts, faces, material)
    obj.location = location
    obj.rotation_euler = (0.0, 0.0, math.radians(angle_deg))
    return obj


def sphere(name, material, radius, location):
    bpy.ops.mesh.primitive_uv_sphere_add(segments=48, ring_count=24, radius=radius, location=location)
    obj = bpy.context.active_object
    obj.name = name
    bpy.ops.object.shade_smooth()
    obj.data.materials.append(material)
    return obj


def cornell_shell(scene):
    """Floor, ceiling, back wall, red left wall, green right wall, ceiling light and camera."""
    white = principled("White", WHITE)
    red = principled("Red", RED)
    green = principled("Green", GREEN)
    light = principled("Light", (0.78, 0.78, 0.78), emission=LIGHT_COLOUR, strength=LIGHT_STRENGTH)
    quad("Floor", [(-1, -1, 0), (1, -1, 0), (1, 1, 0), (-1, 1, 0)], white)
    # The ceiling is a ring around an opening that the light fills: a light hanging below
    # a closed ceiling would light a hidden strip above itself, which paths find only by
    # chance (fireflies), and Cycles emits from both faces of a mesh light.
    s = 0.25
    ring = [
        [(-1, -1, 2), (-1, 1, 2), (-s, 1, 2), (-s, -1, 2)],
        [(s, -1, 2), (s, 1, 2), (1, 1, 2), (1, -1, 2)],
        [(-s, -1, 2), (-s, -s, 2), (s, -s, 2), (s, -1, 2)],
        [(-s, s, 2), (-s, 1, 2), (s, 1, 2), (s, s, 2)],
    ]
    mesh_object("Ceiling", [v for q in ring for v in q], [(4 * i, 4 * i + 1, 4 * i + 2, 4 * i + 3) for i in range(4)], white)
    quad("BackWall", [(-1, 1, 0), (1, 1, 0), (1, 1, 2), (-1, 1, 2)], white)
    quad("LeftWall", [(-1, -1, 0), (-1, 1, 0), (-1, 1, 2), (-1, -1, 2)], red)
    quad("RightWall", [(1, -1, 0), (1, -1, 2), (1, 1, 2), (1, 1, 0)], green)
    quad("CeilingLight", [(-s, -s, 2), (-s, s, 2), (s, s, 2), (s, -s, 2)], light)

    cam_data = bpy.data.cameras.new("Camera")
    cam_data.lens_unit = "FOV"
    cam_data.angle = math.radians(39.3)
    cam = bpy.data.objects.new("Camera", cam_data)
    cam.location = (0.0, -3.9, 1.0)
    cam.rotation_euler = (math.radians(90.0), 0.0, 0.0)
    scene.collection.objects.link(cam)
    scene.camera = cam
    return white


def export(path, lights=False):
    bpy.ops.export_scene.gltf(
        filepath=path,
        export_format="GLB",
        export_cameras=True,
        export_lights=lights,
        export_yup=True,
        export_apply=True,
    )
    print(f"wrote {path} ({os.path.getsize(path)} bytes)")


def build_cornell_box(scene):
    """The classic box: two white blocks turned against each other."""
    white = cornell_shell(scene)
    box("TallBox", white, (0.6, 0.6, 1.2), (-0.33, 0.3, 0.0), 17.0)
    box("ShortBox", white, (0.6, 0.6, 0.6), (0.35, -0.3, 0.0), -17.0)


def build_cornell_spheres(scene):
    """The box with an ideal mirror sphere and an ideal glass sphere."""
    cornell_shell(scene)
    mirror = principled("Mirror", (0.95, 0.95, 0.95), metallic=1.0, roughness=0.0)
    glass = principled("Glass", (1.0, 1.0, 1.0), roughness=0.0, transmission=1.0, ior=1.5)
    sphere("MirrorSphere", mirror, 0.4, (-0.45, 0.35, 0.4))
    sphere("GlassSphere", glass, 0.4, (0.45, -0.3, 0.4))


def main():
    os.makedirs(ASSETS, exist_ok=True)
    for name, build in (("cornell_box", build_cornell_box), ("cornell_spheres", build_cornell_spheres)):
        build(reset())
        export(os.path.join(ASSETS, f"{name}.glb"))
        if name == "cornell_box":
            # The same scene through Blender's USD exporter (Z-up, metres). The spheres scene
            # is not exported: Blender's USD exporter writes no transmission, so its glass
            # would arrive opaque.
            for path in (os.path.join(ASSETS, f"{name}.usdc"), os.path.join(TEST_SCENES, f"{name}.usdz")):
                bpy.ops.wm.usd_export(filepath=path)
                print(f"wrote {path} ({os.path.getsize(path)} bytes)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
