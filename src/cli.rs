//! The command-line driver: parse arguments, load, render, write; or merge parts rendered
//! apart. Errors exit with code 2.

use std::ops::Range;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Instant;

use anyhow::{Context, Result, anyhow, bail};
use clap::{Parser, Subcommand, ValueEnum};
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};

use crate::inspect::describe;
use crate::load::{GltfLightUnits, LoadOptions, load_scene_with};
use crate::merge::merge_files;
use crate::output::{Format, check_writable, write_image_with_record};
use crate::record::{
    RenderIdentity, RenderRecord, format_range, parse_range, sha256_file, sha256_files,
};
use crate::render::{RenderSettings, Renderer, Strategy};
use crate::scene::{Camera, Scene};

/// Image height used when neither --width nor --height is given.
const DEFAULT_HEIGHT: u32 = 512;

/// Render a glTF 2.0 (.gltf, .glb), USD (.usd, .usda, .usdc, .usdz) or PLY scene with a
/// physically based path tracer.
///
/// Emissive materials are area lights; metallic materials are ideal mirrors; transmissive
/// materials are ideal glass; everything else is Lambertian. Output is linear float
/// OpenEXR (.exr) or 8-bit sRGB PNG (.png), chosen by the output file's extension.
///
/// A long render can be split: `--samples A..B` renders only those samples of every pixel,
/// and `gridtrace merge` combines the parts into the image of one render.
#[derive(Parser, Debug)]
#[command(
    name = "gridtrace",
    version,
    about,
    long_about,
    args_conflicts_with_subcommands = true,
    subcommand_negates_reqs = true
)]
pub struct Args {
    /// Something other than rendering.
    #[command(subcommand)]
    pub command: Option<Command>,

    /// Scene file to render (.gltf, .glb, .usd, .usda, .usdc, .usdz, .ply, .ply.gz).
    #[arg(required = true)]
    pub scene: Option<PathBuf>,

    /// Output image, .exr (linear float RGBA) or .png (sRGB). [default: SCENE_STEM.exr in the current folder]
    #[arg(short, long, value_name = "FILE")]
    pub output: Option<PathBuf>,

    /// Samples per pixel: more means less noise and a longer render.
    #[arg(long, default_value_t = 64, value_parser = clap::value_parser!(u32).range(1..))]
    pub spp: u32,

    /// Render only samples A to B−1 of every pixel, as one part of a render split across
    /// processes or machines; `gridtrace merge` combines the parts (write them as .exr).
    /// Any sample is the same whichever process renders it. [instead of --spp]
    #[arg(long, value_name = "A..B", value_parser = parse_range, conflicts_with = "spp")]
    pub samples: Option<Range<u32>>,

    /// Image width in pixels. [default: from --height and the camera's aspect ratio]
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=65536))]
    pub width: Option<u32>,

    /// Image height in pixels. [default: 512, or from --width and the camera's aspect ratio]
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=65536))]
    pub height: Option<u32>,

    /// Most bounces along a path; 0 shows emitters only, 1 direct light only.
    #[arg(long, default_value_t = 16)]
    pub max_depth: u32,

    /// Random seed: the same seed gives a bit-identical image, whatever the thread count.
    #[arg(long, default_value_t = 0)]
    pub seed: u64,

    /// Worker threads. [default: one per core]
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=1024))]
    pub threads: Option<u32>,

    /// Camera to render, by name or by index in file order. [default: the first camera, or
    /// one that frames the whole scene if the file has none]
    #[arg(long, value_name = "NAME|INDEX")]
    pub camera: Option<String>,

    /// No progress bar and no summary; warnings and errors are still printed.
    #[arg(short, long)]
    pub quiet: bool,

    /// Refuse scenes with more triangles than this (after instancing), before building
    /// anything; raise it to render bigger scenes.
    #[arg(long, value_name = "N", default_value_t = 200_000_000)]
    pub max_triangles: u64,

    /// Refuse images with more pixels than this; raise it to render bigger images.
    #[arg(long, value_name = "N", default_value_t = 1 << 28)]
    pub max_pixels: u64,

    /// Print what was loaded (meshes, materials and how they were mapped, textures, lights
    /// with their power, cameras, warnings) and exit without rendering.
    #[arg(long)]
    pub inspect: bool,

    /// USD time code (Blender writes frame numbers) at which to read an animated USD stage:
    /// transforms, points, cameras and lights. [default: the stage's startTimeCode]
    #[arg(long, value_name = "FRAME", allow_negative_numbers = true, value_parser = parse_frame)]
    pub frame: Option<f64>,

    /// What glTF light intensities mean: the specification's candela and lux (Blender's
    /// "Standard" export), or Blender's "Unitless" or "Raw" lighting modes.
    #[arg(long, value_enum, value_name = "UNITS", default_value = "standard")]
    pub gltf_light_units: GltfLightUnits,
}

