//! Running gridtrace as the hostile tests do: under a 2 GiB address-space limit
//! (`setrlimit` in the child, so an allocation past it fails as it would on a smaller
//! machine), its stderr in a file, its peak memory measured, one run at a time, and every
//! child owned by a guard that kills it when the test ends. Also the hostile corpus itself,
//! made once per test binary by `tools/dev/make_hostile_inputs.py`.
#![allow(dead_code)]

#[path = "../binary/mod.rs"]
mod binary;

use std::os::unix::process::CommandExt;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::sync::OnceLock;
use std::time::{Duration, Instant};

#[allow(unused_imports)]
pub use binary::{Owned, gridtrace, stderr, wait_for_text};

/// The address space every run gets.
pub const MEMORY_LIMIT: u64 = 2 << 30;
/// Longest any run may take: generous, so that a busy machine makes the tests slower but
/// never fails them; a hang still ends the test.
pub const TIME_LIMIT: Duration = Duration::from_secs(180);

/// The corpus, made once per test run under Cargo's temporary folder for tests.
pub fn corpus() -> &'static Path {
    static CORPUS: OnceLock<PathBuf> = OnceLock::new();
    CORPUS.get_or_init(|| {
        let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("hostile-corpus");
        let _ = std::fs::remove_dir_all(&dir);
        let status = Command::new("python3")
            .arg(Path::new(env!("CARGO_MANIFEST_DIR")).join("tools/dev/make_hostile_inputs.py"))
            .arg(&dir)
            .status()
            .expect("python3 runs tools/dev/make_hostile_inputs.py");
        assert!(status.success(), "tools/dev/make_hostile_inputs.py failed");
        dir
    })
}

/// Held by every test that starts gridtrace: the runs take all cores and some measure
/// time, so they run one at a time rather than compete.
pub fn serial() -> std::sync::MutexGuard<'static, ()> {
    static SERIAL: std::sync::Mutex<()> = std::sync::Mutex::new(());
    SERIAL
        .lock()
        .unwrap_or_else(|poisoned| poisoned.into_inner())
}

pub fn scenes() -> PathBuf {
    corpus().join("scenes")
}

/// How a limited run ended.
pub struct Run {
    /// Exit code, `None` when killed by a signal.
    pub code: Option<i32>,
    /// What it printed on stderr.
    pub stderr: String,
    /// Peak resident memory in bytes.
    pub peak: u64,
    /// How long it took.
    pub elapsed: Duration,
}

/// Starts gridtrace with `args` in `cwd` under the memory limit, its stderr going to a
/// file (read with [`stderr_of`]).
pub fn spawn_limited(args: &[&str], cwd: &Path, stderr: &Path) -> Owned {
    let log = std::fs::File::create(stderr).unwrap();
    let mut command = Command::new(env!("CARGO_BIN_EXE_gridtrace"));
    command
        .args(args)
        .current_dir(cwd)
        .stdout(Stdio::null())
        .stderr(log);
    // SAFETY: only setrlimit, which is async-signal-safe, runs between fork and exec.
    unsafe {
        command.pre_exec(|| {
            let limit = libc::rlimit {
                rlim_cur: MEMORY_LIMIT,
                rlim_max: MEMORY_LIMIT,
            };
            if libc::setrlimit(libc::RLIMIT_AS, &limit) != 0 {
                return Err(std::io::Error::last_os_error());
            }
            Ok(())
        });
    }
    Owned::new(command.spawn().expect("start gridtrace"))
}

/// Waits for `child` (killing it past the time limit) and reports its peak memory.
pub fn wait_limited(child: Owned, stderr: &Path, started: Instant) -> Run {
    let pid = child.id() as libc::pid_t;
    let mut status = 0;
    // SAFETY: zeroed rusage is a valid value for wait4 to overwrite.
    let mut usage: libc::rusage = unsafe { std::mem::zeroed() };
    loop {
        // SAFETY: waits for our own child, with valid pointers.
        let waited = unsafe { libc::wait4(pid, &mut status, libc::WNOHANG, &mut usage) };
        if waited == pid {
            break;
        }
        if started.elapsed() > TIME_LIMIT {
            // SAFETY: kills and reaps our own child.
            unsafe {
                libc::kill(pid, libc::SIGKILL);
                libc::wait4(pid, &mut status, 0, &mut usage);
            }
            std::mem::forget(child.release());
            panic!("hung: still running after {TIME_LIMIT:?}");
        }
        std::thread::sleep(Duration::from_millis(10));
    }
    // Reaped by wait4 above: nothing is left for the guard to kill.
    std::mem::forget(child.release());
    Run {
        code: libc::WIFEXITED(status).then(|| libc::WEXITSTATUS(status)),
        stderr: std::fs::read_to_string(stderr).unwrap_or_default(),
        peak: usage.ru_maxrss as u64 * 1024,
        elapsed: started.elapsed(),
    }
}

pub fn run_limited(args: &[&str], cwd: &Path) -> Run {
    static RUNS: std::sync::atomic::AtomicUsize = std::sync::atomic::AtomicUsize::new(0);
    let n = RUNS.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
    let logs = tempfile::tempdir().unwrap();
    let log = logs.path().join(format!("stderr-{n}.txt"));
    let started = Instant::now();
    let child = spawn_limited(args, cwd, &log);
    wait_limited(child, &log, started)
}

pub fn temporary_files(dir: &Path) -> Vec<String> {
    std::fs::read_dir(dir)
        .unwrap()
        .flatten()
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .filter(|n| n.starts_with(".gridtrace-"))
        .collect()
}
