#!/usr/bin/env bash
# The project's test command (the README's): installs what the tests need (Embree 4 with
# libclang for its bindings, the Stanford dragon; see tools/setup-dev.sh), then runs every
# test in the optimised test profile.
set -euo pipefail
cd "$(dirname "$0")/.."
tools/setup-dev.sh
cargo test --locked "$@"
