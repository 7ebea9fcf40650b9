//! Running the `gridtrace` binary as a user would, for the command-line tests.
#![allow(dead_code)]

use std::path::Path;
use std::process::{Command, Output};

/// Runs `gridtrace ARGS` in `cwd` and returns what it did.
pub fn gridtrace(args: &[&str], cwd: &Path) -> Output {
    Command::new(env!("CARGO_BIN_EXE_gridtrace"))
        .args(args)
        .current_dir(cwd)
        .output()
        .expect("run gridtrace")
}

/// What a run printed on stderr.
pub fn stderr(out: &Output) -> String {
    String::from_utf8_lossy(&out.stderr).into_owned()
}
