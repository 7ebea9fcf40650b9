//! What a render will do, decided from the options before the scene is read: its budget,
//! the loader's options, the samples, the layers and the output (checked writable first,
//! so a failed run never wastes a render).

use std::ops::Range;
use std::path::{Path, PathBuf};
use std::time::Duration;

use anyhow::{Result, anyhow, bail};

use super::super::args::Args;
use super::super::choices::SoftFalloffChoice;
use super::super::signals::{arm_load_timeout, check_output};
use crate::limits::set_memory_budget;
use crate::load::LoadOptions;
use crate::load::access::check_named_file;
use crate::output::Format;
use crate::output::denoise::check_available;
use crate::render::{AovSet, DEFAULT_SPP};

/// Samples per pixel of a render with a time limit and no `--spp`: as many as the time
/// allows.
const UNBOUNDED_SPP: u32 = 1 << 20;

/// The scene to read and how.
pub struct Request<'a> {
    /// The scene file.
    pub scene_path: &'a Path,
    /// How to read it.
    pub load_options: LoadOptions,
}

/// A render's plan: the request, and what it will produce.
pub struct Plan<'a> {
    /// The scene to read and how.
    pub request: Request<'a>,
    /// The samples every pixel takes.
    pub samples: Range<u32>,
    /// The layers kept beside the beauty (with `--denoise`, its guides too).
    pub aovs: AovSet,
    /// The output file.
    pub output: PathBuf,
}

/// Sets the memory budget and the load timeout, checks that a denoiser is there if asked
/// for, and says which scene to read and how.
pub fn read_request(args: &Args) -> Result<Request<'_>> {
    set_memory_budget(args.limits.max_memory.unwrap_or(0));
    if args.image.denoise {
        check_available()?;
    }
    let scene_path = args
        .scene
        .as_deref()
        .ok_or_else(|| anyhow!("no scene file given"))?;
    check_named_file(scene_path)?;
    let loading = &args.loading;
    let load_options = LoadOptions {
        gltf_light_units: loading.gltf_light_units.into(),
        frame: loading.frame,
        fps: loading.fps,
        animation: loading.animation.clone(),
        material_variant: loading.material_variant.clone(),
        asset_paths: loading.asset_path.clone(),
        subdivision_level: loading.subdivision_level,
        hard_falloff: loading.soft_falloff == SoftFalloffChoice::Off,
        ..LoadOptions::default()
    };
    for dir in &loading.asset_path {
        if !dir.is_dir() {
            bail!("{}: --asset-path is not a folder", dir.display());
        }
    }
    arm_load_timeout(
        Duration::from_secs_f64(args.limits.load_timeout),
        scene_path,
    );
    Ok(Request {
        scene_path,
        load_options,
    })
}

/// Decides the samples, layers and output, and checks that the output can be written.
pub fn plan_outputs<'a>(args: &Args, request: Request<'a>) -> Result<Plan<'a>> {
    let sampling = &args.sampling;
    let default_spp = if sampling.time_limit.is_some() {
        UNBOUNDED_SPP
    } else {
        DEFAULT_SPP
    };
    let samples = sampling
        .samples
        .clone()
        .unwrap_or(0..sampling.spp.unwrap_or(default_spp));
    let guides = AovSet {
        albedo: true,
        normal: true,
        ..AovSet::default()
    };
    let image = &args.image;
    let aovs = image.aov.unwrap_or_default().union(if image.denoise {
        guides
    } else {
        AovSet::default()
    });
    let output = image
        .output
        .clone()
        .unwrap_or_else(|| default_output(request.scene_path, sampling.samples.as_ref()));
    check_output(&output)?;
    let is_exr = Format::from_path(&output)? == Format::Exr;
    if sampling.samples.is_some() && !is_exr {
        crate::terminal::say(format_args!(
            "warning: {}: only .exr parts can be merged; a PNG keeps no record of its samples",
            output.display()
        ));
    }
    if image.aov.is_some() && !is_exr {
        crate::terminal::say(format_args!(
            "warning: {}: a PNG holds the beauty only; --aov layers are written into .exr files",
            output.display()
        ));
    }
    Ok(Plan {
        request,
        samples,
        aovs,
        output,
    })
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
