//! Training the guide on the image's own first samples (Müller et al. 2017, §3.4, with a
//! fixed schedule): samples 0, 1, 2–3, 4–7 and 8–15 of every pixel are the training passes.
//! Each is traced with the guide as the passes before it left it and records into the
//! guide, which is rebuilt at the end of the pass; later samples use the final guide.
//!
//! A sample's value therefore depends only on (seed, pixel, index) and the scene, as
//! without guiding: a process that renders a range starting after sample 0 first traces
//! the training samples before its range, keeping nothing but what they teach the guide,
//! and so holds the same guide at every index as a process that rendered them.

use rayon::prelude::*;

use super::Guide;
use crate::render::integrator::{NextEvent, PathGuiding, PathOptions};
use crate::render::sampler::Sampler;
use crate::render::{CameraSampling, RenderSettings, Renderer};

/// Samples per pixel of each training pass.
const TRAINING_PASSES: [u32; 5] = [1, 1, 2, 4, 8];

/// The first sample index after training.
pub const TRAINING_SAMPLES: u32 = 16;

/// How a path at sample index `sample` uses `guide`: it trains it during the training
/// passes and only samples it after.
pub fn guiding_at(guide: Option<&Guide>, sample: u32) -> PathGuiding<'_> {
    match guide {
        None => PathGuiding::Off,
        Some(g) if sample < TRAINING_SAMPLES => PathGuiding::Train(g),
        Some(g) => PathGuiding::Sample(g),
    }
}

impl Guide {
    /// Called once every pixel's sample `sample` is traced: ends the training pass that
    /// sample closes, if it closes one.
    pub fn after_sample(&mut self, sample: u32) {
        let mut end = 0;
        for (pass, spp) in TRAINING_PASSES.iter().enumerate() {
            end += spp;
            if sample + 1 == end {
                self.end_pass(pass as u32);
            }
        }
    }
}

impl Renderer<'_> {
    /// Traces the training samples `0..end` of every pixel (`end` at most
    /// [`TRAINING_SAMPLES`]) into `guide`, keeping no image: what a process whose range
    /// starts at `end` needs to hold the guide the whole render holds there.
    pub(crate) fn train_guide_before(
        &self,
        view: &CameraSampling,
        settings: &RenderSettings,
        guide: &mut Guide,
        end: u32,
        next_event: NextEvent,
    ) {
        let seed = crate::render::sampling::mix64(settings.seed);
        let (width, height) = (settings.width as usize, settings.height as usize);
        for sample in 0..end.min(TRAINING_SAMPLES) {
            (0..height).into_par_iter().for_each(|y| {
                for x in 0..width {
                    let mut sampler = Sampler::for_sample(seed, (y * width + x) as u64, sample);
                    let ray = view.ray(x, y, &mut sampler);
                    let options = PathOptions {
                        max_depth: settings.max_depth,
                        strategy: settings.strategy,
                        want_features: false,
                        guiding: PathGuiding::Train(guide),
                        next_event,
                        eye: None,
                    };
                    self.trace_path_with(ray, &mut sampler, options);
                }
            });
            guide.after_sample(sample);
        }
    }
}
