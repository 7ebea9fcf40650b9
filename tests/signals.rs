//! Signals, checkpoints and the output: Ctrl-C, SIGTERM and SIGHUP write the image so far,
//! a second signal quits at once and never half-way through a write, a killed checkpointed
//! render resumes into the uninterrupted image (and its stranded temporary file is removed
//! by the next run), the output is checked before anything is loaded, and files named on
//! the command line that are not regular are refused at once. Runs are limited and owned
//! as the hostile corpus's are.

#[path = "support/limited/mod.rs"]
mod limited;

use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::{Duration, Instant};

use gridtrace::output::merge::{MERGE_TOLERANCE, read_part};
use gridtrace::output::read_exr_rgba;
use limited::{
    Owned, TIME_LIMIT, run_limited, scenes, serial, spawn_limited, temporary_files, wait_limited,
};

#[test]
fn the_output_is_checked_before_anything_is_loaded() {
    let _serial = serial();
    let out = tempfile::tempdir().unwrap();
    let folder = out.path().join("render.exr");
    std::fs::create_dir(&folder).unwrap();
    // The scene does not exist: the error must be the output's, found first.
    let run = run_limited(
        &["missing.gltf", "-o", folder.to_str().unwrap()],
        out.path(),
    );
    assert_eq!(run.code, Some(2), "{}", run.stderr);
    assert!(
        run.stderr.contains("render.exr: is a directory"),
        "{}",
        run.stderr
    );

    let locked = out.path().join("locked.png");
    std::fs::write(&locked, b"an earlier render").unwrap();
    let immutable = Command::new("chattr").arg("+i").arg(&locked).status();
    if !immutable.is_ok_and(|s| s.success()) {
        println!("skipping the immutable-file case: chattr +i is not available here");
        return;
    }
    let run = run_limited(
        &["missing.gltf", "-o", locked.to_str().unwrap()],
        out.path(),
    );
    let _ = Command::new("chattr").arg("-i").arg(&locked).status();
    assert_eq!(run.code, Some(2), "{}", run.stderr);
    assert!(
        run.stderr
            .contains("locked.png: cannot replace the existing file"),
        "{}",
        run.stderr
    );
}

fn cornell_box() -> String {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("assets/cornell_box.glb");
    path.to_str().unwrap().to_string()
}

/// Starts a long render of the Cornell box and waits until it is rendering.
fn start_long_render(out: &Path, extra: &[&str]) -> (Owned, PathBuf, Instant) {
    let image = out.join("partial.exr");
    let log = out.join("stderr.txt");
    let scene = cornell_box();
    let mut args = vec![
        scene.as_str(),
        "-o",
        image.to_str().unwrap(),
        "--width",
        "32",
        "--spp",
        "10000000",
    ];
    args.extend_from_slice(extra);
    let started = Instant::now();
    let child = spawn_limited(&args, &scenes(), &log);
    assert!(
        limited::wait_for_text(&log, "prepared in", TIME_LIMIT),
        "the render never started"
    );
    (child, image, started)
}

fn samples_in(image: &Path) -> std::ops::Range<u32> {
    read_part(image).expect("a valid part").record.samples
}

#[test]
fn sigterm_and_sighup_write_the_partial_image_like_ctrl_c() {
    let _serial = serial();
    for (signal, code) in [
        (libc::SIGTERM, 143),
        (libc::SIGHUP, 129),
        (libc::SIGINT, 130),
    ] {
        let out = tempfile::tempdir().unwrap();
        let (child, image, started) = start_long_render(out.path(), &[]);
        std::thread::sleep(Duration::from_millis(300));
        // SAFETY: signals our own child.
        unsafe { libc::kill(child.id() as libc::pid_t, signal) };
        let run = wait_limited(child, &out.path().join("stderr.txt"), started);
        assert_eq!(run.code, Some(code), "signal {signal}: {}", run.stderr);
        let samples = samples_in(&image);
        assert!(samples.start == 0 && samples.end > 0, "{samples:?}");
        assert!(
            run.stderr.contains("writing the image so far"),
            "{}",
            run.stderr
        );
        assert!(temporary_files(out.path()).is_empty());
    }
}

#[test]
fn a_second_signal_quits_at_once_and_never_half_way_through_a_write() {
    let _serial = serial();
    for delay_ms in [0, 1, 3, 10, 30] {
        let out = tempfile::tempdir().unwrap();
        // Checkpoints every 10 ms: a write is under way much of the time.
        let (child, image, started) = start_long_render(out.path(), &["--checkpoint", "0.01"]);
        std::thread::sleep(Duration::from_millis(200));
        let pid = child.id() as libc::pid_t;
        // SAFETY: signals our own child.
        unsafe { libc::kill(pid, libc::SIGINT) };
        std::thread::sleep(Duration::from_millis(delay_ms));
        // SAFETY: as above.
        unsafe { libc::kill(pid, libc::SIGINT) };
        let run = wait_limited(child, &out.path().join("stderr.txt"), started);
        assert_eq!(run.code, Some(130), "{}", run.stderr);
        assert!(
            temporary_files(out.path()).is_empty(),
            "delay {delay_ms} ms"
        );
        // Whatever was written is a whole part (a checkpoint or the final image).
        if image.exists() {
            assert!(samples_in(&image).end > 0);
        }
    }
}

