"""Make docs/correctness.png: each reference scene as Cycles rendered it, as gridtrace renders
it, and their difference, side by side.

Run from the repository root after `cargo build --release` and make_references.py:

    python3 tools/blender/make_correctness_figure.py

gridtrace renders each scene at the references' size, 512 spp, 64 bounces. The difference
column shows |gridtrace − Cycles| × 4 on the same sRGB scale: at these sample counts it is the
two renderers' noise, with no structure.
"""

import os
import struct
import subprocess
import sys
import tempfile
import zlib

import bpy
import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
SCENES = ["cornell_box", "cornell_spheres", "caustic", "coloured_lights", "punctual_lights", "textured"]
SIZE = 128
GAP = 4
DIFFERENCE_SCALE = 4.0


def scene_path(name):
    asset = os.path.join(ROOT, "assets", f"{name}.glb")
    return asset if os.path.exists(asset) else os.path.join(ROOT, "tests", "data", "scenes", f"{name}.glb")


def read_exr(path):
    """RGB float array, top row first."""
    image = bpy.data.images.load(path)
    width, height = image.size
    pixels = np.array(image.pixels[:], dtype=np.float32).reshape(height, width, 4)[::-1, :, :3]
    bpy.data.images.remove(image)
    return pixels


def srgb(linear):
    x = np.clip(linear, 0.0, 1.0)
    return np.where(x <= 0.0031308, 12.92 * x, 1.055 * np.power(x, 1.0 / 2.4) - 0.055)


def write_png(path, rgb):
    """8-bit RGB PNG from values in [0, 1] (PNG spec, ISO/IEC 15948: IHDR, IDAT, IEND)."""
    height, width, _ = rgb.shape
    data = (np.round(rgb * 255.0)).astype(np.uint8)
    raw = b"".join(b"\x00" + data[y].tobytes() for y in range(height))

    def chunk(kind, payload):
        body = kind + payload
        return struct.pack(">I", len(payload)) + body + struct.pack(">I", zlib.crc32(body) & 0xFFFFFFFF)

    header = struct.pack(">IIBBBBB", width, height, 8, 2, 0, 0, 0)
    with open(path, "wb") as f:
        f.write(b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", header) + chunk(b"IDAT", zlib.compress(raw, 9))
                + chunk(b"IEND", b""))


def main():
    binary = os.path.join(ROOT, "target", "release", "gridtrace")
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        for name in SCENES:
            out = os.path.join(tmp, f"{name}.exr")
            subprocess.run([binary, scene_path(name), "-o", out, "--width", str(SIZE), "--height", str(SIZE),
                            "--spp", "512", "--max-depth", "64", "-q"], check=True)
            ours = read_exr(out)
            refs = [read_exr(os.path.join(ROOT, "tests", "data", "references", f"{name}_{h}.exr")) for h in "ab"]
            reference = 0.5 * (refs[0] + refs[1])
            difference = np.abs(ours - reference) * DIFFERENCE_SCALE
            rows.append([reference, ours, difference])
    height = len(rows) * SIZE + (len(rows) - 1) * GAP
    width = 3 * SIZE + 2 * GAP
    figure = np.ones((height, width, 3), dtype=np.float32)
    for r, row in enumerate(rows):
        for c, image in enumerate(row):
            y, x = r * (SIZE + GAP), c * (SIZE + GAP)
            figure[y:y + SIZE, x:x + SIZE] = srgb(image)
    path = os.path.join(ROOT, "docs", "correctness.png")
    write_png(path, figure)
    print(f"wrote {path}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
