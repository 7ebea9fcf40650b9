"""Export the reference scenes and render their reference images with Blender Cycles.

Run from the repository root with the PyPI `bpy` package (Blender as a Python module):

    pip install bpy==5.0.1
    python3 tools/blender/make_references.py [--samples N] [--only NAME]

For every scene this writes the glTF file gridtrace renders (the bundled Cornell scenes stay in
`assets/`, the others go to `tests/data/scenes/`) and two Cycles renders with different seeds,
`tests/data/references/<name>_a.exr` and `_b.exr`, each with half the samples. Their mean is the
reference; their difference measures the reference's own noise (tests/reference_images.rs).

Before rendering, every Principled BSDF is replaced by the node that is gridtrace's model of it:
a Diffuse BSDF (Lambertian: the scenes' Principled BSDFs set Specular IOR Level 0, exported as
KHR_materials_specular.specularFactor 0), a sharp Glossy BSDF (ideal mirror; gridtrace adds
Schlick's Fresnel, a rim difference of at most (1 - F0)(1 - cos)^5), a sharp Glass BSDF (ideal
dielectric), plus an Emission node for emitters.
Cycles runs unbiased: box pixel filter one pixel wide, no clamping, no denoising, no adaptive
sampling, no glossy filter, caustics on, 64 bounces, black world.
"""

import argparse
import math
import os
import sys
import time

import bpy
from mathutils import Vector

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import make_cornell  # noqa: E402  (shares the Cornell scene builders)
from make_cornell import (  # noqa: E402
    box, build_cornell_box, build_cornell_spheres, export, mesh_object, principled, quad, reset, sphere,
)

ROOT = make_cornell.ROOT
SCENES = os.path.join(ROOT, "tests", "data", "scenes")
REFERENCES = os.path.join(ROOT, "tests", "data", "references")
SIZE = 128


def add_camera(scene, location, target, fov_deg):
    data = bpy.data.cameras.new("Camera")
    data.lens_unit = "FOV"
    data.angle = math.radians(fov_deg)
    cam = bpy.data.objects.new("Camera", data)
    cam.location = location
    direction = [t - l for t, l in zip(target, location)]
    cam.rotation_euler = Vector(direction).to_track_quat("-Z", "Y").to_euler()
    scene.collection.objects.link(cam)
    scene.camera = cam


def build_caustic(scene):
    """A glass sphere over a diffuse floor under one light: the caustic below the sphere is
    reached only through two refractions, and the floor beyond the light's cone is lit only by
    light passing the sphere."""
    floor = principled("Floor", (0.8, 0.8, 0.8))
    wall = principled("Wall", (0.35, 0.45, 0.7))
    glass = principled("Glass", (1.0, 1.0, 1.0), roughness=0.0, transmission=1.0, ior=1.5)
    light = principled("Light", (0.0, 0.0, 0.0), emission=(1.0, 0.95, 0.9), strength=15.0)
    quad("Floor", [(-3, -3, 0), (3, -3, 0), (3, 3, 0), (-3, 3, 0)], floor)
    quad("Wall", [(-3, 1.5, 0), (3, 1.5, 0), (3, 1.5, 3), (-3, 1.5, 3)], wall)
    sphere("GlassSphere", glass, 0.5, (0.0, 0.0, 0.65))
    s = 0.4
    # Wound so that the emitting front face looks down at the floor.
    quad("Light", [(-s, -s, 3), (-s, s, 3), (s, s, 3), (s, -s, 3)], light)
    add_camera(scene, (0.0, -4.0, 2.0), (0.0, 0.0, 0.3), 45.0)


