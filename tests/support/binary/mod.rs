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

/// A running child process that is killed and reaped when dropped, so a test that fails
/// (or panics) while it runs never leaves it behind.
pub struct Owned(Option<std::process::Child>);

impl Owned {
    /// Takes ownership of `child`.
    pub fn new(child: std::process::Child) -> Owned {
        Owned(Some(child))
    }

    /// The child's process id.
    pub fn id(&self) -> u32 {
        self.0.as_ref().map_or(0, |c| c.id())
    }

    /// Hands the child back: the caller has reaped it (or will), so dropping does nothing.
    pub fn release(mut self) -> std::process::Child {
        self.0.take().expect("a child not yet released")
    }
}

impl Drop for Owned {
    fn drop(&mut self) {
        if let Some(child) = &mut self.0 {
            let _ = child.kill();
            let _ = child.wait();
        }
    }
}

/// Waits until the file at `path` holds `text`, up to `limit`; false when it never did.
/// Tests wait for what a run prints, not for a fixed time, so a busy machine only makes
/// them slower.
pub fn wait_for_text(path: &Path, text: &str, limit: std::time::Duration) -> bool {
    let started = std::time::Instant::now();
    while started.elapsed() < limit {
        if std::fs::read_to_string(path).is_ok_and(|s| s.contains(text)) {
            return true;
        }
        std::thread::sleep(std::time::Duration::from_millis(10));
    }
    false
}