/// Commands other than rendering.
#[derive(Subcommand, Debug)]
pub enum Command {
    /// Combine EXR parts of one render (rendered with --samples) into one image, equal to
    /// the render of all their samples by one process.
    Merge(MergeArgs),
}

/// Arguments of `gridtrace merge`.
#[derive(clap::Args, Debug)]
pub struct MergeArgs {
    /// The parts: EXR files written by `gridtrace SCENE --samples A..B`, in any order.
    #[arg(required = true, value_name = "PART")]
    pub parts: Vec<PathBuf>,

    /// The merged image, .exr (which can be merged again) or .png.
    #[arg(short, long, value_name = "FILE")]
    pub output: PathBuf,

    /// Fail unless the parts hold exactly these samples, so a missing part is an error
    /// rather than a noisier image. [default: any contiguous range]
    #[arg(long, value_name = "A..B", value_parser = parse_range)]
    pub samples: Option<Range<u32>>,

    /// No summary; errors are still printed.
    #[arg(short, long)]
    pub quiet: bool,
}

/// Set by the first Ctrl-C: finish the current pass, write the image, exit with 130.
static STOP: AtomicBool = AtomicBool::new(false);

/// How a run ended, when it did not fail.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Outcome {
    /// All samples were taken and the image written.
    Completed,
    /// Ctrl-C stopped the render early; the image written holds fewer samples.
    Interrupted,
}

/// Runs the command line and returns the process exit code: 0, 2 on errors, 130 (as for
/// SIGINT) when Ctrl-C stopped the render and the partial image was written.
pub fn main() -> i32 {
    let args = Args::parse();
    // A second Ctrl-C quits at once, without writing.
    let _ = ctrlc::set_handler(|| {
        if STOP.swap(true, Ordering::SeqCst) {
            eprintln!("\ninterrupted again: quitting without writing the image");
            std::process::exit(130);
        }
        eprintln!(
            "\ninterrupted: finishing the current pass, then writing the image (Ctrl-C again quits)"
        );
    });
    match run(&args, &STOP) {
        Ok(Outcome::Completed) => 0,
        Ok(Outcome::Interrupted) => 130,
        Err(e) => {
            eprintln!("error: {e:#}");
            2
        }
    }
}

