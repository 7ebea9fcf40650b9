//! A render split into sample ranges and merged equals one render of all the samples, to
//! the stated f32 rounding bound; sets of parts that do not make one render are refused
//! with messages that name the files.

#[path = "support/binary/mod.rs"]
mod binary;
#[path = "support/common/mod.rs"]
mod common;

use std::ops::Range;
use std::path::{Path, PathBuf};

use binary::gridtrace;

use gridtrace::load::load_scene;
use gridtrace::output::merge::{MERGE_TOLERANCE, MergeError, merge_files, read_part};
use gridtrace::output::{ViewTransform, write_image, write_image_with_record};
use gridtrace::record::{RenderIdentity, RenderRecord};
use gridtrace::render::{Guiding, Image, RenderSettings, Renderer};
use gridtrace::scene::{Camera, Scene};

const SIZE: u32 = 32;
const SPP: u32 = 16;

fn cornell_box() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("assets/cornell_box.glb")
}

fn record(samples: Range<u32>, seed: u64) -> RenderRecord {
    RenderRecord {
        identity: RenderIdentity {
            version: "test".into(),
            scene_sha256: "0".repeat(64),
            dependencies_sha256: "0".repeat(64),
            camera: "'Camera'".into(),
            width: SIZE,
            height: SIZE,
            seed,
            max_depth: 8,
            options: String::new(),
            exposure: 0.0,
            aovs: String::new(),
        },
        scene_name: "cornell_box.glb".into(),
        samples,
        nonfinite: 0,
        noise_threshold: None,
        denoised: false,
    }
}

/// Renders samples `range` of the Cornell box, guided or not.
fn render_guided(
    renderer: &Renderer,
    camera: &Camera,
    range: Range<u32>,
    seed: u64,
    guiding: Guiding,
) -> Image {
    let settings = RenderSettings {
        width: SIZE,
        height: SIZE,
        samples: range.clone(),
        max_depth: 8,
        seed,
        guiding,
        ..RenderSettings::default()
    };
    renderer.render(camera, &settings, &|| {}).0
}

/// Renders samples `range` of the Cornell box.
fn render(renderer: &Renderer, camera: &Camera, range: Range<u32>, seed: u64) -> Image {
    render_guided(renderer, camera, range, seed, Guiding::Off)
}

/// The largest difference between two images relative to the larger value, and whether
/// every alpha is identical.
fn relative_difference(a: &Image, b: &Image) -> f32 {
    a.pixels
        .iter()
        .zip(&b.pixels)
        .flat_map(|(p, q)| (0..3).map(move |c| (p[c], q[c])))
        .map(|(x, y)| {
            let scale = x.abs().max(y.abs());
            if scale == 0.0 {
                0.0
            } else {
                (x - y).abs() / scale
            }
        })
        .fold(0.0, f32::max)
}

#[test]
fn merged_parts_equal_one_render_for_one_two_and_four_parts() {
    let scene = load_scene(&cornell_box()).unwrap().scene;
    let camera = scene.cameras[0].clone();
    let renderer = Renderer::new(&scene);
    let whole = render(&renderer, &camera, 0..SPP, 3);
    let dir = tempfile::tempdir().unwrap();
    let splits: [&[u32]; 3] = [&[0, SPP], &[0, 7, SPP], &[0, 3, 8, 13, SPP]];
    for bounds in splits {
        let mut paths = Vec::new();
        // Written in reverse: the merge does not depend on the order it is given the parts.
        for pair in bounds.windows(2).rev() {
            let range = pair[0]..pair[1];
            let part = render(&renderer, &camera, range.clone(), 3);
            paths.push(write_rendered_part(dir.path(), &part, range, 3));
        }
        let (merged, merged_record) = merge_files(&paths, Some(0..SPP)).unwrap();
        assert_eq!(merged_record.samples, 0..SPP);
        assert_eq!((merged.spp, merged.first_sample), (SPP, 0));
        assert_eq!(merged.alpha, whole.alpha, "alpha merges exactly");
        let difference = relative_difference(&merged, &whole);
        println!(
            "{} part(s): largest relative difference {difference:e} (bound {MERGE_TOLERANCE:e})",
            paths.len()
        );
        if paths.len() == 1 {
            assert_eq!(merged.pixels, whole.pixels, "one part is bit-identical");
        }
        assert!(
            difference <= MERGE_TOLERANCE,
            "{} parts: {difference:e} > {MERGE_TOLERANCE:e}",
            paths.len()
        );
    }
    // The comparison has teeth: another seed's render is nowhere near the bound.
    let other = render(&renderer, &camera, 0..SPP, 4);
    assert!(relative_difference(&other, &whole) > 1000.0 * MERGE_TOLERANCE);
}