#[test]
fn a_signal_while_loading_quits_at_once() {
    let _serial = serial();
    let out = tempfile::tempdir().unwrap();
    let image = out.path().join("never.png");
    let log = out.path().join("stderr.txt");
    let started = Instant::now();
    // The USD reader never finishes this file (tests/data/fuzz_hangs/README.md).
    let hangs = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/fuzz_hangs");
    let child = spawn_limited(
        &[
            "material_connection_loop.usda",
            "-o",
            image.to_str().unwrap(),
        ],
        &hangs,
        &log,
    );
    std::thread::sleep(Duration::from_millis(300));
    // SAFETY: signals our own child.
    unsafe { libc::kill(child.id() as libc::pid_t, libc::SIGINT) };
    let signalled = Instant::now();
    let run = wait_limited(child, &log, started);
    assert_eq!(run.code, Some(130), "{}", run.stderr);
    assert!(
        run.stderr.contains("quitting before rendering"),
        "{}",
        run.stderr
    );
    assert!(
        signalled.elapsed() < Duration::from_secs(5),
        "{:?}",
        signalled.elapsed()
    );
    assert!(!image.exists());
}

#[test]
fn a_killed_checkpointed_render_resumes_into_the_uninterrupted_image() {
    let _serial = serial();
    let out = tempfile::tempdir().unwrap();
    let (child, checkpoint, started) = start_long_render(out.path(), &["--checkpoint", "0.05"]);
    // Kill it some time after its first checkpoint, wherever it then is.
    while !checkpoint.exists() {
        assert!(started.elapsed() < TIME_LIMIT, "no checkpoint was written");
        std::thread::sleep(Duration::from_millis(10));
    }
    std::thread::sleep(Duration::from_millis(300));
    // SAFETY: kills our own child, giving it no chance to write anything more.
    unsafe { libc::kill(child.id() as libc::pid_t, libc::SIGKILL) };
    let killed = child.id();
    let run = wait_limited(child, &out.path().join("stderr.txt"), started);
    assert_eq!(run.code, None, "killed");
    let done = samples_in(&checkpoint);
    // What a kill during a checkpoint's write leaves: the next run in the folder removes it.
    let host: String = std::fs::read_to_string("/proc/sys/kernel/hostname")
        .unwrap()
        .trim()
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || c == '.' {
                c
            } else {
                '_'
            }
        })
        .collect();
    let stranded = out
        .path()
        .join(format!(".gridtrace-{host}-{killed}-Ab12Cd.tmp"));
    std::fs::write(&stranded, b"half a checkpoint").unwrap();
    assert!(done.start == 0 && done.end > 0, "{done:?}");
    let end = done.end + 7;
    let dir = scenes();
    let path = |name: &str| out.path().join(name).to_str().unwrap().to_string();
    let render = |args: &[&str]| {
        let output = limited::gridtrace(args, &dir);
        assert!(
            output.status.success(),
            "{}",
            String::from_utf8_lossy(&output.stderr)
        );
    };
    let rest = format!("{}..{end}", done.end);
    let scene = cornell_box();
    render(&[
        &scene,
        "-o",
        &path("rest.exr"),
        "--width",
        "32",
        "--samples",
        &rest,
        "-q",
    ]);
    assert!(
        !stranded.exists(),
        "the killed run's temporary file is still there"
    );
    render(&[
        "merge",
        &path("partial.exr"),
        &path("rest.exr"),
        "-o",
        &path("merged.exr"),
        "--samples",
        &format!("0..{end}"),
        "-q",
    ]);
    render(&[
        &scene,
        "-o",
        &path("whole.exr"),
        "--width",
        "32",
        "--spp",
        &end.to_string(),
        "-q",
    ]);
    let (merged, merged_alpha) = read_exr_rgba(Path::new(&path("merged.exr"))).unwrap();
    let (whole, whole_alpha) = read_exr_rgba(Path::new(&path("whole.exr"))).unwrap();
    assert_eq!(merged_alpha, whole_alpha);
    for (i, (m, w)) in merged.iter().zip(&whole).enumerate() {
        let scale = m.abs().max(w.abs()).max_element();
        assert!(
            (*m - *w).abs().max_element() <= MERGE_TOLERANCE * scale,
            "pixel {i}: {m} vs {w} (checkpoint held samples {done:?})"
        );
    }
}

/// A scene, a part to merge or an image to denoise named on the command line that is a
/// FIFO is refused at once with the loader's own message for such files: opened, it would
/// wait for a writer (merge and denoise forever, a render until the load timeout).
#[test]
fn files_named_on_the_command_line_that_are_not_regular_are_refused_at_once() {
    let _serial = serial();
    let dir = tempfile::tempdir().unwrap();
    for name in ["scene.glb", "part.exr"] {
        let status = Command::new("mkfifo")
            .arg(dir.path().join(name))
            .status()
            .expect("mkfifo runs");
        assert!(status.success(), "mkfifo {name}");
    }
    let commands: [&[&str]; 4] = [
        &["scene.glb", "-o", "out.exr"],
        &["--inspect", "scene.glb"],
        &["merge", "part.exr", "-o", "out.exr"],
        &["denoise", "part.exr", "-o", "out.exr"],
    ];
    for args in commands {
        let run = run_limited(args, dir.path());
        let named = if args.contains(&"part.exr") {
            "part.exr"
        } else {
            "scene.glb"
        };
        assert_eq!(run.code, Some(2), "{args:?}: {}", run.stderr);
        assert_eq!(
            run.stderr.trim(),
            format!("error: '{named}' is a FIFO, not a regular file; refused"),
            "{args:?}"
        );
        assert!(
            run.elapsed < Duration::from_secs(30),
            "{args:?}: {:?}",
            run.elapsed
        );
    }
}