/// Loads, renders and writes as `args` says; rendering stops early, and the image so far is
/// written, once `stop` is set.
pub fn run(args: &Args, stop: &AtomicBool) -> Result<Outcome> {
    if let Some(Command::Merge(merge)) = &args.command {
        return run_merge(merge).map(|()| Outcome::Completed);
    }
    let scene_path = args
        .scene
        .as_deref()
        .ok_or_else(|| anyhow!("no scene file given"))?;
    let options = LoadOptions {
        gltf_light_units: args.gltf_light_units,
        usd_frame: args.frame,
    };
    if args.inspect {
        let loaded = load_scene_with(scene_path, &options)?;
        print!(
            "{}:\n{}",
            scene_path.display(),
            describe(&loaded.scene, &loaded.warnings)
        );
        return Ok(Outcome::Completed);
    }
    let samples = args.samples.clone().unwrap_or(0..args.spp);
    let output = args
        .output
        .clone()
        .unwrap_or_else(|| default_output(scene_path, args.samples.as_ref()));
    check_writable(&output)?;
    if args.samples.is_some() && Format::from_path(&output)? != Format::Exr {
        eprintln!(
            "warning: {}: only .exr parts can be merged; a PNG keeps no record of its samples",
            output.display()
        );
    }
    let mut pool = rayon::ThreadPoolBuilder::new();
    if let Some(n) = args.threads {
        pool = pool.num_threads(n as usize);
    }
    let pool = pool.build().context("starting worker threads")?;

    let load_start = Instant::now();
    let scene_sha256 =
        sha256_file(scene_path).with_context(|| format!("{}", scene_path.display()))?;
    let loaded = load_scene_with(scene_path, &options)?;
    let scene_dir = match scene_path.parent() {
        Some(dir) if !dir.as_os_str().is_empty() => dir,
        _ => Path::new("."),
    };
    let dependencies_sha256 =
        sha256_files(scene_dir, &loaded.files).context("hashing the files the scene reads")?;
    for warning in &loaded.warnings {
        eprintln!("warning: {warning}");
    }
    let scene = loaded.scene;
    let triangles = scene.instanced_triangle_count() as u64;
    if triangles > args.max_triangles {
        bail!(
            "{}: {triangles} triangles after instancing, more than --max-triangles {}",
            scene_path.display(),
            args.max_triangles
        );
    }
    if scene.instanced_triangle_count() == 0 {
        eprintln!(
            "warning: {}: the scene has no triangles; the image will be empty",
            scene_path.display()
        );
    } else if !scene.has_emitters() {
        eprintln!(
            "warning: {}: the scene has no emitters (no emissive material, no light); the image will be black",
            scene_path.display()
        );
    }

    let camera = choose_camera(&scene, args.camera.as_deref(), args.width, args.height)?;
    let (width, height) = image_size(args.width, args.height, camera.aspect_ratio());
    if width as u64 * height as u64 > args.max_pixels {
        bail!(
            "{width}x{height} is {} pixels, more than --max-pixels {}",
            width as u64 * height as u64,
            args.max_pixels
        );
    }
    if let (Some(w), Some(h), Some(aspect)) = (args.width, args.height, camera.aspect_ratio())
        && ((w as f32 / h as f32) / aspect - 1.0).abs() > 0.01
    {
        eprintln!(
            "note: {w}x{h} does not match the camera's aspect ratio {aspect:.3}; keeping its vertical field of view"
        );
    }
    let settings = RenderSettings {
        width,
        height,
        spp: samples.end - samples.start,
        first_sample: samples.start,
        max_depth: args.max_depth,
        seed: args.seed,
        strategy: Strategy::Mis,
    };

    let renderer = pool.install(|| Renderer::new(&scene));
    if !args.quiet {
        eprintln!(
            "{}: {} triangles in {} instances, {} emissive, {} punctual light(s); camera {}; \
             prepared in {:.2} s",
            scene_path.display(),
            scene.instanced_triangle_count(),
            scene.instances.len(),
            renderer.lights().len(),
            renderer.lights().punctual_len(),
            if camera.name.is_empty() {
                &camera.source
            } else {
                &camera.name
            },
            load_start.elapsed().as_secs_f64()
        );
    }
    let bar = progress_bar(height as u64 * settings.spp as u64, args.quiet);
    let (image, stats) =
        pool.install(|| renderer.render_until(&camera, &settings, &|| bar.inc(1), stop));
    bar.finish_and_clear();
    let interrupted = stats.spp < settings.spp;
    if interrupted {
        eprintln!(
            "stopped after {} of {} samples per pixel (samples {}); writing the image so far",
            stats.spp,
            settings.spp,
            format_range(&image.samples())
        );
    }
    if stats.nonfinite > 0 {
        eprintln!(
            "warning: {} sample(s) were NaN or infinite and were dropped",
            stats.nonfinite
        );
    }
    let record = RenderRecord {
        identity: RenderIdentity {
            version: env!("CARGO_PKG_VERSION").to_string(),
            scene_sha256,
            dependencies_sha256,
            camera: camera_label(&camera),
            width,
            height,
            seed: settings.seed,
            max_depth: settings.max_depth,
            load_options: load_options_label(&options),
        },
        scene_name: scene_path
            .file_name()
            .map_or_else(String::new, |n| n.to_string_lossy().into_owned()),
        samples: image.samples(),
        nonfinite: stats.nonfinite,
    };
    write_image_with_record(&output, &image, Some(&record))?;
    if !args.quiet {
        let seconds = stats.elapsed.as_secs_f64().max(1e-9);
        let range = match args.samples {
            Some(_) => format!(" (samples {})", format_range(&image.samples())),
            None => String::new(),
        };
        eprintln!(
            "rendered {width}x{height} at {} spp{range} in {seconds:.2} s: {:.2} M samples/s, {:.2} M rays/s; wrote {}",
            stats.spp,
            stats.samples as f64 / seconds / 1e6,
            stats.rays as f64 / seconds / 1e6,
            output.display()
        );
    }
    Ok(if interrupted {
        Outcome::Interrupted
    } else {
        Outcome::Completed
    })
}

/// Reads, checks and merges the parts, and writes the merged image.
fn run_merge(args: &MergeArgs) -> Result<()> {
    check_writable(&args.output)?;
    let start = Instant::now();
    let (image, record) = merge_files(&args.parts, args.samples.clone())?;
    if record.nonfinite > 0 {
        eprintln!(
            "warning: {} sample(s) were NaN or infinite and were dropped",
            record.nonfinite
        );
    }
    write_image_with_record(&args.output, &image, Some(&record))?;
    if !args.quiet {
        eprintln!(
            "merged {} part(s) of {} ({}x{}, camera {}): samples {} in {:.2} s; wrote {}",
            args.parts.len(),
            record.scene_name,
            image.width,
            image.height,
            record.identity.camera,
            format_range(&record.samples),
            start.elapsed().as_secs_f64(),
            args.output.display()
        );
    }
    Ok(())
}

/// How the record names a camera: its name and where it came from.
fn camera_label(camera: &Camera) -> String {
    format!("'{}' ({})", camera.name, camera.source)
}

