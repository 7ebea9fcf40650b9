//! `--denoise` and `gridtrace denoise`: Open Image Denoise on a finished image.

use std::time::Instant;

use anyhow::{Context, Result};

use super::args::DenoiseArgs;
use super::signals::{check_output, write_last};
use crate::limits::{check_memory, set_memory_budget};
use crate::load::access::check_named_file;
use crate::output::denoise::denoise;
use crate::output::merge::read_part;
use crate::render::Image;

/// Denoises `image` for writing, saying what guides it unless `quiet`.
pub fn denoise_for_output(image: &mut Image, threads: Option<u32>, quiet: bool) -> Result<()> {
    let start = Instant::now();
    let guides = match (&image.aovs.albedo, &image.aovs.normal) {
        (Some(_), Some(_)) => "albedo and normal",
        (Some(_), None) => "albedo",
        _ => {
            crate::terminal::say(format_args!(
                "warning: the image has no albedo and normal layers; denoising the beauty \
                 alone keeps less detail (render with --denoise or --aov albedo,normal)"
            ));
            "nothing"
        }
    };
    denoise(image, threads.unwrap_or(0) as usize)?;
    if !quiet {
        crate::terminal::say(format_args!(
            "denoised {}x{} guided by {guides} in {:.2} s",
            image.width,
            image.height,
            start.elapsed().as_secs_f64()
        ));
    }
    Ok(())
}

/// Reads a gridtrace EXR, denoises it (from its noisy layer when it was denoised before)
/// and writes the result with its record.
pub fn run_denoise(args: &DenoiseArgs) -> Result<()> {
    set_memory_budget(args.max_memory.unwrap_or(0));
    check_output(&args.output)?;
    check_named_file(&args.input)?;
    let part = read_part(&args.input)?;
    let (width, height) = (part.record.identity.width, part.record.identity.height);
    // The part's channels (at most 32 f32) and the image made of them.
    check_memory(
        || format!("reading a {width}x{height} image"),
        (width as u64 * height as u64).saturating_mul(2 * 32 * 4),
    )?;
    let mut image = part
        .read_image()
        .with_context(|| format!("reading {}", args.input.display()))?;
    denoise_for_output(&mut image, args.threads, args.quiet)?;
    let mut record = part.record;
    record.denoised = true;
    write_last(&args.output, &image, &record, args.view_transform.into())?;
    if !args.quiet {
        crate::terminal::say(format_args!("wrote {}", args.output.display()));
    }
    Ok(())
}
