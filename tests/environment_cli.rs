//! The environment options as a user gives them: a downloaded model with no light renders
//! visibly under the studio light, `--environment` takes an HDR file or a colour,
//! `--environment-strength` scales it, `--environment-rotation` turns it, and
//! `--hide-environment` keeps its light but shows the camera black, alpha 0.

#[path = "support/binary/mod.rs"]
mod binary;

use std::path::{Path, PathBuf};

use binary::{gridtrace, stderr};

fn scene(name: &str) -> String {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data/scenes")
        .join(name)
        .display()
        .to_string()
}

/// Renders `file` at 24×24, 8 spp (unless `extra` names samples) into `output` with
/// `extra` options; returns stderr and the RGBA pixels.
fn render(dir: &Path, file: &str, output: &str, extra: &[&str]) -> (String, Vec<[f32; 4]>) {
    let path = scene(file);
    let mut args = vec![
        path.as_str(),
        "-o",
        output,
        "--width",
        "24",
        "--height",
        "24",
    ];
    if !extra.contains(&"--samples") {
        args.extend_from_slice(&["--spp", "8"]);
    }
    args.extend_from_slice(extra);
    let out = gridtrace(&args, dir);
    assert!(out.status.success(), "{file} {extra:?}: {}", stderr(&out));
    let image = image::open(dir.join(output)).unwrap().to_rgba32f();
    (stderr(&out), image.pixels().map(|p| p.0).collect())
}

fn mean(pixels: &[[f32; 4]]) -> f64 {
    pixels
        .iter()
        .map(|p| (p[0] + p[1] + p[2]) as f64)
        .sum::<f64>()
        / (3 * pixels.len()) as f64
}

/// Files written by other tools (trimesh, pygltflib, Pixar's USD library; see
/// `tools/dev/make_third_party.py`), with no light and no camera, come out lit, framed and with
/// the note that says how.
#[test]
fn models_without_lights_or_camera_render_visibly_with_a_note() {
    let dir = tempfile::tempdir().unwrap();
    for file in [
        "third_party/trimesh_shapes.glb",
        "third_party/pygltflib_plate.gltf",
        "third_party/usd_core_disc.usda",
    ] {
        let (err, pixels) = render(dir.path(), file, "model.exr", &[]);
        assert!(
            err.lines().any(|l| l.starts_with("note: ")
                && l.contains("default studio environment")
                && l.contains("--environment none")),
            "{file}: {err}"
        );
        // The model covers a good part of the frame (alpha 1 where it is hit) and is lit.
        let covered: Vec<[f32; 4]> = pixels.iter().copied().filter(|p| p[3] == 1.0).collect();
        let share = covered.len() as f64 / pixels.len() as f64;
        assert!(
            (0.1..0.9).contains(&share),
            "{file}: covers {share:.2} of the frame"
        );
        assert!(
            mean(&covered) > 0.1,
            "{file}: the model is dark ({})",
            mean(&covered)
        );
    }
}

/// A product model whose only emitters are its headlights (exported by Blender with a
/// camera, no lamps and no world; tools/blender/make_product.py) is lit by the studio light
/// with a note saying why, since the camera sees mostly background; `--environment none`
/// leaves only the headlights. The Cornell box, lit by its ceiling panel with the camera
/// seeing walls everywhere, stays as it is.
#[test]
fn product_models_with_small_emitters_get_the_studio_light_and_rooms_do_not() {
    let dir = tempfile::tempdir().unwrap();
    for file in ["product_emitters.glb", "product_emitters.usdc"] {
        let (err, pixels) = render(dir.path(), file, "product.exr", &[]);
        assert!(
            err.lines().any(|l| l.starts_with("note: ")
                && l.contains("only emissive surfaces light the scene")
                && l.contains("% of the view is empty background")
                && l.contains("--environment none")),
            "{file}: {err}"
        );
        let covered: Vec<[f32; 4]> = pixels.iter().copied().filter(|p| p[3] == 1.0).collect();
        assert!(mean(&covered) > 0.1, "{file}: the model is dark");
        let (err, dark) = render(dir.path(), file, "dark.exr", &["--environment", "none"]);
        assert!(!err.contains("studio"), "{file}: {err}");
        let lit = dark.iter().filter(|p| p[0] + p[1] + p[2] > 0.0).count();
        assert!(
            lit < dark.len() / 10,
            "{file}: {lit} pixels lit without the studio"
        );
    }
    let cornell = Path::new(env!("CARGO_MANIFEST_DIR")).join("assets/cornell_box.glb");
    let out = gridtrace(
        &[
            cornell.to_str().unwrap(),
            "-o",
            "cornell.exr",
            "--width",
            "16",
            "--spp",
            "1",
        ],
        dir.path(),
    );
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(!stderr(&out).contains("studio"), "{}", stderr(&out));
}