def build_coloured_lights(scene):
    """A closed white room lit by two coloured strip lights on the back wall and one small,
    bright white light behind the camera, out of view, which dominates the room's power."""
    white = principled("White", (0.75, 0.75, 0.75))
    blue_box = principled("BlueBox", (0.2, 0.3, 0.75))
    red = principled("RedLight", (0.0, 0.0, 0.0), emission=(1.0, 0.2, 0.05), strength=8.0)
    blue = principled("BlueLight", (0.0, 0.0, 0.0), emission=(0.1, 0.3, 1.0), strength=8.0)
    small = principled("SmallLight", (0.0, 0.0, 0.0), emission=(1.0, 1.0, 1.0), strength=300.0)
    # One-sided lights (glTF doubleSided: false): a double-sided light this close to a wall
    # would light a hidden sliver of the wall behind it, which paths find only by chance.
    for light in (red, blue, small):
        light.use_backface_culling = True
    w, d, h = 2.0, 2.0, 2.5
    quad("Floor", [(-w, -d, 0), (w, -d, 0), (w, d, 0), (-w, d, 0)], white)
    quad("Ceiling", [(-w, -d, h), (-w, d, h), (w, d, h), (w, -d, h)], white)
    quad("BackWall", [(-w, d, 0), (w, d, 0), (w, d, h), (-w, d, h)], white)
    quad("FrontWall", [(-w, -d, 0), (-w, -d, h), (w, -d, h), (w, -d, 0)], white)
    quad("LeftWall", [(-w, -d, 0), (-w, d, 0), (-w, d, h), (-w, -d, h)], white)
    quad("RightWall", [(w, -d, 0), (w, -d, h), (w, d, h), (w, d, 0)], white)
    y = d - 0.01
    quad("RedStrip", [(-1.5, y, 1.6), (-0.3, y, 1.6), (-0.3, y, 1.75), (-1.5, y, 1.75)], red)
    quad("BlueStrip", [(0.3, y, 0.6), (1.5, y, 0.6), (1.5, y, 0.75), (0.3, y, 0.75)], blue)
    s = 0.05
    z = h - 0.01
    quad("SmallLight", [(-s, -1.6 - s, z), (-s, -1.6 + s, z), (s, -1.6 + s, z), (s, -1.6 - s, z)], small)
    box("Box", blue_box, (0.8, 0.8, 0.8), (-0.6, 0.2, 0.0), 30.0)
    add_camera(scene, (-1.2, -1.8, 1.4), (0.4, 1.0, 0.7), 60.0)


def add_light(name, kind, energy, location, colour=(1.0, 1.0, 1.0), rotation=(0.0, 0.0, 0.0), **settings):
    """A Blender light as a true point (radius 0, no soft falloff) or an exact sun (angle 0),
    which is what glTF's punctual lights are."""
    data = bpy.data.lights.new(name, kind)
    data.energy = energy
    data.color = colour
    if kind == "SUN":
        data.angle = 0.0
    else:
        data.shadow_soft_size = 0.0
        data.use_soft_falloff = False
    for key, value in settings.items():
        setattr(data, key, value)
    obj = bpy.data.objects.new(name, data)
    obj.location = location
    obj.rotation_euler = [math.radians(a) for a in rotation]
    bpy.context.scene.collection.objects.link(obj)
    return obj


def build_punctual_lights(scene):
    """A point light, a hard-edged spot light and a sun, with a small emissive panel: exported
    in Blender's Standard lighting mode, their balance with the panel is Blender's."""
    floor = principled("Floor", (0.8, 0.8, 0.8))
    wall = principled("Wall", (0.5, 0.55, 0.7))
    red = principled("Red", (0.7, 0.15, 0.1))
    panel = principled("Panel", (0.0, 0.0, 0.0), emission=(0.3, 1.0, 0.4), strength=6.0)
    panel.use_backface_culling = True
    quad("Floor", [(-3, -3, 0), (3, -3, 0), (3, 3, 0), (-3, 3, 0)], floor)
    quad("BackWall", [(-3, 2, 0), (3, 2, 0), (3, 2, 3), (-3, 2, 3)], wall)
    quad("LeftWall", [(-2, -3, 0), (-2, 3, 0), (-2, 3, 3), (-2, -3, 3)], red)
    quad("Panel", [(0.6, 1.99, 1.2), (1.4, 1.99, 1.2), (1.4, 1.99, 1.6), (0.6, 1.99, 1.6)], panel)
    box("Box", floor, (0.6, 0.6, 0.6), (0.7, 0.3, 0.0), 25.0)
    sphere("Ball", principled("Ball", (0.3, 0.5, 0.8)), 0.4, (-0.7, 0.2, 0.4))
    add_light("Point", "POINT", 60.0, (0.9, -0.6, 1.6), colour=(1.0, 0.8, 0.6))
    add_light("Spot", "SPOT", 200.0, (-0.8, 0.3, 2.6), spot_size=math.radians(50.0), spot_blend=0.0)
    add_light("Sun", "SUN", 1.5, (0.0, 0.0, 5.0), colour=(0.8, 0.9, 1.0), rotation=(35.0, 0.0, 40.0))
    add_camera(scene, (0.0, -5.0, 2.2), (0.0, 0.0, 0.6), 45.0)


