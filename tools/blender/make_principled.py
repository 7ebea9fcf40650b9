"""Export Principled-BSDF test scenes and render their Cycles references with the materials left
as Blender users make them (no node replaced).

Run from the repository root with the PyPI `bpy` package (Blender as a Python module):

    pip install bpy==5.0.1
    python3 tools/blender/make_principled.py [--samples N] [--only NAME]

For every scene this writes `tests/data/scenes/<name>.glb` and `.usdc` through Blender's own
exporters, and two Cycles renders with different seeds, `tests/data/references/<name>_a.exr` and
`_b.exr` (see make_references.py, whose unbiased Cycles settings it shares: box filter, no
clamping, no denoising, 64 bounces, black world).

- principled_metals: gold, steel and copper spheres at roughness 0.2, 0.5 and 0.8 on a floor and
  a wall that keep every Principled default (roughness 0.5, a 4 % specular layer).
- principled_plastics: glossy (0.1) and rough (0.6) plastics and a clear-coated sphere.
- principled_lamp_shade: a lamp shade modelled as one surface (an open cylinder, glass of
  roughness 0.3 tinted (1, 0.85, 0.6)) lit from inside by an emitting ball that nearly fills it, on a
  table-high box in the room; the light leaves through one crossing of a thin sheet.
- principled_sheen: velvet, a dark red base under a white sheen of roughness 0.2, 0.5 and
  0.8 (Cycles' microfibre sheen, which a file written by Blender renders with).
- principled_textured: a metal panel whose roughness comes from a texture and whose normal from
  a normal map.
- principled_glass_tints: single clear and tinted glass sheets, a closed yellow glass ball and
  a glass ball whose Metallic is a texture of 0, in front of an emitting backdrop.
- principled_normals: floor panels normal-mapped 15° and 45° away from the camera, and a
  coarse smooth-shaded metal ball.
- principled_specular: dark plastic spheres with a black, a red and a white Specular Tint.
- principled_anisotropy: brushed metal balls (Anisotropic 0.8, roughness 0.3) stretched
  along their UV tangent and turned a quarter turn, and a brushed plastic (0.6); the
  Principled Tangent input is a UV Tangent node, the frame glTF's tangents give.
- principled_udim: four panels whose colour is a UDIM image of three tiles (1001, 1002,
  1011), each a gradient of its own hue, darker towards its bottom; each panel shows one tile.
  The glTF exporter splits UDIM images into one material and image per tile; the USD exporter
  writes `name.<UDIM>.png`.
- principled_glass: a rough glass ball (0.2). Blender's USD exporter writes no transmission
  into its UsdPreviewSurface, so this scene's .usdc is exported with the exporter's MaterialX
  network on, whose OpenPBR surface carries `transmission_weight`.
"""

import math
import os
import sys

import bpy

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from make_cornell import box, export, principled, quad, reset, sphere  # noqa: E402
from make_references import (  # noqa: E402
    SCENES, add_camera, export_usd, make_image, render_reference, scene_arguments,
)


def blender_default(name, colour, **inputs):
    """A Principled BSDF with Blender's defaults (roughness 0.5, Specular IOR Level 0.5) but
    for the named inputs."""
    mat = principled(name, colour, roughness=0.5, specular=0.5)
    bsdf = mat.node_tree.nodes["Principled BSDF"]
    for key, value in inputs.items():
        bsdf.inputs[key].default_value = value
    return mat


