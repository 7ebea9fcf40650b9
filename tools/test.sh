#!/usr/bin/env bash
# The project's test command (the README's): installs what the tests need (Embree 4 with
# libclang for its bindings, the Stanford dragon; see tools/dev/setup.sh), then runs every
# test in the optimised test profile.
set -euo pipefail
cd "$(dirname "$0")/.."
tools/dev/setup.sh
cargo test --locked "$@"
