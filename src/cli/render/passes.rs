//! The render itself: passes over the image with a progress bar, the live view updated and
//! checkpoints written between passes.

use std::sync::atomic::AtomicBool;
use std::time::{Duration, Instant};

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};

use super::super::args::Args;
use super::super::signals::{Phase, set_phase, write_output};
use super::plan::Plan;
use super::prepare::Prepared;
use crate::output::display::LiveView;
use crate::output::{OutputError, ViewTransform};
use crate::record::{RenderIdentity, RenderRecord};
use crate::render::{Image, RenderStats, Renderer};

/// What the passes produced.
pub struct Rendered {
    /// The image, exposure applied.
    pub image: Image,
    /// How the render went.
    pub stats: RenderStats,
    /// How to record the image (and any later form of it).
    pub recorder: Recorder,
    /// The live view, if one was asked for.
    pub display: Option<LiveView>,
    /// Why a checkpoint could not be written, if one could not.
    pub checkpoint_error: Option<OutputError>,
}

/// Turns images of the render into what gets written: exposure applied, record made.
pub struct Recorder {
    identity: RenderIdentity,
    scene_name: String,
    noise_threshold: Option<f32>,
    exposure: f32,
}

impl Recorder {
    /// `image` as written: scaled by 2^exposure (which scales what is written, never what
    /// is accumulated).
    pub fn exposed(&self, image: Image) -> Image {
        image.scaled(self.exposure.exp2())
    }

    /// The record of `image`.
    pub fn record(&self, image: &Image, stats: &RenderStats) -> RenderRecord {
        RenderRecord {
            identity: self.identity.clone(),
            scene_name: self.scene_name.clone(),
            samples: image.samples(),
            nonfinite: stats.nonfinite,
            noise_threshold: self.noise_threshold,
            denoised: image.aovs.noisy.is_some(),
        }
    }
}

/// Writes the image so far to the output every `every`, as a part `merge` accepts.
struct Checkpointer<'a> {
    every: Option<Duration>,
    last: Instant,
    error: Option<OutputError>,
    output: &'a std::path::Path,
    view: ViewTransform,
}

impl Checkpointer<'_> {
    fn maybe_write(
        &mut self,
        recorder: &Recorder,
        image_so_far: &dyn Fn() -> (Image, RenderStats),
    ) {
        let Some(every) = self.every else { return };
        if self.last.elapsed() < every || self.error.is_some() {
            return;
        }
        let (image, stats) = image_so_far();
        let image = recorder.exposed(image);
        let record = recorder.record(&image, &stats);
        if let Err(e) = write_output(self.output, &image, Some(&record), self.view, None) {
            self.error = Some(e);
        }
        self.last = Instant::now();
    }
}

/// Renders the passes the settings ask for, until they are done, the time is up, every
/// pixel has converged or `stop` is set.
pub fn render_passes(
    args: &Args,
    plan: &Plan,
    prepared: &Prepared,
    renderer: &Renderer,
    pool: &rayon::ThreadPool,
    identity: RenderIdentity,
    stop: &AtomicBool,
) -> Rendered {
    let settings = &prepared.settings;
    let scene_name = plan
        .request
        .scene_path
        .file_name()
        .map_or_else(String::new, |n| n.to_string_lossy().into_owned());
    let recorder = Recorder {
        identity,
        scene_name,
        noise_threshold: settings.noise_threshold,
        exposure: args.image.exposure,
    };
    let bar = progress_bar(
        settings.height as u64 * settings.spp() as u64,
        args.image.quiet || args.sampling.time_limit.is_some(),
    );
    let mut display = args.image.display.as_deref().map(|address| {
        LiveView::start(
            address,
            &recorder.scene_name,
            settings.width,
            settings.height,
        )
    });
    let mut checkpoints = Checkpointer {
        every: args.image.checkpoint.map(Duration::from_secs_f64),
        last: Instant::now(),
        error: None,
        output: &plan.output,
        view: args.image.view_transform.into(),
    };
    let most_passes = settings.spp();
    let report_progress = args.image.progress.is_some();
    let started = Instant::now();
    let mut on_pass = |passes_done: u32, image_so_far: &dyn Fn() -> (Image, RenderStats)| {
        if report_progress {
            crate::terminal::say(format_args!(
                "{{\"pass\":{passes_done},\"of\":{most_passes},\"seconds\":{:.3}}}",
                started.elapsed().as_secs_f64()
            ));
        }
        if let Some(view) = &mut display
            && view.wants_update()
        {
            view.show(&recorder.exposed(image_so_far().0));
        }
        checkpoints.maybe_write(&recorder, image_so_far);
    };
    set_phase(Phase::Rendering);
    let (image, stats) = pool.install(|| {
        renderer.render_with_checkpoints(
            &prepared.camera,
            settings,
            &|| bar.inc(1),
            stop,
            &mut on_pass,
        )
    });
    bar.finish_and_clear();
    let image = recorder.exposed(image);
    Rendered {
        image,
        stats,
        checkpoint_error: checkpoints.error,
        recorder,
        display,
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
