#!/usr/bin/env bash
# Everything the tests and benchmarks need beyond the Rust toolchain: Embree 4 (with
# libclang for its bindings), Open Image Denoise 2, the Stanford dragon, the npm glTF tools
# (tools/dev/npm), Slurm with munge for the cluster test, and Blender as a Python module
# for the add-on's test. Idempotent; safe to run every
# time.
set -euo pipefail
cd "$(dirname "$0")/../.."
tools/dev/install-embree.sh
tools/user/install-oidn.sh
tools/dev/fetch-dragon.sh
tools/dev/install-npm-tools.sh
tools/dev/install-slurm.sh
tools/dev/install-blender.sh
