#!/usr/bin/env python3
"""Downloads the one wheel a hash-pinned requirements file names and copies the shared
libraries in one of its folders into a destination folder: how the development setup gets
native libraries Debian does not package (Embree 4, Open Image Denoise 2).

    python3 tools/user/unpack-wheel-libs.py REQUIREMENTS FOLDER_IN_WHEEL DEST [NAME_PREFIX...]

Only files whose names start with one of the NAME_PREFIXes are copied (all, if none given).
"""
import os
import subprocess
import sys
import tempfile
import zipfile


def main():
    requirements, folder, dest, *prefixes = sys.argv[1:]
    os.makedirs(dest, exist_ok=True)
    with tempfile.TemporaryDirectory() as work:
        subprocess.run([sys.executable, "-m", "pip", "download", "--quiet", "--no-deps",
                        "--require-hashes", "-r", requirements, "-d", work], check=True)
        wheel = next(f for f in os.listdir(work) if f.endswith(".whl"))
        with zipfile.ZipFile(os.path.join(work, wheel)) as z:
            for info in z.infolist():
                base = os.path.basename(info.filename)
                if not info.filename.startswith(folder + "/") or not base:
                    continue
                if prefixes and not base.startswith(tuple(prefixes)):
                    continue
                target = os.path.join(dest, base)
                with open(target, "wb") as out:
                    out.write(z.read(info.filename))
                os.chmod(target, 0o755)


if __name__ == "__main__":
    main()
