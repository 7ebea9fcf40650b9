//! Training the guide: passes of guided paths over the whole image whose only product is
//! what they record, each pass sampling from what the previous ones learned (Müller et al.
//! 2017, §3.4, with a fixed schedule rather than one that grows with the render, so that
//! every process of a split render, whatever its range, trains the same guide).

use rayon::prelude::*;

use super::Guide;
use crate::render::integrator::PathGuiding;
use crate::render::sampler::Sampler;
use crate::render::sampling::mix64;
use crate::render::{CameraSampling, RenderSettings, Renderer};

/// Samples per pixel of each training pass: 8 in all, a small share of a final render's.
pub const TRAINING_PASSES: [u32; 4] = [1, 1, 2, 4];

/// Mixed into the seed of training samples, so that their streams are not the image's.
const TRAINING_STREAM: u64 = 0x6775_6964_696e_6721;

impl Renderer<'_> {
    /// Trains a guide for this view: [`TRAINING_PASSES`], each over every pixel, on
    /// random streams of their own. The result depends on the scene, the view and the
    /// settings' seed and depth alone, not on the thread count or the sample range.
    pub(crate) fn train_guide(&self, view: &CameraSampling, settings: &RenderSettings) -> Guide {
        let mut guide = Guide::new(self.scene.bounds());
        let seed = mix64(mix64(settings.seed) ^ TRAINING_STREAM);
        let (width, height) = (settings.width as usize, settings.height as usize);
        let mut first = 0u32;
        for (pass, &spp) in TRAINING_PASSES.iter().enumerate() {
            let indices = first..first + spp;
            (0..height).into_par_iter().for_each(|y| {
                for x in 0..width {
                    let pixel = (y * width + x) as u64;
                    for index in indices.clone() {
                        let mut sampler = Sampler::for_sample(seed, pixel, index);
                        let ray = view.ray(x, y, &mut sampler);
                        self.trace_path_guided(
                            ray,
                            &mut sampler,
                            settings.max_depth,
                            settings.strategy,
                            false,
                            PathGuiding::Train(&guide),
                        );
                    }
                }
            });
            guide.end_pass(pass as u32);
            first += spp;
        }
        guide
    }
}