def room(scene):
    """Floor and back wall with Blender's default material, a large soft light above and a
    small bright one to the side, both emissive quads. They stay two-sided: Cycles renders a
    material's backface culling only in the viewport, so a one-sided glTF light would differ
    from Cycles' wherever its back face is seen or lights something."""
    floor = blender_default("Floor", (0.8, 0.8, 0.8))
    wall = blender_default("Wall", (0.5, 0.55, 0.7))
    quad("Floor", [(-4, -4, 0), (4, -4, 0), (4, 4, 0), (-4, 4, 0)], floor)
    quad("Wall", [(-4, 1.5, 0), (4, 1.5, 0), (4, 1.5, 4), (-4, 1.5, 4)], wall)
    big = principled("SoftLight", (0.0, 0.0, 0.0), emission=(1.0, 0.95, 0.9), strength=4.0)
    small = principled("KeyLight", (0.0, 0.0, 0.0), emission=(1.0, 1.0, 1.0), strength=60.0)
    s = 1.0
    quad("SoftLight", [(-s, -s - 0.5, 3.5), (-s, s - 0.5, 3.5), (s, s - 0.5, 3.5), (s, -s - 0.5, 3.5)], big)
    k = 0.15
    # Facing the spheres from the front left, so its highlight shows on each of them.
    quad("KeyLight", [(-2.5, -2.0 - k, 1.6 - k), (-2.5, -2.0 + k, 1.6 - k), (-2.5, -2.0 + k, 1.6 + k),
                      (-2.5, -2.0 - k, 1.6 + k)], small)
    add_camera(scene, (0.0, -5.0, 1.8), (0.0, 0.0, 0.5), 40.0)


def build_metals(scene):
    room(scene)
    for name, colour, roughness, x in (("Gold", (1.0, 0.78, 0.34), 0.2, -1.1),
                                       ("Steel", (0.56, 0.57, 0.58), 0.5, 0.0),
                                       ("Copper", (0.95, 0.64, 0.54), 0.8, 1.1)):
        mat = blender_default(name, colour, Metallic=1.0, Roughness=roughness)
        sphere(name, mat, 0.5, (x, 0.0, 0.5))


def build_plastics(scene):
    room(scene)
    glossy = blender_default("GlossyPlastic", (0.7, 0.1, 0.08), Roughness=0.1)
    rough = blender_default("RoughPlastic", (0.1, 0.5, 0.15), Roughness=0.6)
    coated = blender_default("Coated", (0.1, 0.2, 0.6), Roughness=0.5)
    coated_bsdf = coated.node_tree.nodes["Principled BSDF"]
    coated_bsdf.inputs["Coat Weight"].default_value = 1.0
    coated_bsdf.inputs["Coat Roughness"].default_value = 0.05
    for (name, mat), x in zip((("Glossy", glossy), ("Rough", rough), ("Coated", coated)), (-1.1, 0.0, 1.1)):
        sphere(name, mat, 0.5, (x, 0.0, 0.5))


def build_glass(scene):
    room(scene)
    glass = blender_default("RoughGlass", (1.0, 1.0, 1.0), Roughness=0.2)
    glass.node_tree.nodes["Principled BSDF"].inputs["Transmission Weight"].default_value = 1.0
    sphere("GlassBall", glass, 0.5, (-0.3, -0.3, 0.5))


def build_textured(scene):
    room(scene)

    def stripes(u, v):
        # Roughness in smooth bands from 0.15 to 0.75 (glTF reads it from the green channel).
        # Smooth, because Blender's USD export cannot say "Closest": the .usdc is filtered
        # bilinearly, the .glb (magFilter NEAREST) and Cycles are not.
        r = 0.45 - 0.3 * math.cos(2 * math.pi * 2 * u)
        return (1.0, r, 1.0, 1.0)

    def ripples(u, v):
        k = 2 * math.pi * 3
        dx = 0.3 * math.cos(k * u)
        n = (-dx, 0.0, 1.0)
        length = math.sqrt(sum(c * c for c in n))
        return tuple(0.5 + 0.5 * c / length for c in n) + (1.0,)

    panel = blender_default("StripedMetal", (0.9, 0.9, 0.92), Metallic=1.0)
    nodes, links = panel.node_tree.nodes, panel.node_tree.links
    bsdf = nodes["Principled BSDF"]

    def data_texture(name, pixel):
        tex = nodes.new("ShaderNodeTexImage")
        tex.image = make_image(name, 64, pixel, "Non-Color")
        tex.interpolation = "Closest"
        return tex

    rough_tex = data_texture("stripes", stripes)
    # The glTF exporter packs roughness into the green channel of metallicRoughnessTexture
    # through a Separate Color node, as a user wires a packed texture.
    separate = nodes.new("ShaderNodeSeparateColor")
    links.new(rough_tex.outputs["Color"], separate.inputs["Color"])
    links.new(separate.outputs["Green"], bsdf.inputs["Roughness"])
    links.new(separate.outputs["Blue"], bsdf.inputs["Metallic"])
    normal_tex = data_texture("ripples", ripples)
    normal_map = nodes.new("ShaderNodeNormalMap")
    links.new(normal_tex.outputs["Color"], normal_map.inputs["Color"])
    links.new(normal_map.outputs["Normal"], bsdf.inputs["Normal"])
    obj = quad("Panel", [(-0.9, 0.0, 0.05), (0.9, 0.4, 0.05), (0.9, 0.4, 1.45), (-0.9, 0.0, 1.45)], panel)
    uv = obj.data.uv_layers.new(name="UVMap")
    for loop, coord in zip(obj.data.loops, [(0, 0), (1, 0), (1, 1), (0, 1)]):
        uv.data[loop.index].uv = coord