def make_image(name, size, pixel, colorspace="sRGB"):
    """A packed 8-bit RGBA image (Blender rows run bottom to top), exported as PNG."""
    image = bpy.data.images.new(name, size, size, alpha=True)
    image.colorspace_settings.name = colorspace
    pixels = []
    for row in range(size):
        for col in range(size):
            pixels.extend(pixel((col + 0.5) / size, (row + 0.5) / size))
    image.pixels = pixels
    image.pack()
    return image


def textured(name, image, link_to="Base Color", colour=(1.0, 1.0, 1.0), mapping=None, normal_strength=None,
             emission_strength=None, cutout=False):
    """A Principled BSDF fed by an image texture, the way a Blender user wires one."""
    mat = principled(name, colour)
    nodes, links = mat.node_tree.nodes, mat.node_tree.links
    bsdf = nodes["Principled BSDF"]
    tex = nodes.new("ShaderNodeTexImage")
    tex.image = image
    # Closest (glTF magFilter NEAREST): Cycles filters 8-bit sRGB images before decoding them,
    # gridtrace (like GPUs and the glTF specification) decodes first, so bilinear edges would
    # differ by design, not by error. Bilinear filtering has its own unit tests.
    tex.interpolation = "Closest"
    tex.extension = "REPEAT"
    if mapping is not None:
        coords = nodes.new("ShaderNodeTexCoord")
        node = nodes.new("ShaderNodeMapping")
        node.inputs["Location"].default_value = mapping["location"]
        node.inputs["Rotation"].default_value = mapping["rotation"]
        node.inputs["Scale"].default_value = mapping["scale"]
        links.new(coords.outputs["UV"], node.inputs["Vector"])
        links.new(node.outputs["Vector"], tex.inputs["Vector"])
    if normal_strength is not None:
        normal_map = nodes.new("ShaderNodeNormalMap")
        normal_map.inputs["Strength"].default_value = normal_strength
        links.new(tex.outputs["Color"], normal_map.inputs["Color"])
        links.new(normal_map.outputs["Normal"], bsdf.inputs["Normal"])
    elif emission_strength is not None:
        links.new(tex.outputs["Color"], bsdf.inputs["Emission Color"])
        bsdf.inputs["Emission Strength"].default_value = emission_strength
    else:
        links.new(tex.outputs["Color"], bsdf.inputs[link_to])
    if cutout:
        # Blender's glTF exporter writes alphaMode MASK (cutoff 0.5) for a rounded alpha.
        round_node = nodes.new("ShaderNodeMath")
        round_node.operation = "ROUND"
        links.new(tex.outputs["Alpha"], round_node.inputs[0])
        links.new(round_node.outputs["Value"], bsdf.inputs["Alpha"])
    return mat


