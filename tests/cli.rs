//! The `gridtrace` command as a user runs it.

#[path = "support/binary/mod.rs"]
mod binary;
#[path = "support/common/mod.rs"]
mod common;

use std::path::Path;
use std::process::Command;

use binary::{gridtrace, stderr};

fn asset(name: &str) -> String {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("assets")
        .join(name)
        .display()
        .to_string()
}

#[test]
fn renders_the_bundled_scene_to_png_and_exr() {
    let dir = tempfile::tempdir().unwrap();
    let out = gridtrace(
        &[
            &asset("cornell_box.glb"),
            "-o",
            "box.png",
            "--width",
            "48",
            "--spp",
            "4",
        ],
        dir.path(),
    );
    assert!(out.status.success(), "{}", stderr(&out));
    // The camera's aspect ratio is 1: the height follows the width.
    let png = image::open(dir.path().join("box.png")).unwrap().to_rgb8();
    assert_eq!(png.dimensions(), (48, 48));
    // The red wall is on the left, the green wall on the right.
    let left = png.get_pixel(3, 24);
    let right = png.get_pixel(44, 24);
    let (left, right) = (left.0.map(i32::from), right.0.map(i32::from));
    assert!(
        left[0] > left[1] + 40 && right[1] > right[0] + 20,
        "left {left:?}, right {right:?}"
    );
    let summary = stderr(&out);
    assert!(
        summary.contains("samples/s") && summary.contains("rays/s"),
        "{summary}"
    );

    let out = gridtrace(
        &[
            &asset("cornell_spheres.glb"),
            "-o",
            "s.exr",
            "--width",
            "40",
            "--height",
            "30",
            "--spp",
            "2",
            "-q",
        ],
        dir.path(),
    );
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(
        stderr(&out).contains("aspect ratio"),
        "a note says the vertical field of view is kept"
    );
    let exr = exr::prelude::read_first_rgba_layer_from_file(
        dir.path().join("s.exr"),
        |size, _| vec![[0f32; 4]; size.width() * size.height()],
        |pixels: &mut Vec<[f32; 4]>, pos, (r, g, b, a): (f32, f32, f32, f32)| {
            pixels[pos.y() * 40 + pos.x()] = [r, g, b, a]
        },
    )
    .unwrap();
    let size = exr.layer_data.size;
    assert_eq!((size.width(), size.height()), (40, 30));
    let spp = exr
        .layer_data
        .attributes
        .other
        .get(&exr::meta::attribute::Text::from("spp"));
    assert_eq!(
        spp,
        Some(&exr::meta::attribute::AttributeValue::I32(2)),
        "the header records the samples per pixel"
    );
    let pixels = &exr.layer_data.channel_data.pixels;
    assert!(pixels.iter().all(|p| p.iter().all(|c| c.is_finite())));
    assert!(
        pixels.iter().any(|p| p[0] > 1.0),
        "the light is brighter than 1 in linear EXR"
    );
    // Alpha is coverage: the box fills the centre; the wider-than-square view sees past
    // its side walls at the left and right edges.
    assert_eq!(pixels[15 * 40 + 20][3], 1.0);
    assert!(pixels.iter().all(|p| (0.0..=1.0).contains(&p[3])));
    assert!(
        pixels[15 * 40][3] < 1.0,
        "left edge alpha {}",
        pixels[15 * 40][3]
    );
}

#[test]
fn without_output_it_writes_scene_stem_exr_in_the_current_folder() {
    let dir = tempfile::tempdir().unwrap();
    let out = gridtrace(
        &[
            &asset("cornell_box.glb"),
            "--width",
            "8",
            "--spp",
            "1",
            "-q",
        ],
        dir.path(),
    );
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(dir.path().join("cornell_box.exr").is_file());
}

#[test]
fn the_image_does_not_depend_on_the_thread_count() {
    let dir = tempfile::tempdir().unwrap();
    let scene = asset("cornell_spheres.glb");
    for (threads, name) in [("1", "one.exr"), ("2", "two.exr")] {
        let out = gridtrace(
            &[
                &scene,
                "-o",
                name,
                "--width",
                "24",
                "--spp",
                "3",
                "--threads",
                threads,
                "-q",
            ],
            dir.path(),
        );
        assert!(out.status.success(), "{}", stderr(&out));
    }
    assert_eq!(
        std::fs::read(dir.path().join("one.exr")).unwrap(),
        std::fs::read(dir.path().join("two.exr")).unwrap()
    );
}

#[test]
fn errors_are_one_line_with_exit_code_2() {
    let dir = tempfile::tempdir().unwrap();
    let cases: [(&[&str], &str); 5] = [
        (&["missing.glb"], "missing.glb"),
        (&[&asset("cornell_box.glb"), "-o", "out.jpg"], "out.jpg"),
        (
            &[&asset("cornell_box.glb"), "--camera", "Nope", "-o", "x.png"],
            "Nope",
        ),
        (
            &[&asset("cornell_box.glb"), "-o", "no/such/folder/x.png"],
            "x.png",
        ),
        (
            &[
                &asset("cornell_box.glb"),
                "--frame",
                "12",
                "--animation",
                "Walk",
            ],
            "no animation 'Walk'",
        ),
    ];
    for (args, named) in cases {
        let out = gridtrace(args, dir.path());
        let err = stderr(&out);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {err}");
        assert_eq!(err.trim_end().lines().count(), 1, "{args:?}: {err}");
        assert!(
            err.starts_with("error: ") && err.contains(named),
            "{args:?}: {err}"
        );
        assert!(!err.contains("panicked"), "{err}");
    }
    assert_eq!(
        std::fs::read_dir(dir.path()).unwrap().count(),
        0,
        "nothing written on error"
    );
}