def build_glass_tints(scene):
    """Glass as real assets use it, in front of a bright backdrop: a clear and a tinted
    single sheet (a window pane modelled as one surface), a closed yellow glass ball, and a
    clear glass ball whose Metallic comes from a texture of 0 (the glTF exporter writes
    metallicFactor 1 with a metallic-roughness texture)."""
    room(scene)
    backdrop = principled("Backdrop", (0.0, 0.0, 0.0), emission=(1.0, 1.0, 1.0), strength=0.8)
    quad("Backdrop", [(-4, 1.4, 0), (4, 1.4, 0), (4, 1.4, 4), (-4, 1.4, 4)], backdrop)

    def glass(name, colour, roughness=0.0):
        mat = blender_default(name, colour, Roughness=roughness)
        mat.node_tree.nodes["Principled BSDF"].inputs["Transmission Weight"].default_value = 1.0
        return mat

    for name, colour, x in (("ClearSheet", (1.0, 1.0, 1.0), -1.15), ("TintedSheet", (0.25, 0.5, 1.0), -0.35)):
        quad(name, [(x - 0.35, -0.6, 0.2), (x + 0.35, -0.6, 0.2), (x + 0.35, -0.6, 1.4), (x - 0.35, -0.6, 1.4)],
             glass(name, colour))
    sphere("YellowBall", glass("YellowGlass", (1.0, 0.9, 0.1)), 0.35, (0.45, -0.3, 0.6))
    textured_glass = glass("TexturedMetallicGlass", (1.0, 1.0, 1.0))
    nodes, links = textured_glass.node_tree.nodes, textured_glass.node_tree.links
    tex = nodes.new("ShaderNodeTexImage")
    tex.image = make_image("metallic_zero", 4, lambda u, v: (1.0, 0.0, 0.0, 1.0), "Non-Color")
    tex.interpolation = "Closest"
    separate = nodes.new("ShaderNodeSeparateColor")
    links.new(tex.outputs["Color"], separate.inputs["Color"])
    links.new(separate.outputs["Blue"], nodes["Principled BSDF"].inputs["Metallic"])
    links.new(separate.outputs["Green"], nodes["Principled BSDF"].inputs["Roughness"])
    sphere("TexturedBall", textured_glass, 0.35, (1.2, -0.3, 0.6))


def normal_mapped_panel(name, x0, degrees):
    """A floor panel of Blender's default material (base colour (0.8, 0.7, 0.5)) from x0 to
    x0 + 1.6, whose normal map leans `degrees` away from the camera (None: no normal map)."""
    mat = blender_default(name, (0.8, 0.7, 0.5))
    if degrees is not None:
        t = math.radians(degrees)
        # Tangent space: +Y follows the V coordinate, which runs away from the camera.
        texel = (0.5, 0.5 + 0.5 * math.sin(t), 0.5 + 0.5 * math.cos(t), 1.0)
        nodes, links = mat.node_tree.nodes, mat.node_tree.links
        tex = nodes.new("ShaderNodeTexImage")
        tex.image = make_image(f"normal_{degrees}", 4, lambda u, v, texel=texel: texel, "Non-Color")
        tex.interpolation = "Closest"
        normal_map = nodes.new("ShaderNodeNormalMap")
        links.new(tex.outputs["Color"], normal_map.inputs["Color"])
        links.new(normal_map.outputs["Normal"], nodes["Principled BSDF"].inputs["Normal"])
    obj = quad(name, [(x0, -2.0, 0.01), (x0 + 1.6, -2.0, 0.01), (x0 + 1.6, 0.5, 0.01), (x0, 0.5, 0.01)], mat)
    uv = obj.data.uv_layers.new(name="UVMap")
    for loop, coord in zip(obj.data.loops, [(0, 0), (1, 0), (1, 1), (0, 1)]):
        uv.data[loop.index].uv = coord