def build_textured(scene):
    """Textures as Blender users wire them: a checker floor through a Mapping node
    (KHR_texture_transform), a normal-mapped block, an emissive texture, a cutout leaf, and a
    textured box mirrored by a negative scale."""
    def checker(u, v):
        odd = (int(u * 8) + int(v * 8)) % 2
        return (0.85, 0.8, 0.7, 1.0) if odd else (0.6, 0.2, 0.1, 1.0)

    def bumps(u, v):
        # Height h = sin(2π·4u)·sin(2π·4v)/160; normal (−∂h/∂u, −∂h/∂v, 1) in tangent space,
        # tilted by at most 9°.
        k = 2 * math.pi * 4
        dx = k * math.cos(k * u) * math.sin(k * v) / 8 * 0.05
        dy = k * math.sin(k * u) * math.cos(k * v) / 8 * 0.05
        n = (-dx, -dy, 1.0)
        length = math.sqrt(sum(c * c for c in n))
        return tuple(0.5 + 0.5 * c / length for c in n) + (1.0,)

    def gradient(u, v):
        return (u, 0.3 + 0.7 * v, 1.0 - u, 1.0)

    def leaf(u, v):
        inside = (u - 0.5) ** 2 / 0.2 + (v - 0.5) ** 2 / 0.08 < 1.0
        return (0.2, 0.6, 0.15, 1.0 if inside else 0.0)

    def arrow(u, v):
        # An asymmetric mark, so a mirrored copy looks mirrored.
        on = (0.2 < v < 0.4 and u > 0.2) or (0.4 <= v < 0.8 and 0.2 < u < 0.45)
        return (0.9, 0.75, 0.2, 1.0) if on else (0.2, 0.3, 0.6, 1.0)

    floor = textured("CheckerFloor", make_image("checker", 64, checker),
                     mapping={"location": (0.1, 0.2, 0.0), "rotation": (0.0, 0.0, math.radians(30.0)),
                              "scale": (3.0, 3.0, 1.0)})
    bumpy = textured("Bumpy", make_image("bumps", 64, bumps, "Non-Color"), colour=(0.8, 0.8, 0.8),
                     normal_strength=1.0)
    # Strength 1: Blender's USD exporter drops the strength of a textured emission.
    glow = textured("Glow", make_image("gradient", 32, gradient), colour=(0.0, 0.0, 0.0), emission_strength=1.0)
    # One-sided, as the other lights here: lit from behind, the 5 cm gap to the wall would be a
    # hidden hot spot that paths find only by chance (a heavy tail that no finite render gets
    # right).
    glow.use_backface_culling = True
    leafy = textured("Leaf", make_image("leaf", 64, leaf), cutout=True)
    marked = textured("Marked", make_image("arrow", 32, arrow))
    light = principled("Light", (0.0, 0.0, 0.0), emission=(1.0, 0.95, 0.85), strength=6.0)
    light.use_backface_culling = True

    def uv_quad(name, corners, material):
        obj = quad(name, corners, material)
        uv = obj.data.uv_layers.new(name="UVMap")
        for loop, coord in zip(obj.data.loops, [(0, 0), (1, 0), (1, 1), (0, 1)]):
            uv.data[loop.index].uv = coord
        return obj

    uv_quad("Floor", [(-3, -3, 0), (3, -3, 0), (3, 3, 0), (-3, 3, 0)], floor)
    uv_quad("Wall", [(-3, 1.5, 0), (3, 1.5, 0), (3, 1.5, 3), (-3, 1.5, 3)], bumpy)
    uv_quad("GlowPanel", [(-2.2, 1.45, 0.8), (-1.2, 1.45, 0.8), (-1.2, 1.45, 1.6), (-2.2, 1.45, 1.6)], glow)
    uv_quad("Leaf", [(-0.6, -0.5, 0.2), (0.4, -0.5, 0.2), (0.4, 0.1, 1.3), (-0.6, 0.1, 1.3)], leafy)
    bpy.ops.mesh.primitive_cube_add(size=0.6, location=(1.2, 0.2, 0.3))
    cube = bpy.context.active_object
    cube.data.materials.append(marked)
    mirrored = cube.copy()
    mirrored.data = cube.data
    mirrored.location = (1.9, -0.4, 0.3)
    mirrored.scale = (-1.0, 1.0, 1.0)
    bpy.context.scene.collection.objects.link(mirrored)
    s = 0.6
    quad("Light", [(-s, -s - 0.5, 3), (-s, s - 0.5, 3), (s, s - 0.5, 3), (s, -s - 0.5, 3)], light)
    add_camera(scene, (0.3, -5.0, 2.4), (0.3, 0.0, 0.6), 45.0)


def build_material_details(scene):
    """Materials the loader must read but Cycles cannot check here: a glass whose volume
    absorbs (Blender exports KHR_materials_volume only through a "glTF Material Output" group
    with a Thickness input, and Cycles' Volume Absorption, σ = density·(1 − colour), is not
    glTF's σ = −ln(colour)/distance), and a rough metal, which gridtrace renders ideal."""
    glass = principled("TintedGlass", (1.0, 1.0, 1.0), roughness=0.0, transmission=1.0, ior=1.5)
    nodes, links = glass.node_tree.nodes, glass.node_tree.links
    out = next(n for n in nodes if n.type == "OUTPUT_MATERIAL")
    absorption = nodes.new("ShaderNodeVolumeAbsorption")
    absorption.inputs["Color"].default_value = (0.9, 0.5, 0.2, 1.0)
    absorption.inputs["Density"].default_value = 2.0
    links.new(absorption.outputs["Volume"], out.inputs["Volume"])
    group = bpy.data.node_groups.new("glTF Material Output", "ShaderNodeTree")
    group.interface.new_socket("Thickness", in_out="INPUT", socket_type="NodeSocketFloat")
    settings = nodes.new("ShaderNodeGroup")
    settings.node_tree = group
    settings.inputs["Thickness"].default_value = 1.0
    rough = principled("RoughMetal", (0.9, 0.9, 0.9), metallic=1.0, roughness=0.4)
    sphere("GlassBall", glass, 0.5, (0.0, 0.0, 0.5))
    sphere("MetalBall", rough, 0.5, (1.5, 0.0, 0.5))