/// Every process of a guided split render trains the same guide, whatever its range, so
/// guided parts merge to the guided whole as unguided ones do.
#[test]
fn guided_parts_merge_to_the_guided_whole() {
    // The room lit through a window: guiding takes part there (in a Cornell box, every
    // region may keep the BSDF alone).
    let scene = window_room();
    let camera = scene.cameras[0].clone();
    let renderer = Renderer::new(&scene);
    let whole = render_guided(&renderer, &camera, 0..SPP, 3, Guiding::On);
    let merged = merge_of_parts(&[0..5, 5..SPP], |range| {
        render_guided(&renderer, &camera, range, 3, Guiding::On)
    });
    assert_within_merge_tolerance(&merged, &whole);
    // Guiding changed the samples: the comparison is of guided renders.
    let unguided = render(&renderer, &camera, 0..SPP, 3);
    assert!(relative_difference(&unguided, &whole) > 1000.0 * MERGE_TOLERANCE);
}

/// Every process of a split render traces the same pre-pass, whatever its range, so parts
/// rendered with next-event roulette merge to the whole.
#[test]
fn parts_with_next_event_roulette_merge_to_the_whole() {
    // In the room lit through a window every light sample ends at the pane: the roulette
    // takes part there.
    let scene = window_room();
    let camera = scene.cameras[0].clone();
    let renderer = Renderer::new(&scene);
    let settings = |range: Range<u32>, next_event_roulette: bool| RenderSettings {
        width: SIZE,
        height: SIZE,
        samples: range,
        max_depth: 8,
        seed: 3,
        next_event_roulette,
        ..RenderSettings::default()
    };
    let (whole, stats) = renderer.render(&camera, &settings(0..SPP, true), &|| {});
    let merged = merge_of_parts(&[0..3, 3..10, 10..SPP], |range| {
        renderer.render(&camera, &settings(range, true), &|| {}).0
    });
    assert_within_merge_tolerance(&merged, &whole);
    // The roulette took part: it left out shadow rays.
    let every_light_sample = renderer.render(&camera, &settings(0..SPP, false), &|| {}).1;
    assert!(stats.rays < every_light_sample.rays * 3 / 4);
}

/// The room lit only through a glazed window, where guiding and next-event roulette both
/// take part.
fn window_room() -> Scene {
    load_scene(Path::new("tests/data/scenes/window_room.glb"))
        .unwrap()
        .scene
}

/// Renders each of `ranges` (seed 3) with `render`, writes them as parts and merges them
/// into samples 0..SPP.
fn merge_of_parts(ranges: &[Range<u32>], render: impl Fn(Range<u32>) -> Image) -> Image {
    let dir = tempfile::tempdir().unwrap();
    let paths: Vec<PathBuf> = ranges
        .iter()
        .map(|range| write_rendered_part(dir.path(), &render(range.clone()), range.clone(), 3))
        .collect();
    merge_files(&paths, Some(0..SPP)).unwrap().0
}

/// Asserts that a merge equals the whole render to the merge's rounding bound.
fn assert_within_merge_tolerance(merged: &Image, whole: &Image) {
    let difference = relative_difference(merged, whole);
    assert!(
        difference <= MERGE_TOLERANCE,
        "{difference:e} > {MERGE_TOLERANCE:e}"
    );
}

/// Writes the rendered samples `range` (seed `seed`) as a part in `dir` and returns its
/// path.
fn write_rendered_part(dir: &Path, part: &Image, range: Range<u32>, seed: u64) -> PathBuf {
    let path = dir.join(format!("part-{}-{}.exr", range.start, range.end));
    write_image_with_record(
        &path,
        part,
        Some(&record(range, seed)),
        ViewTransform::Standard,
    )
    .unwrap();
    path
}

