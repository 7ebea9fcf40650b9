//! The AgX view transform against Blender's own: a linear ramp (exposures from 12 stops
//! under to 10 over middle grey, in grey and eleven colours) saved by Blender 5 through its
//! AgX view (`tools/blender/make_view_transform_ramp.py`) and formed by gridtrace from the
//! same EXR must agree within 1/255 on average (the limit, fixed before looking).

#[path = "support/binary/mod.rs"]
mod binary;

use std::path::Path;

use binary::{gridtrace, stderr};
use gridtrace::output::{ViewTransform, display_bytes, read_exr_rgba};
use gridtrace::render::Image;

fn ramp() -> Image {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/references/view_ramp.exr");
    let header = gridtrace::output::read_exr_header(&path).unwrap();
    let (pixels, alpha) = read_exr_rgba(&path).unwrap();
    let mut image = Image::new(header.width as u32, header.height as u32);
    image.pixels = pixels;
    image.alpha = alpha;
    image
}

fn blender_agx() -> Vec<u8> {
    let path =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/references/view_ramp_agx.png");
    image::open(path).unwrap().to_rgb8().into_raw()
}

#[test]
fn agx_matches_blenders_own_within_one_level_on_average() {
    let ours = display_bytes(&ramp(), ViewTransform::Agx);
    let theirs = blender_agx();
    assert_eq!(ours.len(), theirs.len());
    let differences: Vec<i32> = ours
        .iter()
        .zip(&theirs)
        .map(|(&a, &b)| (i32::from(a) - i32::from(b)).abs())
        .collect();
    let mean = differences.iter().sum::<i32>() as f64 / differences.len() as f64;
    let max = differences.iter().max().copied().unwrap_or(0);
    let grey = &differences[..ours.len() / 12];
    let grey_max = grey.iter().max().copied().unwrap_or(0);
    eprintln!("AgX vs Blender: mean |Δ| {mean:.3}/255, max {max}/255, grey row max {grey_max}/255");
    assert!(mean <= 1.0, "mean difference {mean:.3}/255 exceeds 1/255");
}

#[test]
fn standard_and_agx_differ_where_they_should() {
    let image = ramp();
    let standard = display_bytes(&image, ViewTransform::Standard);
    let agx = display_bytes(&image, ViewTransform::Agx);
    let width = image.width as usize;
    // Four stops over middle grey the sRGB curve has clipped; AgX has not.
    let column = 16 * 4;
    assert_eq!(standard[column * 3], 255);
    assert!(
        agx[column * 3] < 250,
        "AgX at +4 stops is {}",
        agx[column * 3]
    );
    // Middle grey is middle grey in both.
    let grey = 12 * 4 * 3;
    assert!((i32::from(standard[grey]) - i32::from(agx[grey])).abs() <= 1);
    assert_eq!(standard.len(), width * image.height as usize * 3);
}

/// Renders the bundled Cornell box, 16 pixels square, with `extra` options (samples 0..2
/// unless they say otherwise), into `dir`.
fn render(dir: &Path, output: &str, extra: &[&str]) {
    let scene = Path::new(env!("CARGO_MANIFEST_DIR")).join("assets/cornell_box.glb");
    let mut args = vec![scene.to_str().unwrap(), "-o", output, "--width", "16", "-q"];
    args.extend_from_slice(extra);
    if !extra.contains(&"--samples") {
        args.extend_from_slice(&["--samples", "0..2"]);
    }
    let out = gridtrace(&args, dir);
    assert!(out.status.success(), "{}", stderr(&out));
}

#[test]
fn exposure_scales_every_output_and_is_recorded() {
    let dir = tempfile::tempdir().unwrap();
    render(dir.path(), "plain.exr", &[]);
    render(dir.path(), "bright.exr", &["--exposure", "1"]);
    render(
        dir.path(),
        "dark.exr",
        &["--exposure=-2", "--samples", "2..4"],
    );
    let (plain, _) = read_exr_rgba(&dir.path().join("plain.exr")).unwrap();
    let (bright, _) = read_exr_rgba(&dir.path().join("bright.exr")).unwrap();
    assert!(plain.iter().any(|p| p.x > 0.0));
    for (p, b) in plain.iter().zip(&bright) {
        assert_eq!(*p * 2.0, *b);
    }
    let header = gridtrace::output::read_exr_header(&dir.path().join("bright.exr")).unwrap();
    let record = gridtrace::record::RenderRecord::from_text(
        &header.text[gridtrace::record::RECORD_ATTRIBUTE],
    )
    .unwrap();
    assert_eq!(record.identity.exposure, 1.0);
    // Parts at different exposures are not parts of one image.
    let out = gridtrace(
        &["merge", "plain.exr", "dark.exr", "-o", "m.exr"],
        dir.path(),
    );
    assert!(!out.status.success());
    assert!(stderr(&out).contains("exposure"), "{}", stderr(&out));
}

#[test]
fn a_png_records_its_view_transform() {
    let dir = tempfile::tempdir().unwrap();
    render(
        dir.path(),
        "agx.png",
        &["--view-transform", "agx", "--exposure", "0.5"],
    );
    render(dir.path(), "standard.png", &[]);
    let text = |name: &str| {
        let file = std::fs::File::open(dir.path().join(name)).unwrap();
        let reader = png::Decoder::new(std::io::BufReader::new(file))
            .read_info()
            .unwrap();
        reader.info().utf8_text[0].get_text().unwrap()
    };
    let agx = text("agx.png");
    assert!(
        agx.contains("viewTransform=agx\n") && agx.contains("exposure=0.5\n"),
        "{agx}"
    );
    assert!(text("standard.png").contains("viewTransform=standard\n"));
    // The light, far above 1, clips under the sRGB curve but not under AgX.
    let max = |name: &str| {
        let image = image::open(dir.path().join(name)).unwrap().to_rgb8();
        image.pixels().map(|p| p.0[1]).max().unwrap()
    };
    assert_eq!(max("standard.png"), 255);
    assert!(max("agx.png") < 255);
}