def build_normals(scene):
    """Shading normals that face away from the viewer: two floor panels whose normal maps
    lean 15° and 45° away from the camera (the camera sees the 45° panel from below its
    tilted normal's horizon), and a coarse smooth-shaded metal ball, whose interpolated
    normals turn away from the camera along its outline."""
    room(scene)
    for name, degrees, x0 in (("Tilt15", 15, -1.7), ("Tilt45", 45, 0.1)):
        normal_mapped_panel(name, x0, degrees)
    bpy.ops.mesh.primitive_uv_sphere_add(segments=10, ring_count=6, radius=0.45, location=(0.0, 0.9, 0.6))
    ball = bpy.context.active_object
    ball.name = "CoarseBall"
    bpy.ops.object.shade_smooth()
    ball.data.materials.append(blender_default("CoarseMetal", (0.9, 0.9, 0.92), Metallic=1.0, Roughness=0.3))


def build_anisotropy(scene):
    room(scene)
    for name, colour, metallic, rotation, x in (
            ("BrushedSteel", (0.8, 0.8, 0.82), 1.0, 0.0, -1.1),
            ("TurnedGold", (1.0, 0.78, 0.34), 1.0, 0.25, 0.0),
            ("BrushedPlastic", (0.6, 0.1, 0.1), 0.0, 0.0, 1.1)):
        mat = blender_default(name, colour, Metallic=metallic, Roughness=0.3,
                              Anisotropic=0.8 if metallic else 0.6,
                              **{"Anisotropic Rotation": rotation})
        nodes, links = mat.node_tree.nodes, mat.node_tree.links
        tangent = nodes.new("ShaderNodeTangent")
        tangent.direction_type = "UV_MAP"
        tangent.uv_map = "UVMap"
        links.new(tangent.outputs["Tangent"], nodes["Principled BSDF"].inputs["Tangent"])
        sphere(name, mat, 0.5, (x, 0.0, 0.5))


def build_udim(scene):
    """A panel whose UVs span tiles 1001, 1002 (s 1–2) and 1011 (t 1–2) of a UDIM image.
    The tiles are written as PNG files first and loaded as one tiled image, as a user's
    painted UDIM set arrives in Blender."""
    import tempfile

    room(scene)
    folder = tempfile.mkdtemp(prefix="udim_")
    hues = {1001: (0.9, 0.25, 0.1), 1002: (0.1, 0.7, 0.2), 1011: (0.15, 0.3, 0.9)}
    for number, hue in hues.items():
        tile = make_image(f"tile{number}", 32, lambda u, v, h=hue: tuple(c * (0.25 + 0.75 * v) for c in h) + (1.0,))
        tile.filepath_raw = os.path.join(folder, f"painted.{number}.png")
        tile.file_format = "PNG"
        tile.save()
    image = bpy.data.images.load(os.path.join(folder, "painted.1001.png"))
    image.source = "TILED"
    assert sorted(t.number for t in image.tiles) == sorted(hues), list(image.tiles)
    image.pack()
    mat = blender_default("Painted", (1.0, 1.0, 1.0))
    nodes, links = mat.node_tree.nodes, mat.node_tree.links
    tex = nodes.new("ShaderNodeTexImage")
    tex.image = image
    links.new(tex.outputs["Color"], nodes["Principled BSDF"].inputs["Base Color"])
    # Four panels in a 2 × 2 block, each showing one tile whole (as a UV island lies in
    # one tile): 1001 bottom left, 1002 bottom right, 1011 top left, 1001 again top right.
    def corner(i, j):
        return (-0.9 + 0.9 * i, 0.2 * i, 0.05 + 0.7 * j)

    for (i, j), (s0, t0) in zip([(0, 0), (1, 0), (0, 1), (1, 1)], [(0, 0), (1, 0), (0, 1), (0, 0)]):
        corners = [corner(i, j), corner(i + 1, j), corner(i + 1, j + 1), corner(i, j + 1)]
        obj = quad(f"Panel{i}{j}", [(x - 0.02 * (1 - 2 * i), y, z) for x, y, z in corners], mat)
        uv = obj.data.uv_layers.new(name="UVMap")
        for loop, (ds, dt) in zip(obj.data.loops, [(0, 0), (1, 0), (1, 1), (0, 1)]):
            uv.data[loop.index].uv = (s0 + ds, t0 + dt)


