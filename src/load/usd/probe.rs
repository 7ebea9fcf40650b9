//! A first read of the whole stage in a forked child, so that the USD reader's aborts become
//! errors. openusd 0.6 trusts the counts it reads from binary layers, and a corrupt count
//! makes it request an impossible allocation, which aborts the process rather than failing
//! (found by fuzzing); a text layer may sublayer or reference such a binary layer, and
//! composition opens references only when it reaches them, so the child does the whole
//! load, not only the file named on the command line.

use std::path::Path;

use super::resolver::is_layer;
use crate::limits::{Bytes, EXIT_IMPOSSIBLE_ALLOCATION, EXIT_OUT_OF_MEMORY, memory_budget};
use crate::load::LoadError;

/// False only for a text layer whose asset paths all name images: such a stage holds
/// nothing the binary reader sees, and need not be read twice. Any other asset path may
/// lead to a binary layer — by name (`@x.usdc@`), through a variable expression
/// (`` @`"./${V}.usdc"`@ ``, resolved only during composition) or a file without a layer
/// extension — so the stage is probed.
pub fn may_hold_binary_layers(path: &Path) -> bool {
    let text = path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("usda"));
    if !text {
        return true;
    }
    let Ok(bytes) = std::fs::read(path) else {
        return true;
    };
    // Asset paths lie between `@` signs; looking at every piece between two of them (not
    // only the odd ones) stays safe when a string or comment holds a stray `@`.
    // A stray `@` shifts which pieces are asset paths: every piece is checked for layers
    // and expressions, and the pieces in asset-path places must be images.
    let pieces: Vec<&[u8]> = bytes.split(|&b| b == b'@').collect();
    if pieces.len() <= 2 {
        return false;
    }
    let inner = &pieces[1..pieces.len() - 1];
    inner.iter().any(|piece| {
        let piece = String::from_utf8_lossy(piece);
        is_layer(&piece) || piece.starts_with('`')
    }) || inner
        .iter()
        .step_by(2)
        .any(|piece| !is_image(&String::from_utf8_lossy(piece)))
}

/// True for a path with the extension of an image format a texture may have.
fn is_image(path: &str) -> bool {
    let path = path.to_ascii_lowercase();
    [
        ".png", ".jpg", ".jpeg", ".exr", ".hdr", ".webp", ".tga", ".tif", ".tiff", ".bmp", ".ktx2",
        ".tx",
    ]
    .iter()
    .any(|e| path.ends_with(e))
}

/// Runs `load` in a forked child; a child killed by a signal (an abort, a stack overflow,
/// the memory limit) becomes an error naming `path`. Without a child to spare, the caller's
/// own read decides.
#[cfg(unix)]
pub fn probe_stage(path: &Path, load: impl FnOnce() -> bool) -> Result<(), LoadError> {
    // SAFETY: fork has no preconditions; the child below only reads files and leaves with
    // `_exit`, running no destructors and touching nothing it shares with the parent.
    let pid = unsafe { libc::fork() };
    if pid == 0 {
        // SAFETY: prctl with PR_SET_PDEATHSIG takes a signal number: the child dies with
        // its parent (a killed render leaves no stray reader behind).
        #[cfg(target_os = "linux")]
        unsafe {
            libc::prctl(libc::PR_SET_PDEATHSIG, libc::SIGKILL)
        };
        // The reader's own last words (an allocation failure's message and backtrace) are
        // not the user's business: the parent reports the crash in one line.
        // SAFETY: opens /dev/null and moves it onto this process's stderr descriptor; puts
        // back the default action of the signals a crash raises, so that handlers the host
        // installed (a fuzzer's, a debugger's) do not turn the crash into something else.
        unsafe {
            let null = libc::open(c"/dev/null".as_ptr(), libc::O_WRONLY);
            if null >= 0 {
                libc::dup2(null, libc::STDERR_FILENO);
            }
            for signal in [
                libc::SIGABRT,
                libc::SIGSEGV,
                libc::SIGBUS,
                libc::SIGILL,
                libc::SIGFPE,
            ] {
                libc::signal(signal, libc::SIG_DFL);
            }
        }
        crate::limits::exit_on_allocation_failure();
        let _ = std::panic::catch_unwind(std::panic::AssertUnwindSafe(load));
        // SAFETY: ends the child at once, as fork's documentation asks.
        unsafe { libc::_exit(0) };
    }
    if pid < 0 {
        return Ok(());
    }
    // Wait as long as the read takes: the reader can be slow on a large stage, and a stage
    // on which it loops is ended by the command line's load timeout (`--load-timeout`),
    // which takes this child with it. The child inherits every lock and once-only
    // initialisation as some other thread left it at the fork, so the command line forks
    // before its render workers exist: a worker starting up initialises the deque
    // collector that the child's image decoders' threads also need, and one caught midway
    // leaves the child waiting for ever. The threads alive at the fork (signal handling,
    // the load timeout, the BSDF tables' integration) touch nothing the child uses; the
    // backtrace lock is never taken when library backtraces are off (`RUST_LIB_BACKTRACE=0`,
    // which the command line and the test script set).
    let mut status = 0;
    let waited = loop {
        // SAFETY: waits for the child forked above, with a valid status pointer.
        let waited = unsafe { libc::waitpid(pid, &mut status, 0) };
        if waited >= 0 || std::io::Error::last_os_error().kind() != std::io::ErrorKind::Interrupted
        {
            break waited;
        }
    };
    if waited != pid {
        return Ok(());
    }
    // The child leaves with status 0 whatever the load gave; anything else is a crash.
    let crashed = |how: String| {
        format!(
            "the USD reader crashed on this stage or a layer it uses ({how}); a layer is probably corrupt"
        )
    };
    let what = if libc::WIFSIGNALED(status) {
        crashed(format!("signal {}", libc::WTERMSIG(status)))
    } else if !libc::WIFEXITED(status) || libc::WEXITSTATUS(status) == 0 {
        return Ok(());
    } else {
        match libc::WEXITSTATUS(status) {
            EXIT_IMPOSSIBLE_ALLOCATION => {
                crashed("it asked for more memory at once than this run may use".into())
            }
            EXIT_OUT_OF_MEMORY => format!(
                "reading the stage ran out of memory: it needs more than the {} this run may use (--max-memory, ulimit -v)",
                Bytes(memory_budget())
            ),
            code => crashed(format!("exit status {code}")),
        }
    };
    Err(LoadError::Invalid {
        path: path.to_path_buf(),
        what,
    })
}

#[cfg(not(unix))]
pub fn probe_stage(_path: &Path, _load: impl FnOnce() -> bool) -> Result<(), LoadError> {
    Ok(())
}
