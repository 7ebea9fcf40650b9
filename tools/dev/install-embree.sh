#!/usr/bin/env bash
# Installs Embree 4 for the development tests and benchmarks (never for the renderer):
# Debian packages only Embree 3, so the library comes from the PyPI wheel
# embreex==4.4.0.post1 (hash-pinned in tools/dev/embree-requirements.txt), whose
# embreex.libs/ holds libembree4 and its TBB. They go into .embree4/ with a libembree4.so
# symlink; build.rs adds that folder to the link search path and to the tests' and
# benchmarks' rpath. embree4-sys runs bindgen, which needs libclang-dev.
set -euo pipefail
cd "$(dirname "$0")/../.."

if ! dpkg -s libclang-dev >/dev/null 2>&1; then
  SUDO=""
  [ "$(id -u)" -eq 0 ] || SUDO=sudo
  $SUDO apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq libclang-dev >/dev/null
fi

DEST=.embree4
if [ -e "$DEST/libembree4.so" ]; then
  exit 0
fi
python3 tools/user/unpack-wheel-libs.py tools/dev/embree-requirements.txt embreex.libs "$DEST"
lib=$(cd "$DEST" && ls libembree4-*.so.4)
ln -sf "$lib" "$DEST/libembree4.so"
echo "Embree 4 in $DEST ($lib)"