def build_specular(scene):
    """Specular Tint (glTF's specular colour): black, red and white on the same dark
    plastic; a black tint still reflects at grazing angles in Cycles."""
    room(scene)
    for name, tint, x in (("TintBlack", (0.0, 0.0, 0.0), -1.1), ("TintRed", (1.0, 0.2, 0.2), 0.0),
                          ("TintWhite", (1.0, 1.0, 1.0), 1.1)):
        mat = blender_default(name, (0.05, 0.05, 0.06), Roughness=0.25)
        mat.node_tree.nodes["Principled BSDF"].inputs["Specular Tint"].default_value = tint + (1.0,)
        sphere(name, mat, 0.5, (x, 0.0, 0.5))


def build_sheen(scene):
    room(scene)
    for name, roughness, x in (("Velvet2", 0.2, -1.1), ("Velvet5", 0.5, 0.0), ("Velvet8", 0.8, 1.1)):
        mat = blender_default(name, (0.3, 0.02, 0.05), Roughness=0.7,
                              **{"Sheen Weight": 1.0, "Sheen Roughness": roughness})
        sphere(name, mat, 0.5, (x, 0.0, 0.5))


def build_lamp_shade(scene):
    room(scene)
    stand = blender_default("Stand", (0.3, 0.3, 0.32), Roughness=0.4)
    box("Stand", stand, (0.5, 0.5, 0.5), (0.0, 0.2, 0.0), 20.0)
    shade = blender_default("Shade", (1.0, 0.85, 0.6), Roughness=0.3,
                            **{"Transmission Weight": 1.0})
    bpy.ops.mesh.primitive_cylinder_add(vertices=32, radius=0.3, depth=0.45, end_fill_type="NOTHING",
                                        location=(0.0, 0.2, 0.8))
    cylinder = bpy.context.active_object
    cylinder.name = "Shade"
    bpy.ops.object.shade_smooth()
    cylinder.data.materials.append(shade)
    bulb = principled("Bulb", (0.0, 0.0, 0.0), emission=(1.0, 0.9, 0.75), strength=6.0)
    sphere("Bulb", bulb, 0.2, (0.0, 0.2, 0.8))


# name -> (builder, total reference samples)
SCENE_TABLE = {
    "principled_metals": (build_metals, 2048),
    "principled_plastics": (build_plastics, 2048),
    "principled_textured": (build_textured, 2048),
    "principled_glass": (build_glass, 4096),
    "principled_glass_tints": (build_glass_tints, 2048),
    "principled_normals": (build_normals, 2048),
    "principled_specular": (build_specular, 2048),
    "principled_udim": (build_udim, 1024),
    "principled_anisotropy": (build_anisotropy, 2048),
    "principled_sheen": (build_sheen, 2048),
    "principled_lamp_shade": (build_lamp_shade, 4096),
}
# Glass and sheen reach USD only through the exporter's MaterialX network.
MATERIALX = {"principled_glass", "principled_glass_tints", "principled_sheen", "principled_lamp_shade"}


def main():
    args = scene_arguments(__doc__.splitlines()[0])
    for name, (build, samples) in SCENE_TABLE.items():
        if args.only and name not in args.only:
            continue
        scene = reset()
        build(scene)
        export(os.path.join(SCENES, f"{name}.glb"))
        export_usd(os.path.join(SCENES, f"{name}.usdc"), materialx=name in MATERIALX)
        if not args.export_only:
            render_reference(scene, name, args.samples or samples)
    return 0


if __name__ == "__main__":
    sys.exit(main())
