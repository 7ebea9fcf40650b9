//! What a render says and writes when it is ready and when it ends: the scene's summary,
//! why it ended early, the denoised image, the output with its record, the speed.

use std::time::Duration;

use anyhow::Result;

use super::super::Outcome;
use super::super::args::Args;
use super::super::denoise::denoise_for_output;
use super::super::signals::write_last;
use super::passes::Rendered;
use super::plan::Plan;
use super::prepare::Prepared;
use crate::record::format_range;
use crate::render::{EarlyEnd, RenderStats, Renderer};

/// The line that says what was loaded and how long preparing it took.
pub fn prepared(plan: &Plan, prepared: &Prepared, renderer: &Renderer, took: Duration) {
    let scene = &prepared.scene;
    let camera = &prepared.camera;
    crate::terminal::say(format_args!(
        "{}: {} triangles in {} instances, {} emissive, {} punctual light(s); camera {}; \
         prepared in {:.2} s",
        plan.request.scene_path.display(),
        scene.instanced_triangle_count(),
        scene.instances.len(),
        renderer.lights().len(),
        renderer.lights().punctual_len(),
        if camera.name.is_empty() {
            &camera.source
        } else {
            &camera.name
        },
        took.as_secs_f64()
    ));
}

/// Says how the render ended, denoises if asked, writes the output and the summary.
/// How long the final image may wait for a live viewer once the output is written: a
/// twentieth of the render's time, between 10 ms and 2 s, so a slow viewer adds at most
/// 5 % to a render.
fn live_view_grace(render: Duration) -> Duration {
    (render / 20).clamp(Duration::from_millis(10), Duration::from_secs(2))
}

pub fn finish(
    args: &Args,
    plan: &Plan,
    prepared: &Prepared,
    rendered: Rendered,
) -> Result<Outcome> {
    let Rendered {
        mut image,
        stats,
        recorder,
        mut display,
        checkpoint_error,
    } = rendered;
    if let Some(e) = checkpoint_error {
        crate::terminal::say(format_args!(
            "warning: a checkpoint could not be written: {e}"
        ));
    }
    tell_how_it_ended(args, prepared, &image, &stats);
    if let Some(view) = &mut display {
        view.show(&image);
    }
    if args.image.denoise {
        denoise_for_output(&mut image, args.threads, args.image.quiet)?;
        if let Some(view) = &mut display {
            view.show(&image);
        }
    }
    let record = recorder.record(&image, &stats);
    let view = args.image.view_transform.into();
    write_last(&plan.output, &image, &record, view)?;
    if let Some(view) = &mut display {
        view.finish(live_view_grace(stats.elapsed));
    }
    if !args.image.quiet {
        let seconds = stats.elapsed.as_secs_f64().max(1e-9);
        let range = match args.sampling.samples {
            Some(_) => format!(" (samples {})", format_range(&image.samples())),
            None => String::new(),
        };
        crate::terminal::say(format_args!(
            "rendered {}x{} at {} spp{range} in {seconds:.2} s: {:.2} M samples/s, {:.2} M rays/s; wrote {}",
            image.width,
            image.height,
            stats.spp,
            stats.samples as f64 / seconds / 1e6,
            stats.rays as f64 / seconds / 1e6,
            plan.output.display()
        ));
    }
    Ok(match stats.ended_early {
        Some(EarlyEnd::Stopped) => Outcome::Interrupted,
        _ => Outcome::Completed,
    })
}

/// Why the render ended before its last pass (a time limit, convergence, a signal), how
/// many samples adaptive sampling took, and how many samples were dropped.
fn tell_how_it_ended(
    args: &Args,
    prepared: &Prepared,
    image: &crate::render::Image,
    stats: &RenderStats,
) {
    let settings = &prepared.settings;
    let pixels = settings.width as f64 * settings.height as f64;
    let why = match stats.ended_early {
        Some(EarlyEnd::TimeLimit) => Some("the time limit came"),
        Some(EarlyEnd::Converged) => Some("every pixel reached the noise threshold"),
        _ => None,
    };
    if let Some(why) = why {
        crate::terminal::say(format_args!(
            "{why} after {} of at most {} passes ({:.2} samples per pixel on average)",
            stats.spp,
            settings.spp(),
            stats.samples as f64 / pixels
        ));
    } else if settings.noise_threshold.is_some() && !args.image.quiet {
        crate::terminal::say(format_args!(
            "adaptive sampling took {:.2} samples per pixel on average ({} at most)",
            stats.samples as f64 / pixels,
            stats.spp
        ));
    }
    if stats.ended_early == Some(EarlyEnd::Stopped) {
        crate::terminal::say(format_args!(
            "stopped after {} of {} samples per pixel (samples {}); writing the image so far",
            stats.spp,
            settings.spp(),
            format_range(&image.samples())
        ));
    }
    if stats.nonfinite > 0 {
        crate::terminal::say(format_args!(
            "warning: {} sample(s) were NaN or infinite and were dropped",
            stats.nonfinite
        ));
    }
}
