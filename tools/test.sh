#!/usr/bin/env bash
# The project's test command (the README's): installs what the tests need (Embree 4 with
# libclang for its bindings, the Stanford dragon; see tools/dev/setup.sh), then runs every
# test in the optimised test profile.
set -euo pipefail
cd "$(dirname "$0")/.."
tools/dev/setup.sh
# Library backtraces off (panics keep theirs): capturing one takes a process-wide lock, and
# a USD stage's probe forked while a failing test's thread held it would wait for ever,
# turning that failure into a hang.
export RUST_LIB_BACKTRACE=0
cargo test --locked "$@"
