//! `gridtrace merge`: parts of one render into one image.

use std::time::Instant;

use anyhow::Result;

use super::args::MergeArgs;
use super::denoise::denoise_for_output;
use super::signals::{check_output, write_last};
use crate::limits::set_memory_budget;
use crate::load::access::check_named_file;
use crate::output::denoise::check_available;
use crate::output::merge::merge_files;
use crate::record::format_range;

/// Reads, checks and merges the parts, and writes the merged image.
pub fn run_merge(args: &MergeArgs) -> Result<()> {
    set_memory_budget(args.max_memory.unwrap_or(0));
    if args.denoise {
        check_available()?;
    }
    check_output(&args.output)?;
    for part in &args.parts {
        check_named_file(part)?;
    }
    let start = Instant::now();
    let (mut image, mut record) = merge_files(&args.parts, args.samples.clone())?;
    if record.nonfinite > 0 {
        crate::terminal::say(format_args!(
            "warning: {} sample(s) were NaN or infinite and were dropped",
            record.nonfinite
        ));
    }
    if args.denoise {
        denoise_for_output(&mut image, args.threads, args.quiet)?;
        record.denoised = true;
    }
    write_last(&args.output, &image, &record, args.view_transform.into())?;
    if !args.quiet {
        crate::terminal::say(format_args!(
            "merged {} part(s) of {} ({}x{}, camera {}): samples {} in {:.2} s; wrote {}",
            args.parts.len(),
            record.scene_name,
            image.width,
            image.height,
            record.identity.camera,
            format_range(&record.samples),
            start.elapsed().as_secs_f64(),
            args.output.display()
        ));
    }
    Ok(())
}
