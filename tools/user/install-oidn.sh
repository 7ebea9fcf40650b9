#!/usr/bin/env bash
# Installs Intel Open Image Denoise 2 for `--denoise` (gridtrace loads it at run time and
# builds and runs without it). Debian has no OIDN 2 package, so the library comes from the
# PyPI wheel pyoidn==2.5.1.0 (hash-pinned in tools/user/oidn-requirements.txt), whose
# pyoidn/oidn/lib/ holds the library, its CPU device, its core and TBB. Only those go into
# .oidn/lib/ (their rpath is $ORIGIN/../lib); the tests point GRIDTRACE_OIDN there. Users
# can do the same, or install OIDN 2 from Intel's release archives.
set -euo pipefail
cd "$(dirname "$0")/../.."

DEST=.oidn/lib
if [ -e "$DEST/libOpenImageDenoise.so.2" ]; then
  exit 0
fi
python3 tools/user/unpack-wheel-libs.py tools/user/oidn-requirements.txt pyoidn/oidn/lib "$DEST" \
  libOpenImageDenoise.so.2 libOpenImageDenoise_core.so. libOpenImageDenoise_device_cpu.so. \
  libtbb.so.12
echo "Open Image Denoise 2 in $DEST"
