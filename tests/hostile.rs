//! The hostile-input corpus (made at test time by `tools/dev/make_hostile_inputs.py`, since it
//! needs a FIFO, a symbolic link, a hard link and a sparse 3 GB file): every case ends in a
//! one-line error naming the file, or a warning naming it and an image, within the time
//! limit and a 2 GiB address-space limit. No message holds a byte of a file outside the
//! scene's folder, nor a control character from a file.

#[path = "support/limited/mod.rs"]
mod limited;

use std::path::Path;
use std::process::Command;
use std::time::Duration;

use limited::{MEMORY_LIMIT, corpus, run_limited, scenes, serial, temporary_files};

/// The secret outside the scenes' folder (tools/dev/make_hostile_inputs.py writes it).
const SECRET: &[u8] = b"TOPSECRET-canary-7f3a-gridtrace-hostile-input-corpus!!!!";

enum Expect {
    /// Exit code 2 and one line: `error: <file>: ...<text>...`.
    Error(&'static str),
    /// Exit code 0, an image, and a warning naming the file that contains the text.
    Warning(&'static str),
    /// Exit code 0 and an image.
    Image,
}

const CASES: &[(&str, Expect)] = &[
    // Reading outside the roots, or files that are not regular.
    (
        "leak_relative.gltf",
        Expect::Error("buffer 1: '../secret.txt' is outside the folders"),
    ),
    (
        "leak_absolute.gltf",
        Expect::Error("is outside the folders this scene may read"),
    ),
    ("leak_file_uri.gltf", Expect::Error("buffer 1: 'file:///")),
    (
        "leak_percent.gltf",
        Expect::Error("buffer 1: '../secret.txt' is outside"),
    ),
    (
        "leak_proc.gltf",
        Expect::Error("'/proc/self/environ' is outside"),
    ),
    ("leak_symlink.gltf", Expect::Error("'link.bin' is outside")),
    (
        "fifo_buffer.gltf",
        Expect::Error("'pipe.bin' is a FIFO, not a regular file"),
    ),
    ("dev_stdin.gltf", Expect::Error("'/dev/stdin' is outside")),
    ("dev_zero.gltf", Expect::Error("'/dev/zero' is outside")),
    ("huge_buffer.gltf", Expect::Image),
    (
        "image_outside.gltf",
        Expect::Warning("image 0: '../secret.txt' is outside"),
    ),
    (
        "usd_sublayer_outside.usda",
        Expect::Error("secret.usda' is outside"),
    ),
    (
        "usd_reference_outside.usda",
        Expect::Error("secret.usda' is outside"),
    ),
    (
        "usd_reference_fifo.usda",
        Expect::Error("pipe.usda' is a FIFO"),
    ),
    (
        "usd_texture_outside.usda",
        Expect::Warning("texture '../secret.txt' is outside"),
    ),
    // Aborts.
    (
        "usd_corrupt_reference.usda",
        Expect::Error("the USD reader crashed"),
    ),
    (
        "usd_corrupt_sublayer.usda",
        Expect::Error("the USD reader crashed"),
    ),
    (
        "usd_expression_reference.usda",
        Expect::Error("the USD reader crashed"),
    ),
    (
        "usd_deep_prims.usda",
        Expect::Error("nested 10000 levels deep"),
    ),
    (
        "usd_deep_hierarchy.usda",
        Expect::Error("/P0/…/P257: prim hierarchy deeper than 256"),
    ),
    (
        "usd_deep_dictionary.usda",
        Expect::Error("levels deep, more than the 500"),
    ),
    (
        "many_faces.ply.gz",
        Expect::Error("the mesh its header declares needs 7.2 GB"),
    ),
    // Time.
    ("ply_big_polygon.ply", Expect::Image),
    (
        "usd_big_polygon.usda",
        Expect::Warning("face 0 is a concave polygon of 200000 corners"),
    ),
    // Content dropped, impossible cameras and materials, overflowing counts.
    (
        "usd_missing_sublayer.usda",
        Expect::Warning("unresolved sublayer @not_there.usda@"),
    ),
    (
        "usd_many_missing_sublayers.usda",
        Expect::Warning("99000 more layers are missing past the first 1000"),
    ),
    (
        "usd_broken_reference.usda",
        Expect::Warning("malformed Reference layer"),
    ),
    (
        "usd_negative_counts.usda",
        Expect::Error("faceVertexCounts[0] is -3"),
    ),
    // Composition loops, packages with odd members, instancing without end.
    ("usd_sublayer_cycle.usda", Expect::Warning("sublayer cycle")),
    (
        "usd_self_reference.usda",
        Expect::Warning("composition arc cycle at /Ref"),
    ),
    (
        "usd_missing_reference.usda",
        Expect::Warning("not_there.usda@ at /Ref; its content is left out"),
    ),
    (
        "usd_internal_cycle.usda",
        Expect::Warning("composition arc cycle at /A"),
    ),
    (
        "usd_huge_counts.usda",
        Expect::Error("/Huge: faceVertexCounts add up to 4294967294"),
    ),
    (
        "usd_instancer_bomb.usda",
        Expect::Error("/Outer: point instancers place more than"),
    ),
    (
        "usd_instancer_bad_index.usda",
        Expect::Warning("/Scatter: protoIndices holds 7, but there are 1 prototypes"),
    ),
    (
        "usd_skel_bad_index.usda",
        Expect::Warning(
            "/Rig/Skin: skinning to /Rig/Skeleton not applied (joint index 7 for 1 joints)",
        ),
    ),
    (
        "usdz_odd_members.usdz",
        Expect::Warning("/Odd: texture '../escape.png' does not resolve"),
    ),
    (
        "usdz_deflate_bomb.usdz",
        Expect::Warning("member 'big.png' declares 2684354560 bytes, more than the memory budget"),
    ),
    (
        "camera_yfov_zero.gltf",
        Expect::Error("vertical field of view 0 rad"),
    ),
    (
        "camera_yfov_infinite.gltf",
        Expect::Error("vertical field of view inf rad"),
    ),
    (
        "camera_ortho_zero.gltf",
        Expect::Error("orthographic view 0x0 has no size"),
    ),
    (
        "camera_zero_matrix.gltf",
        Expect::Error("transform is not finite or is degenerate"),
    ),
    (
        "zero_scale.gltf",
        Expect::Warning("node 0: its transform is not finite or scales it to nothing"),
    ),
    (
        "ior_negative.gltf",
        Expect::Error("index of refraction -1.5 is not a positive number"),
    ),
    (
        "ior_infinite.gltf",
        Expect::Error("index of refraction inf is not a positive number"),
    ),
    (
        "count_overflow.gltf",
        Expect::Error("accessor 0 needs 55340232221128654860 bytes"),
    ),
    // Memory for the whole process: what is held counts against what is asked for.
    (
        "meshopt_huge_fallback.gltf",
        Expect::Error("buffer 1 needs 2.7 GB"),
    ),
    (
        "zero_filled_positions.gltf",
        Expect::Error("accessor 0 has no buffer view and 300000000 elements"),
    ),
    // Decompression bombs: refused by their headers, before anything is decoded.
    (
        "png_bomb.gltf",
        Expect::Warning("image 0: is too large: decoding its 12000x12000 pixels needs 4.6 GB"),
    ),
    (
        "zero_filled_indices.gltf",
        Expect::Error("accessor 1 has no buffer view and 300000000 elements"),
    ),
    (
        "zero_filled_sparse.gltf",
        Expect::Error("accessor 0 has no buffer view and 300000000 elements"),
    ),
    (
        "jpeg_bomb.gltf",
        Expect::Warning("image 0: is too large: decoding its 20000x20000 pixels needs"),
    ),
    (
        "rgba_png_bomb.gltf",
        Expect::Warning("image 0: is too large: decoding its 16000x16000 pixels needs"),
    ),
    (
        "webp_bomb.gltf",
        Expect::Warning("image 0: is too large: decoding its 16383x16383 pixels needs 8.6 GB"),
    ),
    (
        "usdz_png_bomb.usdz",
        Expect::Warning("texture 'bomb.png' is too large: decoding its 12000x12000 pixels"),
    ),
    (
        "usd_dome_bomb.usda",
        Expect::Warning("dome texture 'big_rle.hdr' is too large: decoding its 12000x6000 pixels"),
    ),
    (
        "usd_dome_exr_bomb.usda",
        Expect::Warning("dome texture 'big_zip.exr' is too large: decoding its 16000x8000 pixels"),
    ),
    // Control characters from the file reach the terminal escaped.
    (
        "escape_in_name.gltf",
        Expect::Error("mesh 0 'quad\\x1b[2J\\nerror: forged second line'"),
    ),
    (
        "escape_in_uri.gltf",
        Expect::Warning("image 0: '\\x1b]0;owned\\x07missing.png' not found"),
    ),
    // A hard link is the file itself; its bytes never reach a message.
    (
        "leak_hardlink.gltf",
        Expect::Error("indices[0] is past the 4 vertices"),
    ),
    (
        "huge_scale.gltf",
        Expect::Warning("node 0 reaches beyond 1e18 from the origin"),
    ),
    // Clipping that would hide everything, packages that are ambiguous or unreadable.
    (
        "camera_near_beyond_far.gltf",
        Expect::Warning("camera 0: znear 10 is beyond zfar 1; clipping from 1 instead"),
    ),
    (
        "usd_reversed_clipping.usda",
        Expect::Warning("/Cam: clippingRange (100, 0.1) is reversed; clipping from 0.1"),
    ),
    (
        "usdz_twin_members.usdz",
        Expect::Error("members share a name, so which one is meant is ambiguous"),
    ),
    (
        "usdz_bzip2_member.usdz",
        Expect::Error("member 'scene.usda' cannot be read (compression method not supported"),
    ),
];

/// No byte of the secret in `text`: neither its words nor the integers an index accessor
/// would make of them.
fn assert_no_secret(name: &str, text: &str) {
    assert!(
        !text.contains("TOPSECRET") && !text.contains("canary"),
        "{name}: {text}"
    );
    for word in SECRET.chunks_exact(4) {
        let n = u32::from_le_bytes(word.try_into().unwrap());
        assert!(!text.contains(&n.to_string()), "{name}: leaks {n}: {text}");
    }
}

/// Nothing in `text` a terminal would act on: no control character but the newline that
/// ends each line.
fn assert_no_control_characters(name: &str, text: &str) {
    let bad = text.chars().find(|&c| c != '\n' && c.is_control());
    assert!(bad.is_none(), "{name}: {bad:?} in {text:?}");
}

#[test]
fn every_hostile_scene_ends_in_a_clear_outcome_within_time_and_memory() {
    let _serial = serial();
    let scenes = scenes();
    let out = tempfile::tempdir().unwrap();
    let mut slowest = (Duration::ZERO, "");
    let mut hungriest = (0, "");
    for (name, expect) in CASES {
        let image = out.path().join(format!("{name}.png"));
        let args = [
            name,
            "-o",
            image.to_str().unwrap(),
            "--width",
            "16",
            "--spp",
            "1",
            "-q",
        ];
        let run = run_limited(&args, &scenes);
        let err = &run.stderr;
        assert!(!err.contains("panicked"), "{name}: {err}");
        assert_no_secret(name, err);
        assert_no_control_characters(name, err);
        match expect {
            Expect::Error(text) => {
                assert_eq!(run.code, Some(2), "{name}: {err}");
                assert_eq!(err.lines().count(), 1, "{name}: one line expected:\n{err}");
                assert!(
                    err.starts_with("error: ") && err.contains(name) && err.contains(text),
                    "{name}: expected '{text}':\n{err}"
                );
                assert!(!image.exists(), "{name}: an image was written");
            }
            Expect::Warning(text) => {
                assert_eq!(run.code, Some(0), "{name}: {err}");
                let warning = err.lines().find(|l| l.contains(text));
                assert!(
                    warning.is_some_and(|w| w.starts_with("warning: ") && w.contains(name)),
                    "{name}: no warning with '{text}':\n{err}"
                );
                assert!(image::open(&image).is_ok(), "{name}: no readable image");
            }
            Expect::Image => {
                assert_eq!(run.code, Some(0), "{name}: {err}");
                assert!(image::open(&image).is_ok(), "{name}: no readable image");
            }
        }
        if run.elapsed > slowest.0 {
            slowest = (run.elapsed, name);
        }
        if run.peak > hungriest.0 {
            hungriest = (run.peak, name);
        }
    }
    assert!(hungriest.0 < MEMORY_LIMIT, "{hungriest:?}");
    assert!(temporary_files(out.path()).is_empty());
    println!(
        "{} cases; slowest {} in {:.2} s; most memory {} with {:.0} MB",
        CASES.len(),
        slowest.1,
        slowest.0.as_secs_f64(),
        hungriest.1,
        hungriest.0 as f64 / 1e6
    );
}

/// Subdivision takes the deepest level that fits `--max-memory`, and a shutter read at 64
/// instants keeps only what moves: neither passes the budget.
#[test]
fn subdivision_and_motion_steps_stay_within_the_budget() {
    let _serial = serial();
    let out = tempfile::tempdir().unwrap();
    let image = out.path().join("out.exr");
    let image = image.to_str().unwrap();
    let common = [image, "--width", "16", "--spp", "1", "-q"];
    let mut args = vec!["usd_subdivision_cage.usda", "--subdivision-level", "6"];
    args.extend(["--max-memory", "1G", "-o"]);
    args.extend(common);
    let run = run_limited(&args, &scenes());
    assert_eq!(run.code, Some(0), "{}", run.stderr);
    assert!(
        run.stderr.contains("/Cage: subdivision to level 6 needs")
            && run.stderr.contains("refined to level 5 instead"),
        "{}",
        run.stderr
    );
    assert!(run.peak < 1 << 30, "peak {} bytes", run.peak);
    let peak_with_steps = |steps: &str| {
        let mut args = vec![
            "usd_moving_grid.usda",
            "--frame",
            "5",
            "--shutter=-0.5..0.5",
        ];
        args.extend(["--motion-steps", steps, "-o"]);
        args.extend(common);
        let run = run_limited(&args, &scenes());
        assert_eq!(run.code, Some(0), "{}", run.stderr);
        run.peak
    };
    let (two, many) = (peak_with_steps("2"), peak_with_steps("64"));
    println!("moving grid: peak {two} bytes at 2 motion steps, {many} at 64");
    assert!(many < 2 * two, "64 steps take {many} bytes, 2 steps {two}");
}

/// Key times of an animation read at `--frame` are held to the zero-filled accessor rule as
/// every other accessor is.
#[test]
fn an_animation_of_zero_filled_key_times_is_refused() {
    let _serial = serial();
    let out = tempfile::tempdir().unwrap();
    let image = out.path().join("never.png");
    let args = [
        "zero_filled_animation.gltf",
        "--frame",
        "1",
        "-o",
        image.to_str().unwrap(),
        "--width",
        "16",
        "--spp",
        "1",
        "-q",
    ];
    let run = run_limited(&args, &scenes());
    assert_eq!(run.code, Some(2), "{}", run.stderr);
    assert!(
        run.stderr.starts_with("error: ")
            && run.stderr.contains("zero_filled_animation.gltf")
            && run
                .stderr
                .contains("accessor 2 has no buffer view and 300000000 elements")
            && run.stderr.lines().count() == 1,
        "{}",
        run.stderr
    );
    assert!(run.peak < MEMORY_LIMIT, "peak {} bytes", run.peak);
    assert!(!image.exists());
}

/// One image file named by four spellings of its URI is decoded once.
#[test]
fn an_image_is_decoded_once_however_its_uri_is_spelt() {
    let _serial = serial();
    let run = limited::gridtrace(&["--inspect", "texture_aliases.gltf"], &scenes());
    let report = String::from_utf8_lossy(&run.stdout);
    assert!(run.status.success(), "{}", limited::stderr(&run));
    assert_eq!(
        report.matches("textures: base colour").count(),
        4,
        "{report}"
    );
    assert!(report.contains("\ntextures: 1\n"), "{report}");
}

/// An environment map named on the command line is held to the same budget and checks as
/// one a scene names: too large for memory, or cut short, it is a one-line error.
#[test]
fn environment_maps_too_large_or_cut_short_are_refused() {
    let _serial = serial();
    let out = tempfile::tempdir().unwrap();
    let image = out.path().join("never.png");
    for (map, expected) in [
        (
            "big_rle.hdr",
            "big_rle.hdr: environment map is too large: decoding its 12000x6000 pixels",
        ),
        (
            "big_zip.exr",
            "big_zip.exr: environment map is too large: decoding its 16000x8000 pixels",
        ),
        ("cut.hdr", "cut.hdr: environment map cannot be decoded"),
    ] {
        let args = [
            "huge_buffer.gltf",
            "--environment",
            map,
            "-o",
            image.to_str().unwrap(),
            "--width",
            "16",
            "--spp",
            "1",
            "-q",
        ];
        let run = run_limited(&args, &scenes());
        assert_eq!(run.code, Some(2), "{map}: {}", run.stderr);
        assert!(
            run.stderr.starts_with("error: ")
                && run.stderr.contains(expected)
                && run.stderr.lines().count() == 1,
            "{map}: {}",
            run.stderr
        );
        assert!(!image.exists());
    }
}

#[test]
fn a_reader_that_loops_is_ended_by_the_load_timeout() {
    let _serial = serial();
    let hangs = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/fuzz_hangs");
    let out = tempfile::tempdir().unwrap();
    // The binary layer's churn may instead reach the 2 GiB limit first: then the probe
    // reports the reader's crash. Either way, one line naming the file, in time.
    let timed_out = "loading did not finish within 2 s";
    for (name, outcomes) in [
        ("material_connection_loop.usda", &[timed_out][..]),
        ("unterminated_token_array.usda", &[timed_out][..]),
        (
            "slow_binary_layer.usdc",
            &[timed_out, "the USD reader crashed"],
        ),
    ] {
        let image = out.path().join("never.png");
        let args = [name, "-o", image.to_str().unwrap(), "--load-timeout", "2"];
        let run = run_limited(&args, &hangs);
        assert_eq!(run.code, Some(2), "{name}: {}", run.stderr);
        let prefix = format!("error: {name}: ");
        assert!(
            run.stderr.starts_with(&prefix)
                && outcomes.iter().any(|o| run.stderr.contains(o))
                && run.stderr.lines().count() == 1,
            "{name}: {}",
            run.stderr
        );
        assert!(run.elapsed < Duration::from_secs(30), "{:?}", run.elapsed);
        assert!(!image.exists());
    }
}

#[test]
fn an_asset_path_lets_a_scene_read_another_folder() {
    let _serial = serial();
    let scenes = scenes();
    let out = tempfile::tempdir().unwrap();
    let image = out.path().join("ok.png");
    let outside = corpus().to_str().unwrap().to_string();
    let args = [
        "usd_reference_outside.usda",
        "-o",
        image.to_str().unwrap(),
        "--width",
        "8",
        "--spp",
        "1",
        "-q",
        "--asset-path",
        &outside,
    ];
    let run = run_limited(&args, &scenes);
    assert_eq!(run.code, Some(0), "{}", run.stderr);
}

#[test]
fn films_and_parts_larger_than_memory_are_refused_before_allocation() {
    let _serial = serial();
    let scenes = scenes();
    let out = tempfile::tempdir().unwrap();
    let image = out.path().join("big.exr");
    let image = image.to_str().unwrap();
    let run = run_limited(
        &[
            "huge_buffer.gltf",
            "-o",
            image,
            "--width",
            "16384",
            "--height",
            "16384",
            "-q",
        ],
        &scenes,
    );
    assert_eq!(run.code, Some(2), "{}", run.stderr);
    assert!(
        run.stderr.starts_with("error: a 16384x16384 film needs")
            && run.stderr.lines().count() == 1,
        "{}",
        run.stderr
    );
    // A part whose header claims 16384² pixels in a few kilobytes.
    let part = out.path().join("part.exr");
    let small = [
        "huge_buffer.gltf",
        "-o",
        part.to_str().unwrap(),
        "--width",
        "4",
        "--samples",
        "0..1",
        "-q",
    ];
    assert_eq!(run_limited(&small, &scenes).code, Some(0));
    let claiming = out.path().join("claims-16384.exr");
    let status = Command::new("python3")
        .arg(Path::new(env!("CARGO_MANIFEST_DIR")).join("tools/dev/make_hostile_inputs.py"))
        .args([
            "--exr-claiming",
            part.to_str().unwrap(),
            "16384",
            claiming.to_str().unwrap(),
        ])
        .status()
        .unwrap();
    assert!(status.success());
    let size = std::fs::metadata(&claiming).unwrap().len();
    assert!(size < 16 << 10, "{size} bytes");
    let merged = out.path().join("merged.exr");
    let run = run_limited(
        &[
            "merge",
            claiming.to_str().unwrap(),
            "-o",
            merged.to_str().unwrap(),
        ],
        out.path(),
    );
    assert_eq!(run.code, Some(2), "{}", run.stderr);
    assert!(
        run.stderr.contains("claims-16384.exr")
            && run.stderr.contains("16384x16384 pixels, more than its")
            && run.stderr.lines().count() == 1,
        "{}",
        run.stderr
    );
}