def build_window_room(scene):
    """A closed room lit only through a glazed window: a bright panel outside faces a pane of
    clear glass (a 1 cm slab) set in the far wall. Next-event estimation cannot see the
    panel through the glass, so every path that lights the room crosses the pane by a BSDF
    bounce — the interior that path guiding is for."""
    white = principled("Wall", (0.8, 0.8, 0.8))
    floor = principled("Floor", (0.6, 0.5, 0.4))
    glass = principled("Pane", (1.0, 1.0, 1.0), roughness=0.0, transmission=1.0, ior=1.5)
    sky = principled("Sky", (0.0, 0.0, 0.0), emission=(0.9, 0.95, 1.0), strength=6.0)
    w, d, h = 2.0, 2.0, 2.5
    x0, x1, z0, z1 = -0.7, 0.7, 0.9, 1.9
    quad("Floor", [(-w, -d, 0), (w, -d, 0), (w, d, 0), (-w, d, 0)], floor)
    quad("Ceiling", [(-w, -d, h), (-w, d, h), (w, d, h), (w, -d, h)], white)
    quad("LeftWall", [(-w, -d, 0), (-w, d, 0), (-w, d, h), (-w, -d, h)], white)
    quad("RightWall", [(w, -d, 0), (w, -d, h), (w, d, h), (w, d, 0)], white)
    quad("NearWall", [(-w, -d, 0), (-w, -d, h), (w, -d, h), (w, -d, 0)], white)
    # The far wall (y = d, facing -y) around the window opening, in four pieces.
    pieces = [
        [(-w, d, 0), (w, d, 0), (w, d, z0), (-w, d, z0)],
        [(-w, d, z1), (w, d, z1), (w, d, h), (-w, d, h)],
        [(-w, d, z0), (x0, d, z0), (x0, d, z1), (-w, d, z1)],
        [(x1, d, z0), (w, d, z0), (w, d, z1), (x1, d, z1)],
    ]
    mesh_object("FarWall", [v for q in pieces for v in q], [(4 * i, 4 * i + 1, 4 * i + 2, 4 * i + 3) for i in range(4)], white)
    pane = box("Pane", glass, (x1 - x0, 0.01, z1 - z0), (0.0, d, z0), 0.0)
    pane.location = (0.0, d, z0)
    quad("Sky", [(-4, d + 3, -1), (4, d + 3, -1), (4, d + 3, 5), (-4, d + 3, 5)], sky)
    add_camera(scene, (-1.2, -1.8, 1.6), (0.4, 1.0, 0.5), 70.0)


# Scenes also exported through Blender's USD exporter, to check that both exports render alike.
USD_EXPORTS = {"punctual_lights", "textured"}

# name -> (builder, directory of the exported .glb, total reference samples; 0: export only)
SCENE_TABLE = {
    "cornell_box": (build_cornell_box, os.path.join(ROOT, "assets"), 8192),
    "cornell_spheres": (build_cornell_spheres, os.path.join(ROOT, "assets"), 8192),
    "caustic": (build_caustic, SCENES, 8192),
    "coloured_lights": (build_coloured_lights, SCENES, 4096),
    "punctual_lights": (build_punctual_lights, SCENES, 4096),
    "textured": (build_textured, SCENES, 4096),
    "window_room": (build_window_room, SCENES, 4096),
    "material_details": (build_material_details, SCENES, 0),
}


def principled_inputs(mat):
    bsdf = mat.node_tree.nodes.get("Principled BSDF")
    i = bsdf.inputs
    return {
        "colour": tuple(i["Base Color"].default_value)[:3],
        "metallic": i["Metallic"].default_value,
        "transmission": i["Transmission Weight"].default_value,
        "ior": i["IOR"].default_value,
        "emission": tuple(i["Emission Color"].default_value)[:3],
        "strength": i["Emission Strength"].default_value,
    }


