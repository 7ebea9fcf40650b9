#!/usr/bin/env python3
"""The README's noisy-versus-denoised figure, docs/denoise.png: the bundled spheres scene at
16 samples per pixel as rendered, then denoised (--denoise, guided by the albedo and normal
layers), then at 4096 samples for comparison. Needs a release build, Open Image Denoise
(tools/user/install-oidn.sh) and Pillow (pip install pillow).

    python3 tools/dev/make_denoise_figure.py
"""
import os
import subprocess
import sys
import tempfile

from PIL import Image

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
GRIDTRACE = os.path.join(ROOT, "target", "release", "gridtrace")
SCENE = os.path.join(ROOT, "assets", "cornell_spheres.glb")
SIZE = "192"


def render(out, *extra):
    env = dict(os.environ, GRIDTRACE_OIDN=os.path.join(ROOT, ".oidn", "lib"))
    subprocess.run([GRIDTRACE, SCENE, "--width", SIZE, "-q", "-o", out, *extra], check=True, env=env)


def main():
    with tempfile.TemporaryDirectory() as tmp:
        panels = []
        for name, extra in [("noisy", ["--spp", "16"]), ("denoised", ["--spp", "16", "--denoise"]),
                            ("converged", ["--spp", "4096"])]:
            path = os.path.join(tmp, name + ".png")
            render(path, *extra)
            panels.append(Image.open(path).convert("RGB"))
        w, h = panels[0].size
        figure = Image.new("RGB", (3 * w + 8, h), "white")
        for i, panel in enumerate(panels):
            figure.paste(panel, (i * (w + 4), 0))
        figure.save(os.path.join(ROOT, "docs", "denoise.png"), optimize=True)


if __name__ == "__main__":
    sys.exit(main())
