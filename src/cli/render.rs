//! Rendering a scene: load, check, render in passes (checkpoints, live view, time limit),
//! denoise if asked, write with the render record.

use std::ops::Range;
use std::path::{Path, PathBuf};
use std::sync::atomic::AtomicBool;
use std::time::{Duration, Instant};

use anyhow::{Context, Result, anyhow, bail};
use clap::ValueEnum;
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};

use super::Outcome;
use super::args::Args;
use super::camera::{camera_label, choose_camera, image_size, with_depth_of_field};
use super::denoise::denoise_for_output;
use super::environment::apply_environment;
use super::motion;
use super::signals::{self, Phase, output_lock, set_phase};
use crate::denoise::check_available;
use crate::display::LiveView;
use crate::inspect::describe;
use crate::limits::{check_memory, set_memory_budget};
use crate::load::access::folder_of;
use crate::load::{LoadOptions, load_scene_with};
use crate::output::{Format, check_writable, write_image_with_record};
use crate::record::{RenderIdentity, RenderRecord, format_range, sha256_file, sha256_files};
use crate::render::{
    AovSet, EarlyEnd, Film, FilterKind, Image, RenderSettings, RenderStats, Renderer, Strategy,
};

/// Loads, renders and writes as `args` says; rendering stops early, and the image so far is
/// written, once `stop` is set.
pub fn run_render(args: &Args, stop: &AtomicBool) -> Result<Outcome> {
    set_memory_budget(args.max_memory.unwrap_or(0));
    if args.denoise {
        check_available()?;
    }
    let scene_path = args
        .scene
        .as_deref()
        .ok_or_else(|| anyhow!("no scene file given"))?;
    let options = LoadOptions {
        gltf_light_units: args.gltf_light_units,
        frame: args.frame,
        fps: args.fps,
        animation: args.animation.clone(),
        asset_paths: args.asset_path.clone(),
        subdivision_level: args.subdivision_level,
    };
    for dir in &args.asset_path {
        if !dir.is_dir() {
            bail!("{}: --asset-path is not a folder", dir.display());
        }
    }
    signals::arm_load_timeout(Duration::from_secs_f64(args.load_timeout), scene_path);
    if args.inspect {
        let mut loaded = load_scene_with(scene_path, &options)?;
        apply_environment(&mut loaded.scene, args, scene_path)?;
        set_phase(Phase::Finished);
        print!(
            "{}:\n{}",
            scene_path.display(),
            describe(&loaded.scene, &loaded.warnings)
        );
        return Ok(Outcome::Completed);
    }
    // With a time limit and no --spp, as many samples as the time allows.
    let default_spp = if args.time_limit.is_some() {
        1 << 20
    } else {
        64
    };
    let samples = args
        .samples
        .clone()
        .unwrap_or(0..args.spp.unwrap_or(default_spp));
    let aovs = args.aov.unwrap_or_default().union(if args.denoise {
        AovSet {
            albedo: true,
            normal: true,
            ..AovSet::default()
        }
    } else {
        AovSet::default()
    });
    let output = args
        .output
        .clone()
        .unwrap_or_else(|| default_output(scene_path, args.samples.as_ref()));
    {
        let _writing = output_lock();
        check_writable(&output)?;
    }
    if args.samples.is_some() && Format::from_path(&output)? != Format::Exr {
        eprintln!(
            "warning: {}: only .exr parts can be merged; a PNG keeps no record of its samples",
            output.display()
        );
    }
    if args.aov.is_some() && Format::from_path(&output)? != Format::Exr {
        eprintln!(
            "warning: {}: a PNG holds the beauty only; --aov layers are written into .exr files",
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
    let (loaded, shutter_label) = motion::apply_shutter(loaded, args, scene_path, &options)?;
    let scene_dir = folder_of(scene_path);
    let dependencies_sha256 =
        sha256_files(scene_dir, &loaded.files).context("hashing the files the scene reads")?;
    for warning in &loaded.warnings {
        eprintln!("warning: {warning}");
    }
    let mut scene = loaded.scene;
    let (environment_note, environment_label) = apply_environment(&mut scene, args, scene_path)?;
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
    } else if let Some(note) = environment_note {
        eprintln!("{note}");
    } else if !scene.has_emitters() {
        eprintln!(
            "warning: {}: the scene has no emitters (no emissive material, no light, no environment); the image will be black",
            scene_path.display()
        );
    }

    let camera = choose_camera(&scene, args.camera.as_deref(), args.width, args.height)?;
    let camera = with_depth_of_field(camera, args.fstop, args.focus_distance, &scene);
    camera.validate().map_err(|why| {
        anyhow!(
            "{}: camera {}: {why}",
            scene_path.display(),
            camera_label(&camera)
        )
    })?;
    let (width, height) = image_size(args.width, args.height, camera.aspect_ratio());
    if width as u64 * height as u64 > args.max_pixels {
        bail!(
            "{width}x{height} is {} pixels, more than --max-pixels {}",
            width as u64 * height as u64,
            args.max_pixels
        );
    }
    check_memory(
        || format!("a {width}x{height} film"),
        Film::bytes(width, height, aovs, args.noise_threshold.is_some()),
    )?;
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
        samples: samples.clone(),
        max_depth: args.max_depth,
        seed: args.seed,
        strategy: Strategy::Mis,
        filter: args.filter,
        filter_width: args.filter_width.unwrap_or(match args.filter {
            FilterKind::Box => 1.0,
            _ => 1.5,
        }),
        aovs,
        noise_threshold: args.noise_threshold,
        time_limit: args.time_limit.map(Duration::from_secs_f64),
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
    let identity = RenderIdentity {
        version: env!("CARGO_PKG_VERSION").to_string(),
        scene_sha256,
        dependencies_sha256,
        camera: camera_label(&camera),
        width,
        height,
        seed: settings.seed,
        max_depth: settings.max_depth,
        load_options: format!(
            "{}{shutter_label} {environment_label} filter={}:{}",
            load_options_label(&options),
            args.filter
                .to_possible_value()
                .map_or_else(String::new, |v| v.get_name().to_string()),
            settings.filter_width
        ),
        exposure: args.exposure,
        aovs: aovs.label(),
    };
    let scene_name = scene_path
        .file_name()
        .map_or_else(String::new, |n| n.to_string_lossy().into_owned());
    // Exposure scales what is written, never what is accumulated.
    let exposed = |image: Image| image.scaled(args.exposure.exp2());
    let record_of = |image: &Image, stats: &RenderStats| RenderRecord {
        identity: identity.clone(),
        scene_name: scene_name.clone(),
        samples: image.samples(),
        nonfinite: stats.nonfinite,
        noise_threshold: settings.noise_threshold,
        denoised: image.aovs.noisy.is_some(),
    };
    let bar = progress_bar(
        height as u64 * settings.spp() as u64,
        args.quiet || args.time_limit.is_some(),
    );
    let mut display = args.display.as_deref().map(|address| {
        LiveView::connect(address, &scene_name, width, height).unwrap_or_else(|e| {
            eprintln!("warning: --display {address}: {e}; rendering without a live view");
            LiveView::disconnected()
        })
    });
    // Checkpoints: the image so far, written as the output itself, every so often.
    let every = args.checkpoint.map(Duration::from_secs_f64);
    let mut last_checkpoint = Instant::now();
    let mut checkpoint_error = None;
    let mut on_pass = |image_so_far: &dyn Fn() -> (Image, RenderStats)| {
        if let Some(view) = &mut display
            && view.wants_update()
        {
            view.show(&exposed(image_so_far().0));
        }
        let Some(every) = every else { return };
        if last_checkpoint.elapsed() < every || checkpoint_error.is_some() {
            return;
        }
        let (image, stats) = image_so_far();
        let image = exposed(image);
        let _writing = output_lock();
        if let Err(e) = write_image_with_record(
            &output,
            &image,
            Some(&record_of(&image, &stats)),
            args.view_transform,
        ) {
            checkpoint_error = Some(e);
        }
        last_checkpoint = Instant::now();
    };
    set_phase(Phase::Rendering);
    let (image, stats) = pool.install(|| {
        renderer.render_with_checkpoints(&camera, &settings, &|| bar.inc(1), stop, &mut on_pass)
    });
    bar.finish_and_clear();
    if let Some(e) = checkpoint_error {
        eprintln!("warning: a checkpoint could not be written: {e}");
    }
    let interrupted = stats.ended_early == Some(EarlyEnd::Stopped);
    let why = match stats.ended_early {
        Some(EarlyEnd::TimeLimit) => Some("the time limit came"),
        Some(EarlyEnd::Converged) => Some("every pixel reached the noise threshold"),
        _ => None,
    };
    if let Some(why) = why {
        eprintln!(
            "{why} after {} of at most {} passes ({:.2} samples per pixel on average)",
            stats.spp,
            settings.spp(),
            stats.samples as f64 / (width as f64 * height as f64)
        );
    } else if settings.noise_threshold.is_some() && !args.quiet {
        eprintln!(
            "adaptive sampling took {:.2} samples per pixel on average ({} at most)",
            stats.samples as f64 / (width as f64 * height as f64),
            stats.spp
        );
    }
    if interrupted {
        eprintln!(
            "stopped after {} of {} samples per pixel (samples {}); writing the image so far",
            stats.spp,
            settings.spp(),
            format_range(&image.samples())
        );
    }
    if stats.nonfinite > 0 {
        eprintln!(
            "warning: {} sample(s) were NaN or infinite and were dropped",
            stats.nonfinite
        );
    }
    let mut image = exposed(image);
    if let Some(view) = &mut display {
        view.show(&image);
    }
    if args.denoise {
        denoise_for_output(&mut image, args.threads, args.quiet)?;
        if let Some(view) = &mut display {
            view.show(&image);
        }
    }
    {
        let _writing = output_lock();
        write_image_with_record(
            &output,
            &image,
            Some(&record_of(&image, &stats)),
            args.view_transform,
        )?;
        set_phase(Phase::Finished);
    }
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

/// The loader options that change the scene, as the record stores them.
fn load_options_label(options: &LoadOptions) -> String {
    let units = options
        .gltf_light_units
        .to_possible_value()
        .map_or_else(String::new, |v| v.get_name().to_string());
    let mut label = format!("gltf-light-units={units}");
    if let Some(frame) = options.frame {
        label += &format!(" frame={frame} fps={}", options.frames_per_second());
    }
    if let Some(animation) = &options.animation {
        label += &format!(" animation={animation}");
    }
    if let Some(levels) = options.subdivision_level {
        label += &format!(" subdivision-level={levels}");
    }
    label
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
    use super::super::args::parse_frame;
    use super::*;

    #[test]
    fn the_frame_is_part_of_the_render_identity() {
        let mut options = LoadOptions::default();
        let still = load_options_label(&options);
        options.frame = Some(12.0);
        let frame12 = load_options_label(&options);
        options.frame = Some(12.5);
        assert_ne!(still, frame12);
        assert_ne!(frame12, load_options_label(&options));
        let frame12_5 = load_options_label(&options);
        options.fps = Some(30.0);
        assert_ne!(frame12_5, load_options_label(&options));
        let fps30 = load_options_label(&options);
        options.animation = Some("Walk".into());
        assert_ne!(fps30, load_options_label(&options));
        assert!(parse_frame("-3.5").is_ok() && parse_frame("inf").is_err());
    }
}
