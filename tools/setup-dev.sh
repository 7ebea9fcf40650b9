#!/usr/bin/env bash
# Everything the tests and benchmarks need beyond the Rust toolchain: Embree 4 (with
# libclang for its bindings), Open Image Denoise 2, the Stanford dragon, the npm glTF tools
# (tools/npm), and Slurm with munge for the cluster test. Idempotent; safe to run every
# time.
set -euo pipefail
cd "$(dirname "$0")/.."
tools/install-embree.sh
tools/install-oidn.sh
tools/fetch-dragon.sh
tools/install-npm-tools.sh
tools/install-slurm.sh
