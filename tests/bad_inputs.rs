//! Every file in the corpus `tests/data/bad/` (made by `tools/dev/make_bad_inputs.py`) gives its
//! exact outcome: a one-line error naming the file and the problem with exit code 2, or a
//! warning naming it and a rendered image. Nothing panics, hangs or writes a partial image.

use std::path::Path;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

enum Expect {
    /// Exit code 2, one line: `error: <file>: ...<text>...`.
    Error(&'static str),
    /// Exit code 0, an image, and a warning naming the file that contains the text.
    Warning(&'static str),
    /// Exit code 0, an image, and a note (what gridtrace chose for the user) naming the
    /// file that contains the text.
    Note(&'static str),
}

const CASES: &[(&str, Expect)] = &[
    (
        "truncated.glb",
        Expect::Error("truncated GLB: the header says 7532 bytes, the file has 3766"),
    ),
    ("bad_magic.glb", Expect::Error("not a GLB file")),
    (
        "bad_version.glb",
        Expect::Error("GLB version 3 is not supported"),
    ),
    ("syntax_error.gltf", Expect::Error("invalid glTF: expected")),
    (
        "accessor_past_view.gltf",
        Expect::Error("accessor 0 needs 480 bytes but buffer view 0 holds 48"),
    ),
    (
        "absurd_count.gltf",
        Expect::Error("accessor 0 needs 12000000000 bytes"),
    ),
    (
        "index_out_of_range.gltf",
        Expect::Error("indices[5] is past the 4 vertices"),
    ),
    (
        "overlapping_stride.gltf",
        Expect::Error("byte stride 4, smaller than accessor 0's 12-byte elements"),
    ),
    (
        "missing_buffer.gltf",
        Expect::Error("buffer 0: 'missing.bin' not found"),
    ),
    (
        "missing_image.gltf",
        Expect::Warning("image 0: 'missing texture.png' not found"),
    ),
    (
        "unknown_required_extension.gltf",
        Expect::Error("requires unsupported glTF extension(s): EXT_teleport"),
    ),
    (
        "animation_target_missing.gltf",
        Expect::Error("animations[0].channels[0].target: node 99 does not exist (1 nodes)"),
    ),
    (
        "cyclic_nodes.gltf",
        Expect::Error("node hierarchy too deep or too large"),
    ),
    (
        "deep_nodes.gltf",
        Expect::Error("node hierarchy too deep or too large"),
    ),
    (
        "nan_positions.gltf",
        Expect::Warning("skipping 1 triangle(s) with NaN or infinite corners"),
    ),
    (
        "inf_positions.gltf",
        Expect::Warning("skipping 1 triangle(s) with NaN or infinite corners"),
    ),
    (
        "degenerate_triangles.gltf",
        Expect::Warning("skipping 2 triangle(s) with no area"),
    ),
    (
        "no_triangles.gltf",
        Expect::Warning("the scene has no triangles"),
    ),
    (
        "no_emitters.gltf",
        Expect::Note("the scene has no lights; lighting it with the default studio environment"),
    ),
    (
        "truncated.ply",
        Expect::Error("Unexpected end of file while reading element 'face'"),
    ),
    (
        "truncated_binary.ply",
        Expect::Error("Unexpected end of file while reading binary element 'vertex'"),
    ),
    (
        "absurd_count.ply",
        Expect::Error(
            "the header declares at least 8000000000 bytes of data, but the file can hold at most 196",
        ),
    ),
    (
        "index_out_of_range.ply",
        Expect::Error("face 0 uses vertex 7, but there are 4 vertices"),
    ),
    (
        "nan_vertex.ply",
        Expect::Warning("skipping 2 triangle(s) with NaN or infinite corners"),
    ),
    ("not_a_ply.ply", Expect::Error("bad PLY header")),
];

/// Runs gridtrace on `scene`, failing the test if it takes longer than three minutes.
fn run(scene: &Path, out: &Path) -> (Option<i32>, String) {
    let mut child = Command::new(env!("CARGO_BIN_EXE_gridtrace"))
        .arg(scene)
        .args([
            "-o",
            out.to_str().unwrap(),
            "--width",
            "16",
            "--spp",
            "1",
            "-q",
        ])
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let start = Instant::now();
    while child.try_wait().unwrap().is_none() {
        if start.elapsed() > Duration::from_secs(180) {
            child.kill().unwrap();
            panic!("{}: gridtrace hung", scene.display());
        }
        std::thread::sleep(Duration::from_millis(20));
    }
    let output = child.wait_with_output().unwrap();
    (
        output.status.code(),
        String::from_utf8_lossy(&output.stderr).into_owned(),
    )
}

#[test]
fn every_bad_input_has_its_exact_outcome() {
    let corpus = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/bad");
    let on_disk = std::fs::read_dir(&corpus).unwrap().count();
    assert_eq!(
        on_disk,
        CASES.len(),
        "every file in tests/data/bad has a case here, and every case a file"
    );
    let dir = tempfile::tempdir().unwrap();
    for (name, expect) in CASES {
        let scene = corpus.join(name);
        let out = dir.path().join(format!("{name}.png"));
        let (code, err) = run(&scene, &out);
        assert!(!err.contains("panicked"), "{name}: {err}");
        match expect {
            Expect::Error(text) => {
                assert_eq!(code, Some(2), "{name}: {err}");
                assert_eq!(err.lines().count(), 1, "{name}: one line expected:\n{err}");
                assert!(
                    err.starts_with("error: ") && err.contains(name) && err.contains(text),
                    "{name}: {err}"
                );
                assert!(!out.exists(), "{name}: an image was written");
            }
            Expect::Warning(text) | Expect::Note(text) => {
                let prefix = match expect {
                    Expect::Note(_) => "note: ",
                    _ => "warning: ",
                };
                assert_eq!(code, Some(0), "{name}: {err}");
                let line = err.lines().find(|l| l.contains(text));
                assert!(
                    line.is_some_and(|w| w.starts_with(prefix) && w.contains(name)),
                    "{name}: no {prefix}line with '{text}':\n{err}"
                );
                assert!(image::open(&out).is_ok(), "{name}: no readable image");
            }
        }
    }
}
