//! Motion blur against its closed form. An emissive square of side w, seen by an
//! orthographic camera (emitters only, `--max-depth 0`), moves a distance d along x while
//! the shutter is open: its image is the square convolved with a box of length d, so the
//! streak is w + d long, its middle holds radiance × w/d, it ramps linearly at both ends,
//! and the light it carries is the still square's. The same streak comes from the square
//! moved by its transform, by its points (a deforming mesh, in time slices), or seen by a
//! camera moving the other way. Limits were fixed before looking: 6 standard errors on
//! every column mean, 1 % on energy.

#[path = "support/binary/mod.rs"]
mod binary;

use std::path::Path;

use binary::{gridtrace, stderr};
use gridtrace::output::read_exr_rgba;

/// Image size: 4 × 1 scene units at 100 pixels per unit.
const WIDTH: usize = 400;
const HEIGHT: usize = 100;
/// Side of the square and the distance it travels while the shutter is open (frames
/// 2.5 to 7.5 of a 0.2-unit-per-frame slide).
const SIDE: f64 = 0.5;
const TRAVEL: f64 = 1.0;
/// The emitter's radiance.
const RADIANCE: f64 = 2.0;

/// A stage with an orthographic camera whose shutter is open 2.5 frames either side of
/// the frame, and the emissive square; `square_motion` and `camera_motion` are the USD
/// text that animates them.
fn stage(square_motion: &str, camera_motion: &str) -> String {
    format!(
        r#"#usda 1.0
(
    metersPerUnit = 1
    upAxis = "Y"
    startTimeCode = 0
    endTimeCode = 10
)

def Camera "Camera"
{{
    token projection = "orthographic"
    float horizontalAperture = 40
    float verticalAperture = 10
    float2 clippingRange = (0.1, 100)
    double shutter:open = -2.5
    double shutter:close = 2.5
    {camera_motion}
}}

def Mesh "Square" (
    prepend apiSchemas = ["MaterialBindingAPI"]
)
{{
    int[] faceVertexCounts = [4]
    int[] faceVertexIndices = [0, 1, 2, 3]
    {square_motion}
    rel material:binding = </Emit>
}}

def Material "Emit"
{{
    token outputs:surface.connect = </Emit/Surface.outputs:surface>
    def Shader "Surface"
    {{
        uniform token info:id = "UsdPreviewSurface"
        color3f inputs:diffuseColor = (0, 0, 0)
        color3f inputs:emissiveColor = ({RADIANCE}, {RADIANCE}, {RADIANCE})
        token outputs:surface
    }}
}}
"#
    )
}

/// The square's corners around x = `x`, as USD points.
fn square_at(x: f64) -> String {
    let h = SIDE / 2.0;
    format!(
        "[({}, {}, 0), ({}, {}, 0), ({}, {}, 0), ({}, {}, 0)]",
        x - h,
        -h,
        x + h,
        -h,
        x + h,
        h,
        x - h,
        h
    )
}

/// The square still at the origin, moved by its transform from x = −1 at frame 0 to +1
/// at frame 10.
fn moved_by_transform() -> String {
    stage(
        &format!(
            "point3f[] points = {}\n    double3 xformOp:translate.timeSamples = {{ 0: (-1, 0, 0), 10: (1, 0, 0) }}\n    uniform token[] xformOpOrder = [\"xformOp:translate\"]",
            square_at(0.0)
        ),
        "double3 xformOp:translate = (0, 0, 5)\n    uniform token[] xformOpOrder = [\"xformOp:translate\"]",
    )
}

/// The same slide written as points (a deforming mesh).
fn moved_by_points() -> String {
    stage(
        &format!(
            "point3f[] points.timeSamples = {{ 0: {}, 10: {} }}",
            square_at(-1.0),
            square_at(1.0)
        ),
        "double3 xformOp:translate = (0, 0, 5)\n    uniform token[] xformOpOrder = [\"xformOp:translate\"]",
    )
}

