#!/usr/bin/env bash
# The project's test command (the README's): installs nothing yet beyond the Rust
# toolchain the machine has, then runs every test in the optimised test profile.
set -euo pipefail
cd "$(dirname "$0")/.."
cargo test --locked "$@"
