"""Export lighting test scenes and render their Cycles references: Blender's world as an HDR
environment texture, a sun under a sky-coloured world, and Blender lamps with a size.

Run from the repository root with the PyPI `bpy` package (Blender as a Python module):

    pip install bpy==5.0.1
    python3 tools/blender/make_lighting.py [--samples N] [--only NAME]

Materials are Blender's Principled BSDF without its specular layer (Lambertian in both
renderers: these scenes test the light, see `matte`); Cycles runs with make_references.py's
unbiased settings, but keeps the world.

- lighting_hdr: a floor and three spheres under an Environment Texture world whose
  latitude-longitude image, `tests/data/scenes/textures/lighting_sky.hdr`, this script computes
  (a sky gradient, a red patch on the horizon, a small sun). `.glb` (no world: gridtrace
  renders it with `--environment` on the same .hdr) and `.usdc` (a DomeLight).
- lighting_sun_sky: the same objects under a sun lamp (angle 0) and a constant sky-coloured
  world. `.glb` with the sun as KHR_lights_punctual (gridtrace adds the sky with
  `--environment R,G,B`) and `.usdc` (DistantLight + DomeLight).
- lighting_dof: lighting_sun_sky through a lens (f/0.4, focused on the grey sphere):
  Blender's camera depth of field as its USD exporter writes it. `.usdc` only.
- lighting_lamps: a square area lamp, a point lamp of radius 0.25 m and a spot lamp of
  radius 0.15 m (Soft Falloff on, Blender's default), in view (Cycles does not show lamps to
  the camera), black world. `.usdc` only: the glTF exporter drops area lamps and point radii.
- lighting_room_lamps: a room lit by a ceiling area lamp 5 cm under the ceiling, facing
  down, and Blender's default point lamp (radius 0.1 m, Soft Falloff) low over the floor:
  the ceiling is lit by light from the floor that passes the lamp (Cycles' lamps are not
  geometry), and the floor near the point lamp shows the soft falloff. `.usdc` only.
"""

import math
import os
import sys

import bpy
from mathutils import Vector

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from make_cornell import export, quad, reset, sphere  # noqa: E402
from make_principled import blender_default  # noqa: E402
from make_references import (  # noqa: E402
    SCENES, add_camera, export_usd, render_reference, scene_arguments,
)

SKY_HDR = os.path.join(SCENES, "textures", "lighting_sky.hdr")
SKY_COLOUR = (0.3, 0.45, 0.7)


def sky_radiance(direction):
    """Linear radiance of the procedural sky along a Blender (Z-up) world direction."""
    x, y, z = direction
    if z >= 0.0:
        r, g, b = 0.25 + 0.5 * z, 0.35 + 0.5 * z, 0.6 + 0.6 * z
    else:
        r, g, b = 0.12, 0.1, 0.08

    def near(azimuth_deg, elevation_deg, radius_deg):
        a, e = math.radians(azimuth_deg), math.radians(elevation_deg)
        c = (math.cos(e) * math.cos(a), math.cos(e) * math.sin(a), math.sin(e))
        return x * c[0] + y * c[1] + z * c[2] > math.cos(math.radians(radius_deg))

    if near(70.0, 10.0, 15.0):
        r, g, b = r + 1.5, g + 0.2, b + 0.1
    if near(-60.0, 40.0, 4.0):
        r, g, b = r + 60.0, g + 55.0, b + 45.0
    return r, g, b


def write_sky_hdr(width=128, height=64):
    """The sky as an equirectangular Radiance .hdr, in Blender's convention (centre column
    towards +X, u growing towards -Y; rows bottom to top in Blender's pixel buffer)."""
    image = bpy.data.images.new("lighting_sky", width, height, alpha=False, float_buffer=True)
    pixels = []
    for row in range(height):
        elevation = ((row + 0.5) / height - 0.5) * math.pi
        for col in range(width):
            azimuth = (0.5 - (col + 0.5) / width) * 2.0 * math.pi
            d = (math.cos(elevation) * math.cos(azimuth), math.cos(elevation) * math.sin(azimuth),
                 math.sin(elevation))
            pixels.extend(sky_radiance(d) + (1.0,))
    image.pixels = pixels
    os.makedirs(os.path.dirname(SKY_HDR), exist_ok=True)
    image.filepath_raw = SKY_HDR
    image.file_format = "HDR"
    image.save()
    print(f"wrote {SKY_HDR} ({os.path.getsize(SKY_HDR)} bytes)", flush=True)
    return bpy.data.images.load(SKY_HDR, check_existing=False)


def matte(name, colour):
    """Blender's Principled BSDF with no specular layer: Lambertian in Cycles and gridtrace.
    These scenes test the light; with Blender's default 4 % layer (or a metal) the two
    renderers' Principled models differ by 0.5-1 % on surfaces seen at grazing angles under
    a bright sky, which these noise-free images would measure instead."""
    return blender_default(name, colour, **{"Specular IOR Level": 0.0, "Roughness": 1.0})


def objects(scene):
    quad("Floor", [(-4, -4, 0), (4, -4, 0), (4, 4, 0), (-4, 4, 0)], matte("Floor", (0.8, 0.8, 0.8)))
    for name, colour, x in (("Grey", (0.8, 0.8, 0.8), -1.1), ("Blue", (0.15, 0.3, 0.8), 0.0),
                            ("Red", (0.7, 0.1, 0.08), 1.1)):
        sphere(name, matte(name, colour), 0.5, (x, 0.0, 0.5))
    add_camera(scene, (0.0, -5.0, 1.6), (0.0, 0.0, 0.9), 50.0)


def world(scene):
    w = bpy.data.worlds.new("World")
    w.use_nodes = True
    scene.world = w
    return w.node_tree