/// The square still, the camera sliding the other way.
fn camera_moving() -> String {
    stage(
        &format!("point3f[] points = {}", square_at(0.0)),
        "double3 xformOp:translate.timeSamples = { 0: (1, 0, 5), 10: (-1, 0, 5) }\n    uniform token[] xformOpOrder = [\"xformOp:translate\"]",
    )
}

/// Renders `usda` at frame 5 with `extra` options and returns the red channel, row-major.
fn render(dir: &Path, name: &str, usda: &str, extra: &[&str]) -> Vec<f64> {
    let scene = dir.join(format!("{name}.usda"));
    std::fs::write(&scene, usda).unwrap();
    let output = format!("{name}.exr");
    let mut args = vec![
        scene.to_str().unwrap(),
        "-o",
        &output,
        "--frame",
        "5",
        "--width",
        "400",
        "--height",
        "100",
        "--max-depth",
        "0",
        "-q",
    ];
    args.extend_from_slice(extra);
    let out = gridtrace(&args, dir);
    assert!(out.status.success(), "{}", stderr(&out));
    let (pixels, _) = read_exr_rgba(&dir.join(&output)).unwrap();
    assert_eq!(pixels.len(), WIDTH * HEIGHT);
    pixels.iter().map(|p| f64::from(p.x)).collect()
}

/// Column means over the rows the square covers, with their standard errors.
fn column_means(image: &[f64]) -> Vec<(f64, f64)> {
    let rows = (HEIGHT / 2 - 20)..(HEIGHT / 2 + 20);
    (0..WIDTH)
        .map(|x| {
            let values: Vec<f64> = rows.clone().map(|y| image[y * WIDTH + x]).collect();
            let n = values.len() as f64;
            let mean = values.iter().sum::<f64>() / n;
            let variance = values.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (n - 1.0);
            (mean, (variance / n).sqrt())
        })
        .collect()
}

/// The expected column mean at pixel column `x`: the time-averaged coverage of the pixel's
/// centre line by the sliding square (a trapezoid), times the radiance, averaged over the
/// pixel's width.
fn expected(x: usize) -> f64 {
    let steps = 64;
    (0..steps)
        .map(|i| {
            let sx = (x as f64 + (i as f64 + 0.5) / steps as f64) / 100.0 - 2.0;
            // The square's centre runs over [−d/2, d/2]; the point is covered while the
            // centre is within w/2 of it.
            let lo = (sx - SIDE / 2.0).max(-TRAVEL / 2.0);
            let hi = (sx + SIDE / 2.0).min(TRAVEL / 2.0);
            (hi - lo).max(0.0) / TRAVEL
        })
        .sum::<f64>()
        / steps as f64
        * RADIANCE
}

fn check_streak(what: &str, image: &[f64], still_energy: f64) {
    let columns = column_means(image);
    let mut worst = 0.0f64;
    for (x, &(mean, error)) in columns.iter().enumerate() {
        let want = expected(x);
        // A column the streak never reaches must be exactly black.
        if want == 0.0 {
            assert_eq!(mean, 0.0, "{what}: column {x} outside the streak is lit");
            continue;
        }
        let z = (mean - want) / error.max(1e-3 * want);
        worst = worst.max(z.abs());
        assert!(
            z.abs() < 6.0,
            "{what}: column {x}: {mean:.4} ± {error:.4}, expected {want:.4}"
        );
    }
    let lit: Vec<usize> = (0..WIDTH).filter(|&x| columns[x].0 > 0.0).collect();
    let length = (lit[lit.len() - 1] - lit[0] + 1) as f64 / 100.0;
    let energy: f64 = image.iter().sum();
    eprintln!(
        "{what}: streak {length:.2} units (expected {:.2}), energy {:.4} of the still square's, worst column z {worst:.2}",
        SIDE + TRAVEL,
        energy / still_energy
    );
    assert!(
        (length - (SIDE + TRAVEL)).abs() <= 0.02,
        "{what}: streak {length}"
    );
    assert!(
        (energy / still_energy - 1.0).abs() < 0.01,
        "{what}: energy {energy} against {still_energy}"
    );
}