#[test]
fn a_scene_without_emitters_is_lit_by_the_studio_light_unless_asked_for_black() {
    let dir = tempfile::tempdir().unwrap();
    let scene = common::write_gltf(dir.path(), "dark.gltf", &common::quad_document());
    let render = |extra: &[&str], output: &str| {
        let mut args = vec![
            scene.to_str().unwrap(),
            "-o",
            output,
            "--width",
            "8",
            "--spp",
            "4",
        ];
        args.extend_from_slice(extra);
        let out = gridtrace(&args, dir.path());
        assert!(out.status.success(), "{}", stderr(&out));
        let png = image::open(dir.path().join(output)).unwrap().to_rgb8();
        (stderr(&out), png)
    };
    let (err, lit) = render(&[], "lit.png");
    assert!(
        err.lines()
            .any(|l| l.starts_with("note: ") && l.contains("default studio environment")),
        "{err}"
    );
    // Every pixel sees the quad or the studio's grey sky.
    assert!(lit.pixels().all(|p| p.0.iter().all(|&c| c > 20)), "{lit:?}");
    let (err, dark) = render(&["--environment", "none"], "dark.png");
    assert!(
        err.contains("warning: ") && err.contains("no emitters"),
        "{err}"
    );
    assert!(dark.pixels().all(|p| p.0 == [0, 0, 0]));
}

#[test]
fn help_explains_every_option() {
    let out = gridtrace(&["--help"], Path::new("."));
    assert!(out.status.success());
    let help = String::from_utf8_lossy(&out.stdout);
    for option in [
        "--output",
        "--spp",
        "--width",
        "--height",
        "--max-depth",
        "--seed",
        "--threads",
        "--camera",
        "--quiet",
        "--environment",
        "--environment-strength",
        "--environment-rotation",
        "--hide-environment",
        "--fstop",
        "--focus-distance",
        "--filter",
        "--exposure",
        "--view-transform",
    ] {
        assert!(help.contains(option), "--help lacks {option}:\n{help}");
    }
}

#[test]
fn ctrl_c_stops_after_the_current_pass_and_writes_the_image_so_far() {
    let dir = tempfile::tempdir().unwrap();
    let log = dir.path().join("stderr.txt");
    let child = Command::new(env!("CARGO_BIN_EXE_gridtrace"))
        .args([
            &asset("cornell_box.glb"),
            "-o",
            "partial.exr",
            "--width",
            "64",
            "--spp",
            "1000000",
        ])
        .current_dir(dir.path())
        .stderr(std::fs::File::create(&log).unwrap())
        .spawn()
        .unwrap();
    let child = binary::Owned::new(child);
    // Once rendering has begun, interrupt as a terminal's Ctrl-C would.
    assert!(
        binary::wait_for_text(&log, "prepared in", std::time::Duration::from_secs(180)),
        "the render never started"
    );
    let killed = Command::new("kill")
        .args(["-INT", &child.id().to_string()])
        .status()
        .unwrap();
    assert!(killed.success());
    let status = child.release().wait().unwrap();
    let out = std::process::Output {
        status,
        stdout: Vec::new(),
        stderr: std::fs::read(&log).unwrap(),
    };
    let err = stderr(&out);
    assert_eq!(out.status.code(), Some(130), "{err}");
    assert!(
        err.contains("stopped after") && err.contains("of 1000000 samples per pixel"),
        "{err}"
    );
    let meta = exr::meta::MetaData::read_from_file(dir.path().join("partial.exr"), false).unwrap();
    let spp = match meta.headers[0]
        .own_attributes
        .other
        .get(&exr::meta::attribute::Text::from("spp"))
    {
        Some(exr::meta::attribute::AttributeValue::I32(n)) => *n,
        other => panic!("no spp attribute: {other:?}"),
    };
    assert!((1..1_000_000).contains(&spp), "spp {spp}");
    assert!(err.contains(&format!("stopped after {spp} of")), "{err}");
}

#[test]
fn inspect_lists_what_was_loaded_and_renders_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let scene = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/scenes/punctual_lights.glb");
    let out = gridtrace(&["--inspect", &scene.display().to_string()], dir.path());
    assert!(out.status.success(), "{}", stderr(&out));
    let report = String::from_utf8_lossy(&out.stdout);
    for expected in [
        "meshes: 6 (2228 triangles)",
        "'Panel': black; base colour (0.000, 0.000, 0.000)",
        "area light, radiance (1.800, 6.000, 2.400)",
        "one-sided",
        // 60 W at colour (1, 0.8, 0.6): 60 × 0.8 = 48 W on average over the channels.
        "'Point' (node 6 'Point'): point at (0.900, 1.600, 0.600)",
        "48.00 W",
        "directional towards",
        "cameras: 1",
        "vertical field of view 45.0°",
        "warnings: 0",
    ] {
        assert!(
            report.contains(expected),
            "missing {expected:?} in:\n{report}"
        );
    }
    assert_eq!(
        std::fs::read_dir(dir.path()).unwrap().count(),
        0,
        "nothing written"
    );

    // Warnings are part of the report.
    let mut doc = common::quad_document();
    doc["extensionsUsed"] = serde_json::json!(["EXT_unknown"]);
    let path = common::write_gltf(dir.path(), "w.gltf", &doc);
    let out = gridtrace(&["--inspect", &path.display().to_string()], dir.path());
    let report = String::from_utf8_lossy(&out.stdout);
    assert!(
        report.contains("warnings: 1") && report.contains("EXT_unknown"),
        "{report}"
    );
}