def use_exact_models(mat):
    """Replaces the material's Principled BSDF by gridtrace's model of its inputs, keeping
    whatever feeds them (image textures, mappings, normal maps, alpha)."""
    p = principled_inputs(mat)
    nodes = mat.node_tree.nodes
    links = mat.node_tree.links
    principled = nodes["Principled BSDF"]
    out = next(n for n in nodes if n.type == "OUTPUT_MATERIAL")

    def source(name):
        socket = principled.inputs[name]
        return socket.links[0].from_socket if socket.is_linked else None

    if p["transmission"] >= 0.5:
        surface = nodes.new("ShaderNodeBsdfGlass")
        surface.distribution = "SHARP" if "SHARP" in _enum_items(surface, "distribution") else "GGX"
        surface.inputs["Roughness"].default_value = 0.0
        surface.inputs["IOR"].default_value = p["ior"]
    elif p["metallic"] >= 0.5:
        surface = nodes.new("ShaderNodeBsdfGlossy")
        surface.distribution = "SHARP" if "SHARP" in _enum_items(surface, "distribution") else "GGX"
        surface.inputs["Roughness"].default_value = 0.0
    else:
        surface = nodes.new("ShaderNodeBsdfDiffuse")
        surface.inputs["Roughness"].default_value = 0.0
    surface.inputs["Color"].default_value = (*p["colour"], 1.0)
    if source("Base Color") is not None:
        links.new(source("Base Color"), surface.inputs["Color"])
    if source("Normal") is not None:
        links.new(source("Normal"), surface.inputs["Normal"])
    shader = surface.outputs["BSDF"]
    emission_source = source("Emission Color")
    if p["strength"] > 0.0 and (max(p["emission"]) > 0.0 or emission_source is not None):
        emission = nodes.new("ShaderNodeEmission")
        emission.inputs["Color"].default_value = (*p["emission"], 1.0)
        if emission_source is not None:
            links.new(emission_source, emission.inputs["Color"])
        emission.inputs["Strength"].default_value = p["strength"]
        add = nodes.new("ShaderNodeAddShader")
        links.new(shader, add.inputs[0])
        links.new(emission.outputs["Emission"], add.inputs[1])
        shader = add.outputs["Shader"]
    if source("Alpha") is not None:
        # Where alpha is 0 the surface is not there: a transparent pass-through.
        transparent = nodes.new("ShaderNodeBsdfTransparent")
        mix = nodes.new("ShaderNodeMixShader")
        links.new(source("Alpha"), mix.inputs["Fac"])
        links.new(transparent.outputs["BSDF"], mix.inputs[1])
        links.new(shader, mix.inputs[2])
        shader = mix.outputs["Shader"]
    if mat.use_backface_culling:
        # glTF doubleSided: false, which gridtrace renders as a black, non-emitting back face.
        backfacing = nodes.new("ShaderNodeNewGeometry").outputs["Backfacing"]
        black = nodes.new("ShaderNodeBsdfDiffuse")
        black.inputs["Color"].default_value = (0.0, 0.0, 0.0, 1.0)
        mix = nodes.new("ShaderNodeMixShader")
        links.new(backfacing, mix.inputs["Fac"])
        links.new(shader, mix.inputs[1])
        links.new(black.outputs["BSDF"], mix.inputs[2])
        shader = mix.outputs["Shader"]
    nodes.remove(principled)
    links.new(shader, out.inputs["Surface"])


def _enum_items(node, prop):
    return {item.identifier for item in node.bl_rna.properties[prop].enum_items}


def scene_arguments(description):
    """The options the reference scripts share: --samples, --only, --export-only (after a
    `--` when run through Blender's own command line)."""
    parser = argparse.ArgumentParser(description=description)
    parser.add_argument("--samples", type=int, help="total Cycles samples per pixel per scene")
    parser.add_argument("--only", action="append", help="scene name (repeatable)")
    parser.add_argument("--export-only", action="store_true", help="rewrite the scene files, render nothing")
    args = parser.parse_args(sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else None)
    os.makedirs(SCENES, exist_ok=True)
    os.makedirs(REFERENCES, exist_ok=True)
    return args


def export_usd(path, materialx=False):
    """Blender's USD export of the scene; textures are written beside the layer, replacing
    any left by an earlier run. An existing .usdc is removed first: USD saves over a crate
    file by appending to it, so a re-exported file would keep growing. `materialx` turns on
    the exporter's MaterialX network (an OpenPBR surface beside the preview one)."""
    if os.path.exists(path):
        os.remove(path)
    bpy.ops.wm.usd_export(
        filepath=path, overwrite_textures=True, generate_materialx_network=materialx
    )
    print(f"wrote {path} ({os.path.getsize(path)} bytes)", flush=True)