def build_hdr(scene):
    objects(scene)
    nodes = world(scene)
    env = nodes.nodes.new("ShaderNodeTexEnvironment")
    env.image = write_sky_hdr()
    env.interpolation = "Linear"
    nodes.links.new(env.outputs["Color"], nodes.nodes["Background"].inputs["Color"])


def build_sun_sky(scene):
    objects(scene)
    nodes = world(scene)
    nodes.nodes["Background"].inputs["Color"].default_value = SKY_COLOUR + (1.0,)
    nodes.nodes["Background"].inputs["Strength"].default_value = 1.0
    data = bpy.data.lights.new("Sun", "SUN")
    data.energy = 3.0
    data.angle = 0.0
    sun = bpy.data.objects.new("Sun", data)
    # From the front left, 50 degrees above the horizon.
    sun.rotation_euler = (math.radians(40.0), 0.0, math.radians(-35.0))
    scene.collection.objects.link(sun)


def build_lamps(scene):
    objects(scene)
    area = bpy.data.lights.new("Area", "AREA")
    area.shape = "SQUARE"
    area.size = 1.0
    area.energy = 150.0
    lamp = bpy.data.objects.new("Area", area)
    lamp.location = (-1.6, -1.2, 2.4)
    lamp.rotation_euler = (math.radians(30.0), math.radians(-30.0), 0.0)
    scene.collection.objects.link(lamp)
    point = bpy.data.lights.new("Point", "POINT")
    point.energy = 120.0
    point.shadow_soft_size = 0.25
    # Soft Falloff stays on, as Blender sets it: Cycles then lights with a disc facing each
    # shading point. USD has no word for it; gridtrace follows Blender's default for files
    # Blender wrote.
    bulb = bpy.data.objects.new("Point", point)
    bulb.location = (1.4, -0.6, 1.7)
    scene.collection.objects.link(bulb)
    # A spot lamp with a radius, its cone edge hard (blend 0): Cycles' smoothstep blend and
    # glTF's/USD's squared-linear one agree only there.
    spot = bpy.data.lights.new("Spot", "SPOT")
    spot.energy = 300.0
    spot.shadow_soft_size = 0.15
    spot.spot_size = math.radians(50.0)
    spot.spot_blend = 0.0
    cone = bpy.data.objects.new("Spot", spot)
    cone.location = (2.5, 1.0, 3.0)
    # Pointing down at the floor left of the spheres (a spot shines along its local -Z).
    direction = Vector((-3.5, -1.5, -3.0))
    cone.rotation_euler = direction.to_track_quat("-Z", "Y").to_euler()
    scene.collection.objects.link(cone)


def build_room_lamps(scene):
    grey, warm = matte("Walls", (0.8, 0.8, 0.8)), matte("Back", (0.8, 0.6, 0.4))
    quad("Floor", [(-2, -3, 0), (2, -3, 0), (2, 2, 0), (-2, 2, 0)], grey)
    quad("Ceiling", [(-2, -3, 2.5), (-2, 2, 2.5), (2, 2, 2.5), (2, -3, 2.5)], grey)
    quad("Back", [(-2, 2, 0), (2, 2, 0), (2, 2, 2.5), (-2, 2, 2.5)], warm)
    quad("Left", [(-2, -3, 0), (-2, 2, 0), (-2, 2, 2.5), (-2, -3, 2.5)], grey)
    quad("Right", [(2, -3, 0), (2, -3, 2.5), (2, 2, 2.5), (2, 2, 0)], grey)
    area = bpy.data.lights.new("CeilingLamp", "AREA")
    area.shape = "SQUARE"
    area.size = 0.8
    area.energy = 25.0
    lamp = bpy.data.objects.new("CeilingLamp", area)
    lamp.location = (0.0, 0.3, 2.45)
    scene.collection.objects.link(lamp)
    point = bpy.data.lights.new("Point", "POINT")
    point.energy = 5.0
    point.shadow_soft_size = 0.1
    bulb = bpy.data.objects.new("Point", point)
    bulb.location = (1.2, 1.0, 0.35)
    scene.collection.objects.link(bulb)
    add_camera(scene, (0.0, -2.8, 1.2), (0.0, 1.0, 1.4), 70.0)


def build_dof(scene):
    """The sun-and-sky scene through a lens: focused on the grey sphere, f/0.4, so the
    floor and the other spheres blur (depth of field is a camera setting Blender's USD
    exporter writes as fStop and focusDistance)."""
    build_sun_sky(scene)
    camera = scene.camera
    camera.data.dof.use_dof = True
    camera.data.dof.aperture_fstop = 0.4
    camera.data.dof.focus_distance = (Vector((-1.1, 0.0, 0.5)) - camera.location).length


# name -> (builder, total reference samples, formats exported)
SCENE_TABLE = {
    "lighting_hdr": (build_hdr, 2048, ("glb", "usdc")),
    "lighting_sun_sky": (build_sun_sky, 2048, ("glb", "usdc")),
    "lighting_lamps": (build_lamps, 2048, ("usdc",)),
    "lighting_room_lamps": (build_room_lamps, 2048, ("usdc",)),
    "lighting_dof": (build_dof, 2048, ("usdc",)),
}


def main():
    args = scene_arguments(__doc__.splitlines()[0])
    for name, (build, samples, formats) in SCENE_TABLE.items():
        if args.only and name not in args.only:
            continue
        scene = reset()
        build(scene)
        if "glb" in formats:
            export(os.path.join(SCENES, f"{name}.glb"), lights=True)
        if "usdc" in formats:
            export_usd(os.path.join(SCENES, f"{name}.usdc"))
        if not args.export_only:
            render_reference(scene, name, args.samples or samples, keep_world=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