/// The loader options that change the scene, as the record stores them.
fn load_options_label(options: &LoadOptions) -> String {
    let units = options
        .gltf_light_units
        .to_possible_value()
        .map_or_else(String::new, |v| v.get_name().to_string());
    match options.usd_frame {
        Some(frame) => format!("gltf-light-units={units} usd-frame={frame}"),
        None => format!("gltf-light-units={units}"),
    }
}

/// A finite frame number (USD time code).
fn parse_frame(text: &str) -> Result<f64, String> {
    text.parse::<f64>()
        .ok()
        .filter(|f| f.is_finite())
        .ok_or_else(|| format!("'{text}' is not a frame number"))
}

/// `SCENE_STEM.exr` in the current folder; `SCENE_STEM.samples-A-B.exr` for a part.
fn default_output(scene: &Path, samples: Option<&Range<u32>>) -> PathBuf {
    let stem = scene
        .file_stem()
        .map_or_else(|| "render".into(), |s| s.to_string_lossy().into_owned());
    match samples {
        Some(r) => PathBuf::from(format!("{stem}.samples-{}-{}.exr", r.start, r.end)),
        None => PathBuf::from(format!("{stem}.exr")),
    }
}

/// The camera asked for, the first one, or one that frames the scene.
pub fn choose_camera(
    scene: &Scene,
    wanted: Option<&str>,
    width: Option<u32>,
    height: Option<u32>,
) -> Result<Camera> {
    let list = || {
        if scene.cameras.is_empty() {
            "the scene has no cameras".to_string()
        } else {
            let names: Vec<String> = scene
                .cameras
                .iter()
                .enumerate()
                .map(|(i, c)| format!("{i} '{}' ({})", c.name, c.source))
                .collect();
            format!("cameras: {}", names.join(", "))
        }
    };
    match wanted {
        Some(spec) => {
            if let Ok(index) = spec.parse::<usize>() {
                return scene
                    .cameras
                    .get(index)
                    .cloned()
                    .ok_or_else(|| anyhow!("no camera {index}; {}", list()));
            }
            let found = scene
                .cameras
                .iter()
                .find(|c| c.name == spec || c.source.ends_with(&format!("'{spec}'")));
            found
                .cloned()
                .ok_or_else(|| anyhow!("no camera named '{spec}'; {}", list()))
        }
        None => Ok(match scene.cameras.first() {
            Some(c) => c.clone(),
            None => {
                let aspect = match (width, height) {
                    (Some(w), Some(h)) => w as f32 / h as f32,
                    _ => 1.0,
                };
                Camera::framing(&scene.bounds(), aspect)
            }
        }),
    }
}

/// Image size from the options, filling a missing side from the camera's aspect ratio.
pub fn image_size(width: Option<u32>, height: Option<u32>, aspect: Option<f32>) -> (u32, u32) {
    let aspect = aspect.filter(|a| a.is_finite() && *a > 0.0).unwrap_or(1.0);
    let from_aspect = |x: f32| (x.round() as u32).clamp(1, 65536);
    match (width, height) {
        (Some(w), Some(h)) => (w, h),
        (Some(w), None) => (w, from_aspect(w as f32 / aspect)),
        (None, Some(h)) => (from_aspect(h as f32 * aspect), h),
        (None, None) => (from_aspect(DEFAULT_HEIGHT as f32 * aspect), DEFAULT_HEIGHT),
    }
}

/// A bar over `steps` (rows × passes).
fn progress_bar(steps: u64, quiet: bool) -> ProgressBar {
    if quiet {
        return ProgressBar::hidden();
    }
    let bar = ProgressBar::with_draw_target(Some(steps), ProgressDrawTarget::stderr());
    bar.set_style(
        ProgressStyle::with_template(
            "{spinner} [{elapsed_precise}] [{bar:40}] {percent:>3}%, ETA {eta}",
        )
        .expect("static template")
        .progress_chars("=> "),
    );
    bar
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_frame_is_part_of_the_render_identity() {
        let mut options = LoadOptions::default();
        let still = load_options_label(&options);
        options.usd_frame = Some(12.0);
        let frame12 = load_options_label(&options);
        options.usd_frame = Some(12.5);
        assert_ne!(still, frame12);
        assert_ne!(frame12, load_options_label(&options));
        assert!(parse_frame("-3.5").is_ok() && parse_frame("inf").is_err());
    }

    #[test]
    fn image_size_follows_the_camera_aspect() {
        assert_eq!(image_size(None, None, Some(1.5)), (768, 512));
        assert_eq!(image_size(Some(300), None, Some(1.5)), (300, 200));
        assert_eq!(image_size(None, Some(100), None), (100, 100));
        assert_eq!(image_size(Some(7), Some(9), Some(2.0)), (7, 9));
    }
}
