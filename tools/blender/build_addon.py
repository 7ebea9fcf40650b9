"""Package the Blender add-on (blender/gridtrace_blender/) for installation.

Run from the repository root (plain Python, no Blender needed):

    python3 tools/blender/build_addon.py [OUT_DIR]

Writes into OUT_DIR (default `dist/`):
- `gridtrace-VERSION-extension.zip`: a Blender 4.2+ extension (the manifest at the root of
  the archive): Preferences > Get Extensions > Install from Disk;
- `gridtrace_blender-VERSION-addon.zip`: a legacy add-on (one top-level package folder):
  Preferences > Add-ons > Install from Disk.
Both hold the project's Slurm scripts (tools/user/slurm/) under `slurm/`, which the add-on's
"Write Slurm Job" operator copies beside an exported scene.
"""

import os
import re
import sys
import zipfile

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
PACKAGE = os.path.join(ROOT, "blender", "gridtrace_blender")
SLURM = os.path.join(ROOT, "tools", "user", "slurm")
SLURM_FILES = ("submit.sh", "render-part.sbatch", "merge.sbatch")


def version():
    with open(os.path.join(PACKAGE, "blender_manifest.toml")) as f:
        return re.search(r'^version = "([^"]+)"', f.read(), re.M).group(1)


def members():
    """(path on disk, path inside the package) for every file the add-on ships."""
    for name in sorted(os.listdir(PACKAGE)):
        path = os.path.join(PACKAGE, name)
        if os.path.isfile(path) and (name.endswith(".py") or name == "blender_manifest.toml"):
            yield path, name
    for name in SLURM_FILES:
        yield os.path.join(SLURM, name), f"slurm/{name}"


def write(path, prefix):
    with zipfile.ZipFile(path, "w", zipfile.ZIP_DEFLATED) as z:
        for disk, inner in members():
            info = zipfile.ZipInfo(prefix + inner, date_time=(2020, 1, 1, 0, 0, 0))
            info.external_attr = (0o755 if inner.endswith((".sh", ".sbatch")) else 0o644) << 16
            info.compress_type = zipfile.ZIP_DEFLATED
            with open(disk, "rb") as f:
                z.writestr(info, f.read())
    print(f"wrote {path}")
    return path


def build(out):
    os.makedirs(out, exist_ok=True)
    v = version()
    extension = write(os.path.join(out, f"gridtrace-{v}-extension.zip"), "")
    addon = write(os.path.join(out, f"gridtrace_blender-{v}-addon.zip"), "gridtrace_blender/")
    return extension, addon


if __name__ == "__main__":
    build(sys.argv[1] if len(sys.argv) > 1 else os.path.join(ROOT, "dist"))