/// Writes a part with `record` and returns its path.
fn part(dir: &Path, name: &str, record: RenderRecord) -> PathBuf {
    let mut image = Image::new(SIZE, SIZE);
    image.spp = record.samples.end - record.samples.start;
    image.first_sample = record.samples.start;
    let path = dir.join(name);
    write_image_with_record(&path, &image, Some(&record), ViewTransform::Standard).unwrap();
    path
}

fn merge(paths: &[&PathBuf], wanted: Option<Range<u32>>) -> Result<Image, MergeError> {
    let paths: Vec<PathBuf> = paths.iter().map(|p| p.to_path_buf()).collect();
    merge_files(&paths, wanted).map(|(image, _)| image)
}

fn assert_error(result: Result<Image, MergeError>, needles: &[&str]) {
    let message = result.expect_err("the merge must fail").to_string();
    for needle in needles {
        assert!(message.contains(needle), "'{needle}' not in: {message}");
    }
}

#[test]
fn bad_part_sets_are_refused_naming_the_parts() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let a = part(d, "a.exr", record(0..8, 1));
    let b = part(d, "b.exr", record(8..16, 1));
    let c = part(d, "c.exr", record(16..24, 1));
    let overlapping = part(d, "overlapping.exr", record(4..12, 1));
    let other_seed = part(d, "seed2.exr", record(8..16, 2));
    let mut other_scene = record(8..16, 1);
    other_scene.identity.scene_sha256 = "1".repeat(64);
    let other_scene = part(d, "other_scene.exr", other_scene);

    assert!(merge(&[&c, &a, &b], Some(0..24)).is_ok());
    assert_error(
        merge(&[&a, &c], None),
        &["a.exr", "c.exr", "samples 8..16", "--samples 8..16"],
    );
    assert_error(
        merge(&[&a, &overlapping, &b], None),
        &["a.exr", "overlapping.exr", "samples 4..8"],
    );
    assert_error(merge(&[&a, &a], None), &["a.exr", "overlap"]);
    assert_error(
        merge(&[&a, &other_seed], None),
        &["a.exr", "seed2.exr", "seed", "'1' and '2'"],
    );
    assert_error(
        merge(&[&a, &other_scene], None),
        &["other_scene.exr", "sceneSha256"],
    );
    assert_error(merge(&[&a, &b], Some(0..24)), &["0..16", "0..24"]);
    assert_error(merge(&[], None), &["no parts"]);

    // Files that are not parts.
    let plain = d.join("plain.exr");
    write_image(&plain, &Image::new(SIZE, SIZE)).unwrap();
    assert_error(
        merge(&[&plain], None),
        &["plain.exr", "gridtrace/record", "not a gridtrace render"],
    );
    let text = d.join("text.exr");
    std::fs::write(&text, "not an image").unwrap();
    assert_error(merge(&[&text], None), &["text.exr", "OpenEXR"]);
    let missing = d.join("missing.exr");
    assert_error(merge(&[&missing], None), &["missing.exr"]);
    let mut nan = Image::new(SIZE, SIZE);
    nan.pixels[5].y = f32::NAN;
    nan.spp = 8;
    let damaged = d.join("damaged.exr");
    write_image_with_record(
        &damaged,
        &nan,
        Some(&record(0..8, 1)),
        ViewTransform::Standard,
    )
    .unwrap();
    assert_error(merge(&[&damaged], None), &["damaged.exr", "pixel (5, 0)"]);
    let mut small = record(0..8, 1);
    small.identity.width = SIZE / 2;
    let wrong_size = part(d, "wrong_size.exr", small);
    assert_error(
        merge(&[&wrong_size], None),
        &["wrong_size.exr", "16x32", "32x32"],
    );
}

fn read(path: &Path) -> Image {
    read_part(path)
        .and_then(|part| part.read_image())
        .unwrap_or_else(|e| panic!("{e}"))
}