#[test]
fn environment_file_strength_rotation_and_hiding() {
    let dir = tempfile::tempdir().unwrap();
    let hdr = scene("textures/lighting_sky.hdr");
    let model = "third_party/trimesh_shapes.glb";
    let (err, base) = render(dir.path(), model, "base.exr", &["--environment", &hdr]);
    assert!(!err.contains("studio"), "{err}");
    let (_, strong) = render(
        dir.path(),
        model,
        "strong.exr",
        &["--environment", &hdr, "--environment-strength", "2"],
    );
    // One light, the same samples: twice the radiance everywhere.
    for (a, b) in base.iter().zip(&strong) {
        for c in 0..3 {
            assert!(
                (b[c] - 2.0 * a[c]).abs() <= 1e-5 * (1.0 + b[c]),
                "{a:?} {b:?}"
            );
        }
    }
    let (_, turned) = render(
        dir.path(),
        model,
        "turned.exr",
        &["--environment", &hdr, "--environment-rotation", "120"],
    );
    let moved = base
        .iter()
        .zip(&turned)
        .filter(|(a, b)| (a[0] - b[0]).abs() > 0.05)
        .count();
    assert!(moved > 0, "turning the sky changed nothing");
    let (_, full_turn) = render(
        dir.path(),
        model,
        "full_turn.exr",
        &["--environment", &hdr, "--environment-rotation", "360"],
    );
    for (a, b) in base.iter().zip(&full_turn) {
        assert!(
            (0..3).all(|c| (a[c] - b[c]).abs() <= 1e-3 * (1.0 + a[c])),
            "{a:?} {b:?}"
        );
    }
    let (_, hidden) = render(
        dir.path(),
        model,
        "hidden.exr",
        &["--environment", &hdr, "--hide-environment"],
    );
    for (a, h) in base.iter().zip(&hidden) {
        if a[3] == 0.0 {
            // Background: black and transparent, where it was the sky.
            assert_eq!(h, &[0.0; 4]);
            assert!(a[0] + a[1] + a[2] > 0.0);
        } else if a[3] == 1.0 {
            assert_eq!(a, h, "the model is lit the same");
        } else {
            // An edge pixel: its sky share is gone.
            assert!(h[3] == a[3] && (0..3).all(|c| h[c] <= a[c]), "{a:?} {h:?}");
        }
    }
    let (_, grey) = render(
        dir.path(),
        model,
        "grey.exr",
        &["--environment", "0.5,0.5,0.5"],
    );
    let background: Vec<&[f32; 4]> = grey.iter().filter(|p| p[3] == 0.0).collect();
    assert!(!background.is_empty() && background.iter().all(|p| p[..3] == [0.5; 3]));
    // An OpenEXR map: the one-colour world Blender's USD exporter wrote, (0.3, 0.45, 0.7).
    let exr = scene("textures/color_4C72B2.exr");
    let (_, sky) = render(dir.path(), model, "sky.exr", &["--environment", &exr]);
    let background: Vec<&[f32; 4]> = sky.iter().filter(|p| p[3] == 0.0).collect();
    assert!(!background.is_empty());
    for p in background {
        assert!(
            (p[0] - 0.3).abs() < 1e-6 && (p[1] - 0.45).abs() < 1e-6 && (p[2] - 0.7).abs() < 1e-6
        );
    }
}

#[test]
fn bad_environment_options_are_refused_in_one_line() {
    let dir = tempfile::tempdir().unwrap();
    let model = scene("third_party/trimesh_shapes.glb");
    let missing = PathBuf::from("no_such_sky.hdr");
    for (args, expected) in [
        (
            vec!["--environment", "1,2"],
            "neither one number, R,G,B nor a file",
        ),
        (
            vec!["--environment", "-1,0,0"],
            "must be finite and not negative",
        ),
        (
            vec!["--environment-strength", "-2"],
            "not a finite, non-negative number",
        ),
        (
            vec!["--environment", missing.to_str().unwrap()],
            "no_such_sky.hdr",
        ),
    ] {
        let mut all = vec![model.as_str(), "-o", "x.png", "--spp", "1", "--width", "8"];
        all.extend_from_slice(&args);
        let out = gridtrace(&all, dir.path());
        let err = stderr(&out);
        assert!(!out.status.success(), "{args:?}: {err}");
        assert!(err.contains(expected), "{args:?}: {err}");
        assert!(!err.contains("panicked"), "{args:?}: {err}");
    }
    assert!(!dir.path().join("x.png").exists());
}

/// The environment is part of what a render is: parts rendered under different ones are
/// not merged into one image.
#[test]
fn parts_under_different_environments_do_not_merge() {
    let dir = tempfile::tempdir().unwrap();
    let model = "third_party/trimesh_shapes.glb";
    render(dir.path(), model, "a.exr", &["--samples", "0..4"]);
    render(
        dir.path(),
        model,
        "b.exr",
        &["--samples", "4..8", "--environment-strength", "2"],
    );
    let out = gridtrace(&["merge", "a.exr", "b.exr", "-o", "m.exr"], dir.path());
    let err = stderr(&out);
    assert!(!out.status.success(), "{err}");
    assert!(
        err.contains("not parts of one render") && err.contains("strength=2"),
        "{err}"
    );
    assert!(!dir.path().join("m.exr").exists());
}