def render_reference(scene, name, samples, keep_world=False, pixel_filter=("BOX", 1.0)):
    """The reference of `name`: two Cycles renders of half the samples, seeds 1 and 2."""
    for half, seed in (("a", 1), ("b", 2)):
        render(scene, os.path.join(REFERENCES, f"{name}_{half}.exr"), samples // 2, seed,
               keep_world, pixel_filter)


def configure_cycles(scene, samples, seed, keep_world=False, pixel_filter=("BOX", 1.0)):
    scene.render.engine = "CYCLES"
    scene.render.resolution_x = SIZE
    scene.render.resolution_y = SIZE
    scene.render.resolution_percentage = 100
    scene.render.film_transparent = False
    scene.render.image_settings.file_format = "OPEN_EXR"
    scene.render.image_settings.color_depth = "32"
    scene.render.image_settings.exr_codec = "ZIP"
    scene.render.image_settings.color_mode = "RGB"
    scene.view_settings.view_transform = "Standard"
    scene.view_settings.look = "None"
    scene.view_settings.exposure = 0.0
    scene.view_settings.gamma = 1.0
    c = scene.cycles
    c.device = "CPU"
    c.samples = samples
    c.use_adaptive_sampling = False
    c.use_denoising = False
    c.seed = seed
    c.use_animated_seed = False
    c.pixel_filter_type, c.filter_width = pixel_filter
    c.sample_clamp_direct = 0.0
    c.sample_clamp_indirect = 0.0
    c.blur_glossy = 0.0
    c.caustics_reflective = True
    c.caustics_refractive = True
    c.max_bounces = 64
    c.diffuse_bounces = 64
    c.glossy_bounces = 64
    c.transmission_bounces = 64
    c.transparent_max_bounces = 64
    c.volume_bounces = 0
    c.min_light_bounces = 0
    c.min_transparent_bounces = 0
    scene.render.threads_mode = "AUTO"
    if scene.world is not None and not keep_world:
        scene.world = None
    for obj in scene.objects:
        if obj.type == "MESH":
            # Cycles' terminator offset bends shadow rays off smooth-shaded faces; gridtrace
            # has no such offset.
            obj.cycles.shadow_terminator_geometry_offset = 0.0
            obj.cycles.shadow_terminator_offset = 0.0


def render(scene, path, samples, seed, keep_world=False, pixel_filter=("BOX", 1.0)):
    configure_cycles(scene, samples, seed, keep_world, pixel_filter)
    scene.render.filepath = path
    start = time.time()
    bpy.ops.render.render(write_still=True)
    print(f"wrote {path}: {samples} spp, seed {seed}, {time.time() - start:.1f} s", flush=True)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--samples", type=int, help="total Cycles samples per pixel per scene")
    parser.add_argument("--only", action="append", help="scene name (repeatable)")
    parser.add_argument("--no-export", action="store_true", help="render without rewriting the .glb")
    parser.add_argument("--export-only", action="store_true", help="rewrite the scene files, render nothing")
    args = parser.parse_args(sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else None)

    os.makedirs(SCENES, exist_ok=True)
    os.makedirs(REFERENCES, exist_ok=True)
    for name, (build, directory, samples) in SCENE_TABLE.items():
        if args.only and name not in args.only:
            continue
        samples = args.samples or samples
        scene = reset()
        build(scene)
        if not args.no_export:
            export(os.path.join(directory, f"{name}.glb"), lights=bool(bpy.data.lights))
            if name in USD_EXPORTS:
                path = os.path.join(directory, f"{name}.usdc")
                bpy.ops.wm.usd_export(filepath=path)
                print(f"wrote {path} ({os.path.getsize(path)} bytes)")
        for mat in bpy.data.materials:
            if mat.node_tree and mat.node_tree.nodes.get("Principled BSDF"):
                use_exact_models(mat)
        if samples == 0 or args.export_only:
            continue
        for half, seed in (("a", 1), ("b", 2)):
            render(scene, os.path.join(REFERENCES, f"{name}_{half}.exr"), samples // 2, seed)
    return 0


if __name__ == "__main__":
    sys.exit(main())
