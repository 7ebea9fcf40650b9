//! The Blender add-on (blender/gridtrace_blender/) in Blender itself: the PyPI `bpy` package
//! (Blender 5.0 as a Python module, installed by tools/dev/install-blender.sh) runs
//! tools/blender/test_addon.py against this build's binary. The script checks that F12 and
//! its passes equal a command-line render of the exported scene bit for bit, that Render
//! Animation renders the frames `--frame` does, that Esc leaves a partial image and
//! nothing running, that failures are Blender reports, that Blender's settings reach the
//! command line, and that the farm operator writes a Slurm job. Then the project's Blender
//! reference scenes, rendered by the add-on, are held to their Cycles references with the
//! criteria of the other reference tests.

#[path = "support/image_stats/mod.rs"]
mod image_stats;

use std::path::Path;
use std::process::Command;

use image_stats::{Halves, check_agreement, read_exr, reference};

/// Samples per pixel of the add-on's renders of the reference scenes (as the command-line
/// reference tests).
const SPP: u32 = 1024;

/// The Python that has `bpy`: the project's virtual environment, else the system's.
fn python() -> String {
    let venv = Path::new(env!("CARGO_MANIFEST_DIR")).join(".blender-venv/bin/python");
    if venv.exists() {
        venv.display().to_string()
    } else {
        "python3".into()
    }
}

#[test]
fn the_blender_add_on_renders_what_the_command_line_renders() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let work = tempfile::tempdir().unwrap();
    let output = Command::new(python())
        .arg(root.join("tools/blender/test_addon.py"))
        .arg(env!("CARGO_BIN_EXE_gridtrace"))
        .current_dir(work.path())
        .output()
        .expect(
            "python runs tools/blender/test_addon.py (tools/dev/install-blender.sh installs bpy)",
        );
    let stdout = String::from_utf8_lossy(&output.stdout);
    let checks: Vec<&str> = stdout
        .lines()
        .filter(|l| l.starts_with("ok:") || l.starts_with("FAILED"))
        .collect();
    println!("{}", checks.join("\n"));
    assert!(
        output.status.success() && stdout.contains("all add-on checks passed"),
        "{stdout}\n{}",
        String::from_utf8_lossy(&output.stderr)
    );
    assert_eq!(checks.iter().filter(|l| l.starts_with("ok:")).count(), 6);
}

#[test]
fn the_add_on_agrees_with_cycles_on_the_reference_scenes() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let out = tempfile::tempdir().unwrap();
    let output = Command::new(python())
        .arg(root.join("tools/blender/test_addon.py"))
        .arg(env!("CARGO_BIN_EXE_gridtrace"))
        .arg("--references")
        .arg(out.path())
        .arg(SPP.to_string())
        .current_dir(out.path())
        .output()
        .expect("python runs tools/blender/test_addon.py");
    let stdout = String::from_utf8_lossy(&output.stdout);
    assert!(
        output.status.success(),
        "{stdout}\n{}",
        String::from_utf8_lossy(&output.stderr)
    );
    for name in [
        "cornell_box",
        "principled_metals",
        "principled_plastics",
        "lighting_lamps",
        "lighting_hdr",
        "lighting_dof",
    ] {
        let half = |h: &str| read_exr(&out.path().join(format!("{name}_{h}.exr")));
        let ours = Halves {
            a: half("a"),
            b: half("b"),
        };
        check_agreement(
            &format!("{name} through the add-on at {SPP} spp vs Cycles"),
            &ours,
            &reference(name),
        );
    }
}