#[test]
fn the_command_line_splits_and_merges() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let scene = cornell_box().display().to_string();
    // With Cycles' Blackman–Harris filter (each sample still lands in one pixel) and depth
    // of field (a lens position per sample).
    let common = [
        "--width",
        "24",
        "-q",
        "--filter",
        "blackman-harris",
        "--fstop",
        "0.7",
    ];
    let run = |extra: &[&str]| {
        let args: Vec<&str> = [scene.as_str()]
            .into_iter()
            .chain(common)
            .chain(extra.iter().copied())
            .collect();
        let out = gridtrace(&args, d);
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
    };
    run(&["--seed", "9", "--spp", "12", "-o", "whole.exr"]);
    run(&["--seed", "9", "--samples", "0..5"]);
    run(&["--seed", "9", "--samples", "5..12", "--threads", "1"]);
    let out = gridtrace(
        &[
            "merge",
            "cornell_box.samples-5-12.exr",
            "cornell_box.samples-0-5.exr",
            "--samples",
            "0..12",
            "-o",
            "merged.exr",
        ],
        d,
    );
    let summary = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{summary}");
    assert!(
        summary.contains("merged 2 part(s)") && summary.contains("0..12"),
        "{summary}"
    );
    let (whole, merged) = (read(&d.join("whole.exr")), read(&d.join("merged.exr")));
    assert_eq!(merged.alpha, whole.alpha);
    assert!(relative_difference(&merged, &whole) <= MERGE_TOLERANCE);

    // A merged image is itself a part: later samples refine it.
    run(&["--seed", "9", "--spp", "20", "-o", "whole20.exr"]);
    run(&["--seed", "9", "--samples", "12..20", "-o", "more.exr"]);
    let out = gridtrace(&["merge", "more.exr", "merged.exr", "-o", "refined.exr"], d);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let (whole20, refined) = (read(&d.join("whole20.exr")), read(&d.join("refined.exr")));
    assert_eq!(refined.samples(), 0..20);
    assert!(relative_difference(&refined, &whole20) <= MERGE_TOLERANCE);

    // The record holds what the merge checks: another seed is refused.
    run(&["--samples", "12..16", "--seed", "10", "-o", "seed10.exr"]);
    let out = gridtrace(&["merge", "merged.exr", "seed10.exr", "-o", "bad.exr"], d);
    assert_eq!(out.status.code(), Some(2));
    let message = String::from_utf8_lossy(&out.stderr);
    assert!(
        message.contains("seed10.exr") && message.contains("seed"),
        "{message}"
    );
    assert!(!d.join("bad.exr").exists());
    // So is another pixel filter (the same lens).
    let out = gridtrace(
        &[
            &scene,
            "--width",
            "24",
            "-q",
            "--seed",
            "9",
            "--samples",
            "12..16",
            "--fstop",
            "0.7",
            "-o",
            "box.exr",
        ],
        d,
    );
    assert!(out.status.success());
    let out = gridtrace(&["merge", "merged.exr", "box.exr", "-o", "bad.exr"], d);
    let message = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{message}");
    assert!(message.contains("filter=box"), "{message}");
    assert!(!d.join("bad.exr").exists());

    // --spp and --samples are two ways of saying how many samples: not both.
    let out = gridtrace(&[&scene, "--spp", "4", "--samples", "0..4"], d);
    assert_eq!(out.status.code(), Some(2));
}

#[test]
fn parts_read_from_different_buffer_files_do_not_merge() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    common::write_gltf(d, "quad.gltf", &common::quad_document());
    // Relative to the working folder, as users type it.
    let scene = "quad.gltf";
    let render = |samples: &str, out: &str| {
        let out = gridtrace(
            &[scene, "--width", "8", "-q", "--samples", samples, "-o", out],
            d,
        );
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
    };
    render("0..2", "a.exr");
    render("2..4", "b.exr");
    // The .gltf is untouched, but its buffer is re-exported with one corner moved.
    let mut buffer = std::fs::read(d.join("quad.bin")).unwrap();
    buffer[0] ^= 1;
    std::fs::write(d.join("quad.bin"), buffer).unwrap();
    render("2..4", "b_changed.exr");

    let merge = |parts: &[&str]| {
        let args: Vec<&str> = ["merge"]
            .into_iter()
            .chain(parts.iter().copied())
            .chain(["-o", "merged.exr"])
            .collect();
        gridtrace(&args, d)
    };
    assert!(merge(&["a.exr", "b.exr"]).status.success());
    let out = merge(&["a.exr", "b_changed.exr"]);
    let message = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{message}");
    assert!(
        message.contains("b_changed.exr") && message.contains("dependenciesSha256"),
        "{message}"
    );
}
