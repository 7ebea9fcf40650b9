#!/usr/bin/env bash
# Installs Intel Open Image Denoise 2 for `--denoise` (gridtrace loads it at run time and
# builds and runs without it). Debian has no OIDN 2 package, so the library comes from the
# PyPI wheel pyoidn==2.5.1.0 (hash-pinned in tools/oidn-requirements.txt), whose
# pyoidn/oidn/lib/ holds the library, its CPU device, its core and TBB. Only those go into
# .oidn/lib/ (their rpath is $ORIGIN/../lib); the tests point GRIDTRACE_OIDN there. Users
# can do the same, or install OIDN 2 from Intel's release archives.
set -euo pipefail
cd "$(dirname "$0")/.."

DEST=.oidn/lib
if [ -e "$DEST/libOpenImageDenoise.so.2" ]; then
  exit 0
fi
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
python3 -m pip download --quiet --no-deps --require-hashes -r tools/oidn-requirements.txt -d "$work"
mkdir -p "$DEST"
python3 - "$work" "$DEST" <<'PY'
import os, sys, zipfile
work, dest = sys.argv[1], sys.argv[2]
wheel = next(f for f in os.listdir(work) if f.endswith(".whl"))
wanted = ("libOpenImageDenoise.so.2", "libOpenImageDenoise_core.so.", "libOpenImageDenoise_device_cpu.so.", "libtbb.so.12")
with zipfile.ZipFile(os.path.join(work, wheel)) as z:
    for info in z.infolist():
        base = os.path.basename(info.filename)
        if info.filename.startswith("pyoidn/oidn/lib/") and base.startswith(wanted):
            with open(os.path.join(dest, base), "wb") as out:
                out.write(z.read(info.filename))
            os.chmod(os.path.join(dest, base), 0o755)
PY
ls "$DEST"
echo "Open Image Denoise 2 in $DEST"
