//! What SIGINT (Ctrl-C), SIGTERM (what Slurm and `kill` send) and SIGHUP (a closed
//! terminal) do: during a render the first one finishes the current pass and writes the
//! image so far; before and after it, and on a second signal, the process quits at once.
//! It never quits in the middle of writing a file: quitting waits for [`output_lock`], which
//! every write holds, so no temporary file survives and no message claims the output was
//! not replaced when it was.

use std::path::Path;
use std::sync::atomic::{AtomicBool, AtomicI32, AtomicU8, Ordering};
use std::sync::{Mutex, MutexGuard};
use std::time::Duration;

use signal_hook::consts::{SIGHUP, SIGINT, SIGTERM};

use crate::output::{OutputError, ViewTransform, check_writable, write_image_with_record};
use crate::record::RenderRecord;
use crate::render::Image;

/// Set by the first signal during a render: finish the pass, write, exit.
pub static STOP: AtomicBool = AtomicBool::new(false);

/// The first signal received (0: none).
static SIGNAL: AtomicI32 = AtomicI32::new(0);

/// What the run is doing, which decides what a first signal does.
static PHASE: AtomicU8 = AtomicU8::new(Phase::Preparing as u8);

/// Held while an output file is written (and by a quitting signal thread).
static OUTPUT: Mutex<()> = Mutex::new(());

/// What the run is doing.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[repr(u8)]
pub enum Phase {
    /// Loading or preparing: nothing to save, a signal quits.
    Preparing = 0,
    /// Rendering: a first signal ends the render after the current pass.
    Rendering = 1,
    /// The output is written: a signal quits (after the write in progress, if any).
    Finished = 2,
}

/// Enters `phase`.
pub fn set_phase(phase: Phase) {
    PHASE.store(phase as u8, Ordering::SeqCst);
}

/// Held while writing an output file, so that no signal ends the process half-way through.
pub fn output_lock() -> MutexGuard<'static, ()> {
    OUTPUT
        .lock()
        .unwrap_or_else(|poisoned| poisoned.into_inner())
}

/// Checks that `path` can take the output, holding the output lock (the check creates and
/// removes a probe file, which a signal must not strand).
pub fn check_output(path: &Path) -> Result<(), OutputError> {
    let _writing = output_lock();
    check_writable(path)?;
    let folder = path.parent().filter(|p| !p.as_os_str().is_empty());
    let (files, bytes) = crate::output::temporary::remove_stale(folder.unwrap_or(Path::new(".")));
    if files > 0 {
        crate::terminal::say(format_args!(
            "note: removed {files} temporary file(s) ({}) left in {} by a run that was killed while writing",
            crate::limits::Bytes(bytes),
            folder.unwrap_or(Path::new(".")).display()
        ));
    }
    Ok(())
}

/// Writes an output under the output lock, so no signal ends the process half-way through;
/// `then` is the phase entered before the lock is let go (the last write of a run enters
/// [`Phase::Finished`], after which a signal quits at once).
pub fn write_output(
    path: &Path,
    image: &Image,
    record: Option<&RenderRecord>,
    view: ViewTransform,
    then: Option<Phase>,
) -> Result<(), OutputError> {
    let _writing = output_lock();
    write_image_with_record(path, image, record, view)?;
    if let Some(phase) = then {
        set_phase(phase);
    }
    Ok(())
}

/// Writes a run's last output, with its record, and enters [`Phase::Finished`].
pub fn write_last(
    path: &Path,
    image: &Image,
    record: &RenderRecord,
    view: ViewTransform,
) -> Result<(), OutputError> {
    write_output(path, image, Some(record), view, Some(Phase::Finished))
}

/// The exit code for a run that a signal stopped: 128 + its number (130 for SIGINT, 143 for
/// SIGTERM, 129 for SIGHUP), as shells report it.
pub fn interrupted_exit_code() -> i32 {
    128 + SIGNAL.load(Ordering::SeqCst).max(0)
}

/// Ends the process with an error naming `scene` if it is still preparing (loading the
/// scene, building the grid) after `limit`: the readers are third-party code, and one that
/// loops on a crafted file cannot be interrupted any other way.
pub fn arm_load_timeout(limit: Duration, scene: &Path) {
    let scene = scene.display().to_string();
    std::thread::spawn(move || {
        std::thread::sleep(limit);
        let _writing = output_lock();
        if PHASE.load(Ordering::SeqCst) == Phase::Preparing as u8 {
            crate::terminal::say(format_args!(
                "error: {scene}: loading did not finish within {} s (--load-timeout); a reader may be looping on this file",
                limit.as_secs_f64()
            ));
            std::process::exit(2);
        }
    });
}

/// Installs the handlers: a thread that waits for the signals and acts on them.
pub fn install() {
    let Ok(mut signals) = signal_hook::iterator::Signals::new([SIGINT, SIGTERM, SIGHUP]) else {
        crate::terminal::say(format_args!(
            "warning: cannot install signal handlers; Ctrl-C will not save the image"
        ));
        return;
    };
    std::thread::spawn(move || {
        for signal in signals.forever() {
            on_signal(signal);
        }
    });
}

fn on_signal(signal: i32) {
    let first = SIGNAL
        .compare_exchange(0, signal, Ordering::SeqCst, Ordering::SeqCst)
        .is_ok();
    let name = name(signal);
    let rendering = PHASE.load(Ordering::SeqCst) == Phase::Rendering as u8;
    if first && rendering {
        STOP.store(true, Ordering::SeqCst);
        crate::terminal::say(format_args!(
            "\n{name}: finishing the current pass, then writing the image (a second signal quits without writing)"
        ));
        return;
    }
    // Quit, but never half-way through writing a file.
    let _writing = output_lock();
    let code = 128 + SIGNAL.load(Ordering::SeqCst);
    match PHASE.load(Ordering::SeqCst) {
        p if p == Phase::Finished as u8 => {}
        p if p == Phase::Rendering as u8 => crate::terminal::say(format_args!(
            "\n{name} again: quitting without writing the image"
        )),
        _ => crate::terminal::say(format_args!("\n{name}: quitting before rendering")),
    }
    std::process::exit(code);
}

fn name(signal: i32) -> &'static str {
    match signal {
        SIGINT => "interrupted (SIGINT)",
        SIGTERM => "terminated (SIGTERM)",
        SIGHUP => "hung up (SIGHUP)",
        _ => "signal",
    }
}
