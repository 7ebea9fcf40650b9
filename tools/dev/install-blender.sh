#!/usr/bin/env bash
# Installs Blender 5.0 as a Python module (the PyPI bpy wheel, Python 3.11) with OpenEXR
# into .blender-venv/, for the Blender add-on's test (tests/blender_addon.rs runs
# tools/blender/test_addon.py with .blender-venv/bin/python). Hash-pinned in
# tools/dev/blender-requirements.txt. Idempotent.
set -euo pipefail
cd "$(dirname "$0")/../.."

VENV=.blender-venv
if [ -x "$VENV/bin/python" ] && "$VENV/bin/python" -c "import bpy, OpenEXR" 2>/dev/null; then
  exit 0
fi
python3 -m venv "$VENV"
"$VENV/bin/pip" install --quiet --require-hashes -r tools/dev/blender-requirements.txt
"$VENV/bin/python" -c "import bpy; print('Blender', bpy.app.version_string, 'in $VENV')"
