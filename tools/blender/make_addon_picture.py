"""The picture of the Blender add-on in the manual (docs/blender_passes.png): the Cornell
box with a mirror and a glass sphere built in Blender, rendered by pressing F12 with
gridtrace as the render engine, and the passes the add-on fills beside the image —
Combined (through Blender's Standard view), Denoising Albedo, Normal and Depth.

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


if __name__ == "__main__":
    main()
