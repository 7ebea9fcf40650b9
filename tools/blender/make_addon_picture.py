"""The pictures of the Blender add-on in the manual. docs/blender_passes.png: the Cornell box
with a mirror and a glass sphere built in Blender, rendered by pressing F12 with gridtrace as
the render engine, and the passes the add-on fills beside the image — Combined (through
Blender's Standard view), Denoising Albedo, Normal and Depth. docs/blender_panel.png: the
add-on's gridtrace panel as it was set for that render, its labels and values read from the
add-on's own properties and drawn as text by Cycles (a headless Blender draws no interface),
beside the render.

    .blender-venv/bin/python tools/blender/make_addon_picture.py target/release/gridtrace
"""

import os
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
sys.argv = [sys.argv[0], sys.argv[1] if len(sys.argv) > 1 else "gridtrace"]
sys.path.insert(0, HERE)

import bpy  # noqa: E402
import numpy as np  # noqa: E402

import make_cornell  # noqa: E402
import test_addon  # noqa: E402

SIZE = 256


def srgb(linear):
    linear = np.clip(linear, 0.0, 1.0)
    return np.where(linear <= 0.0031308, 12.92 * linear, 1.055 * np.power(linear, 1 / 2.4) - 0.055)


def main():
    test_addon.install()
    scene = make_cornell.reset()
    test_addon.enable()
    make_cornell.build_cornell_spheres(scene)
    scene.render.engine = "GRIDTRACE"
    scene.render.resolution_x = scene.render.resolution_y = SIZE
    scene.gridtrace.samples = 256
    scene.gridtrace.albedo_pass = True
    layer = scene.view_layers[0]
    layer.use_pass_z = layer.use_pass_normal = True
    scene.render.image_settings.media_type = "MULTI_LAYER_IMAGE"
    scene.render.image_settings.color_depth = "32"
    image, _ = test_addon.f12(scene, "passes.exr")

    def rgb(name, c="RGB"):
        return np.stack([image[f"ViewLayer.{name}.{x}"] for x in c], axis=-1)

    depth = image["ViewLayer.Depth.Z"]
    finite = np.isfinite(depth) & (depth < 1e9)
    near, far = depth[finite].min(), depth[finite].max()
    grey = np.where(finite, 1 - (depth - near) / max(far - near, 1e-6), 0.0)
    panels = [
        srgb(rgb("Combined")),
        srgb(rgb("Denoising Albedo")),
        np.clip(rgb("Normal", "XYZ") * 0.5 + 0.5, 0, 1),
        np.repeat(grey[..., None], 3, axis=-1),
    ]
    gap = np.ones((SIZE, 8, 3))
    row = np.concatenate([p if i == 0 else np.concatenate([gap, p], axis=1) for i, p in enumerate(panels)], axis=1)
    height, width = row.shape[:2]
    out = bpy.data.images.new("passes", width, height, alpha=False)
    rgba = np.concatenate([row, np.ones((height, width, 1))], axis=-1)[::-1]  # Blender rows run bottom up
    out.pixels.foreach_set(rgba.astype(np.float32).ravel())
    out.filepath_raw = os.path.join(ROOT, "docs", "blender_passes.png")
    out.file_format = "PNG"
    out.save()
    print(f"wrote {out.filepath_raw}")
    panel_rows = settings_rows(scene)
    draw_panel(panel_rows, panels[0])


def settings_rows(scene):
    """(label, value) of every setting the gridtrace panel shows, read from the add-on."""
    ui = sys.modules[test_addon.MODULE + ".ui"]
    rows = [("Render Engine", "gridtrace"), ("Resolution", f"{SIZE} x {SIZE} px")]
    settings = scene.gridtrace
    for name in ui.GRIDTRACE_PT_render.SHOWN:
        prop = settings.bl_rna.properties[name]
        value = getattr(settings, name)
        if prop.type == "ENUM":
            value = prop.enum_items[value].name
        elif prop.type == "BOOLEAN":
            value = "on" if value else "off"
        elif prop.type == "FLOAT":
            value = f"{value:g}"
        rows.append((prop.name, str(value)))
    return rows


def draw_panel(rows, render):
    """The panel's rows as text in a scene of its own, rendered by Cycles, beside `render`."""
    scene = make_cornell.reset()
    scene.render.engine = "CYCLES"
    scene.cycles.samples = 16
    scene.cycles.device = "CPU"
    scene.view_settings.view_transform = "Standard"
    line, width = 0.26, 4.6
    height = line * (len(rows) + 2)
    scene.render.resolution_x = round(SIZE * width / height)
    scene.render.resolution_y = SIZE

    def emission(name, value):
        material = bpy.data.materials.new(name)
        material.use_nodes = True
        nodes = material.node_tree.nodes
        nodes.clear()
        out = nodes.new("ShaderNodeOutputMaterial")
        light = nodes.new("ShaderNodeEmission")
        light.inputs["Color"].default_value = (value, value, value, 1)
        material.node_tree.links.new(light.outputs[0], out.inputs[0])
        return material

    def text(body, x, y, material, size=0.16, align="LEFT"):
        curve = bpy.data.curves.new(body, "FONT")
        curve.body, curve.size, curve.align_x = body, size, align
        obj = bpy.data.objects.new(body, curve)
        obj.location = (x, y, 0.01)
        obj.data.materials.append(material)
        scene.collection.objects.link(obj)

    bright, dim = emission("Text", 0.85), emission("Label", 0.6)
    text("gridtrace", -width / 2 + 0.15, height / 2 - line, bright, size=0.18)
    for i, (label, value) in enumerate(rows):
        y = height / 2 - line * (i + 2)
        text(label, -0.1, y, dim, align="RIGHT")
        text(value, 0.1, y, bright)
    plane = bpy.data.meshes.new("Background")
    plane.from_pydata([(-width, -height, 0), (width, -height, 0), (width, height, 0), (-width, height, 0)], [],
                      [(0, 1, 2, 3)])
    background = bpy.data.objects.new("Background", plane)
    background.data.materials.append(emission("Background", 0.04))
    scene.collection.objects.link(background)
    cam_data = bpy.data.cameras.new("Top")
    cam_data.type = "ORTHO"
    cam_data.ortho_scale = width
    camera = bpy.data.objects.new("Top", cam_data)
    camera.location = (0, 0, 5)
    scene.collection.objects.link(camera)
    scene.camera = camera
    scene.render.image_settings.file_format = "OPEN_EXR"
    scene.render.image_settings.color_depth = "32"
    scene.render.filepath = os.path.join(test_addon.WORK, "panel.exr")
    bpy.ops.render.render(write_still=True)
    drawn = test_addon.channels(scene.render.filepath)
    panel = srgb(np.stack([drawn[c] for c in "RGB"], axis=-1))
    gap = np.ones((SIZE, 8, 3))
    row = np.concatenate([render, gap, panel], axis=1)
    height_px, width_px = row.shape[:2]
    out = bpy.data.images.new("panel", width_px, height_px, alpha=False)
    rgba = np.concatenate([row, np.ones((height_px, width_px, 1))], axis=-1)[::-1]
    out.pixels.foreach_set(rgba.astype(np.float32).ravel())
    out.filepath_raw = os.path.join(ROOT, "docs", "blender_panel.png")
    out.file_format = "PNG"
    out.save()
    print(f"wrote {out.filepath_raw}")


if __name__ == "__main__":
    main()
