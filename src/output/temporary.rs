//! The temporary files outputs are written through (then renamed over the output, so a
//! reader never sees half an image), and the clean-up of those a killed run left behind.
//!
//! A temporary is named `.gridtrace-HOST-PID-RANDOM.tmp`: the host and process that write
//! it. A run removes, from the folder it writes to, the temporaries of its own host whose
//! process no longer exists — a render killed (SIGKILL, out of memory, a node's reboot)
//! while writing a checkpoint can leave one of gigabytes. Files of other hosts (a farm's
//! shared folder) or of live processes are never touched.

use std::path::Path;

/// What every temporary's name starts and ends with.
const PREFIX: &str = ".gridtrace-";
const SUFFIX: &str = ".tmp";

/// This machine's name as it appears in temporaries: letters, digits, `.` and `_` only.
fn host() -> String {
    let mut name = [0u8; 256];
    // SAFETY: gethostname writes at most `len` bytes into the buffer.
    let ok = unsafe { libc::gethostname(name.as_mut_ptr().cast(), name.len()) } == 0;
    let end = name.iter().position(|&b| b == 0).unwrap_or(name.len());
    let name = if ok { &name[..end] } else { &b"host"[..] };
    name.iter()
        .map(|&b| match b {
            b'a'..=b'z' | b'A'..=b'Z' | b'0'..=b'9' | b'.' => b as char,
            _ => '_',
        })
        .collect()
}

/// A builder for this process's temporaries.
pub fn builder() -> tempfile::Builder<'static, 'static> {
    static PROCESS_PREFIX: std::sync::OnceLock<String> = std::sync::OnceLock::new();
    let prefix =
        PROCESS_PREFIX.get_or_init(|| format!("{PREFIX}{}-{}-", host(), std::process::id()));
    let mut builder = tempfile::Builder::new();
    builder.prefix(prefix).suffix(SUFFIX);
    builder
}

/// The host and process id in a temporary's file name, if it is one of ours.
fn writer_of(name: &str) -> Option<(&str, u32)> {
    let middle = name.strip_prefix(PREFIX)?.strip_suffix(SUFFIX)?;
    let mut parts = middle.rsplitn(3, '-');
    let (_random, pid, host) = (parts.next()?, parts.next()?, parts.next()?);
    Some((host, pid.parse().ok()?))
}

/// True unless the process `pid` is known to be gone.
fn is_alive(pid: u32) -> bool {
    let Ok(pid) = libc::pid_t::try_from(pid) else {
        return true;
    };
    // SAFETY: signal 0 only asks whether the process exists.
    let answer = unsafe { libc::kill(pid, 0) };
    answer == 0 || std::io::Error::last_os_error().raw_os_error() != Some(libc::ESRCH)
}

/// Removes from `dir` the temporaries this host's dead processes left there; returns how
/// many files and bytes were removed.
pub fn remove_stale(dir: &Path) -> (usize, u64) {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return (0, 0);
    };
    let here = host();
    let mut removed = (0, 0);
    for entry in entries.flatten() {
        let name = entry.file_name();
        let Some((writer, pid)) = name.to_str().and_then(writer_of) else {
            continue;
        };
        let Ok(metadata) = entry.metadata() else {
            continue;
        };
        if writer != here || !metadata.is_file() || is_alive(pid) {
            continue;
        }
        if std::fs::remove_file(entry.path()).is_ok() {
            removed.0 += 1;
            removed.1 += metadata.len();
        }
    }
    removed
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_say_who_wrote_them() {
        let file = builder().tempfile_in(std::env::temp_dir()).unwrap();
        let name = file
            .path()
            .file_name()
            .unwrap()
            .to_str()
            .unwrap()
            .to_string();
        assert_eq!(
            writer_of(&name),
            Some((host().as_str(), std::process::id()))
        );
        assert_eq!(
            writer_of(".gridtrace-a-b-c-42-x1Yz.tmp"),
            Some(("a-b-c", 42))
        );
        assert_eq!(writer_of(".gridtrace-AbC123.tmp"), None);
        assert_eq!(writer_of("render.exr"), None);
    }

    #[test]
    fn only_the_dead_processes_temporaries_of_this_host_are_removed() {
        let dir = tempfile::tempdir().unwrap();
        let mut child = std::process::Command::new("true").spawn().unwrap();
        let dead = child.id();
        child.wait().unwrap();
        let here = host();
        let named = |name: String| {
            std::fs::write(dir.path().join(&name), b"partial").unwrap();
            name
        };
        let stale = named(format!(".gridtrace-{here}-{dead}-abc123.tmp"));
        let live = named(format!(
            ".gridtrace-{here}-{}-abc123.tmp",
            std::process::id()
        ));
        let other_host = named(format!(".gridtrace-elsewhere-{dead}-abc123.tmp"));
        let unrelated = named("render.exr".into());
        assert_eq!(remove_stale(dir.path()), (1, 7));
        assert!(!dir.path().join(stale).exists());
        for kept in [live, other_host, unrelated] {
            assert!(dir.path().join(&kept).exists(), "{kept}");
        }
    }
}