/// The light in the image of `usda` with the shutter closed, checked against the square's
/// radiance × area.
fn still_energy(dir: &Path, usda: &str) -> f64 {
    let still = render(dir, "still", usda, &["--shutter", "0..0", "--spp", "16"]);
    let energy: f64 = still.iter().sum();
    let side_pixels = (SIDE * 100.0).powi(2);
    assert!(
        (energy / (side_pixels * RADIANCE) - 1.0).abs() < 0.01,
        "the still square holds its radiance × area"
    );
    energy
}

#[test]
fn a_moving_emitter_leaves_a_streak_of_the_expected_length_and_energy() {
    let dir = tempfile::tempdir().unwrap();
    let spp = ["--spp", "64"];
    let still_energy = still_energy(dir.path(), &moved_by_transform());
    let moving = render(dir.path(), "moving", &moved_by_transform(), &spp);
    check_streak("transform", &moving, still_energy);
    let camera = render(dir.path(), "camera", &camera_moving(), &spp);
    check_streak("moving camera", &camera, still_energy);
}

#[test]
fn a_deforming_emitter_is_drawn_at_every_step() {
    let dir = tempfile::tempdir().unwrap();
    let still_energy = still_energy(dir.path(), &moved_by_points());
    // With 2 steps only the ends are drawn: two squares, each half the time, and nothing
    // between them.
    let two = column_means(&render(
        dir.path(),
        "two",
        &moved_by_points(),
        &["--spp", "32", "--motion-steps", "2"],
    ));
    assert_eq!(
        two[200].0, 0.0,
        "nothing at the middle between the two copies"
    );
    assert!(
        (two[150].0 / (0.5 * RADIANCE) - 1.0).abs() < 0.1,
        "{}",
        two[150].0
    );
    // With many steps the copies merge into the streak of the transform.
    let many = render(
        dir.path(),
        "many",
        &moved_by_points(),
        &["--spp", "64", "--motion-steps", "51"],
    );
    let energy: f64 = many.iter().sum();
    assert!(
        (energy / still_energy - 1.0).abs() < 0.01,
        "energy {energy} against {still_energy}"
    );
    let columns = column_means(&many);
    let lit: Vec<usize> = (0..WIDTH).filter(|&x| columns[x].0 > 0.0).collect();
    assert_eq!(
        (lit[0], lit[lit.len() - 1]),
        (125, 274),
        "the streak spans −0.75 … 0.75"
    );
    // Each copy is seen for 1/50 of the shutter: the plateau is within a copy's step of the
    // continuous one.
    for (x, &(mean, _)) in columns.iter().enumerate().take(220).skip(180) {
        assert!((mean / expected(x) - 1.0).abs() < 0.1, "column {x}: {mean}");
    }
}

#[test]
fn blurred_renders_merge_exactly_and_ignore_the_thread_count() {
    let dir = tempfile::tempdir().unwrap();
    let scene = moved_by_transform();
    let whole = render(
        dir.path(),
        "whole",
        &scene,
        &["--samples", "0..6", "--threads", "1"],
    );
    render(
        dir.path(),
        "a",
        &scene,
        &["--samples", "0..2", "--threads", "2"],
    );
    render(
        dir.path(),
        "b",
        &scene,
        &["--samples", "2..6", "--threads", "2"],
    );
    let out = gridtrace(&["merge", "a.exr", "b.exr", "-o", "merged.exr"], dir.path());
    assert!(out.status.success(), "{}", stderr(&out));
    let (merged, _) = read_exr_rgba(&dir.path().join("merged.exr")).unwrap();
    let merged: Vec<f64> = merged.iter().map(|p| f64::from(p.x)).collect();
    assert_eq!(merged, whole);
    // A part rendered with another shutter is not part of the same image.
    render(
        dir.path(),
        "c",
        &scene,
        &["--samples", "2..6", "--shutter=-1..1"],
    );
    let out = gridtrace(&["merge", "a.exr", "c.exr", "-o", "bad.exr"], dir.path());
    assert!(!out.status.success());
    assert!(stderr(&out).contains("shutter"), "{}", stderr(&out));
}
