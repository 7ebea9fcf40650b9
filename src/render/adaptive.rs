//! Adaptive sampling: a pixel stops taking samples once its estimated error is below the
//! `--noise-threshold`.
//!
//! The error estimate is the standard error of the pixel's mean (from the sample variance
//! of its radiance, averaged over the three channels) divided by the square root of its
//! mean intensity — the normalisation of Dammertz et al. 2010 ("A hierarchical automatic
//! stopping condition for Monte Carlo global illumination") that Cycles' adaptive sampling
//! uses, between absolute error (which would stop dark pixels too soon) and relative error
//! (which would never stop them). Decisions are made between passes from each pixel's sums,
//! which do not depend on how pixels were shared among threads: the same seed and threshold
//! give the same image on any thread count.

use super::aov::{FeatureAccumulator, sample_variance};
use super::film::PixelAccumulator;

/// Intensity floor in the error's denominator, so black pixels converge (as in Cycles).
const INTENSITY_FLOOR: f64 = 1e-4;

/// Passes between convergence checks.
const CHECK_EVERY: u32 = 4;

/// When and how pixels are judged converged.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Schedule {
    /// The noise threshold.
    pub threshold: f32,
    /// Samples every pixel takes before any may stop.
    pub min_samples: u32,
}

impl Schedule {
    /// The schedule of a render of `spp` samples per pixel: at least 16 samples, or √spp
    /// when more (Cycles' automatic minimum), before the first check.
    pub fn new(threshold: f32, spp: u32) -> Schedule {
        let min_samples = (f64::from(spp).sqrt().ceil() as u32).max(16).min(spp);
        Schedule {
            threshold,
            min_samples,
        }
    }

    /// True when pixels are judged after `passes` passes.
    pub fn check_after(&self, passes: u32) -> bool {
        passes >= self.min_samples && (passes - self.min_samples).is_multiple_of(CHECK_EVERY)
    }

    /// Passes from `done` to the next pass count after which pixels are judged.
    pub fn passes_until_check(&self, done: u32) -> u32 {
        if done < self.min_samples {
            return self.min_samples - done;
        }
        CHECK_EVERY - (done - self.min_samples) % CHECK_EVERY
    }

    /// The estimated error of a pixel's mean over its `n` samples.
    pub fn error(beauty: &PixelAccumulator, features: &FeatureAccumulator, n: u32) -> f64 {
        if n < 2 {
            return f64::INFINITY;
        }
        let variance = sample_variance(beauty.sum(), features.squares(), n).as_dvec3();
        let standard_error = (variance.element_sum() / 3.0 / f64::from(n)).sqrt();
        let intensity = beauty.sum().element_sum() / 3.0 / f64::from(n);
        standard_error / (INTENSITY_FLOOR + intensity.max(0.0)).sqrt()
    }

    /// True when the pixel may stop.
    pub fn converged(
        &self,
        beauty: &PixelAccumulator,
        features: &FeatureAccumulator,
        n: u32,
    ) -> bool {
        n >= self.min_samples && Schedule::error(beauty, features, n) < f64::from(self.threshold)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::render::Features;
    use glam::Vec3;

    fn pixel(values: &[f32]) -> (PixelAccumulator, FeatureAccumulator) {
        let (mut b, mut f) = (PixelAccumulator::default(), FeatureAccumulator::default());
        for &v in values {
            b.add(Vec3::splat(v), true);
            f.add(&Features::default(), Vec3::splat(v));
        }
        (b, f)
    }

    /// The passes to the next check lead, from every pass count, to the first count after
    /// it that [`Schedule::check_after`] accepts.
    #[test]
    fn the_next_check_is_the_first_pass_count_checked() {
        for spp in [1, 16, 20, 100, 1024] {
            let schedule = Schedule::new(0.01, spp);
            for done in 0..spp {
                let next = done + schedule.passes_until_check(done);
                let first = (done + 1..).find(|&p| schedule.check_after(p)).unwrap();
                assert_eq!(next, first, "spp {spp}, after {done}");
            }
        }
    }

    #[test]
    fn error_is_the_standard_error_over_root_intensity() {
        // Samples 0 and 2 alternating: mean 1, sample variance 64/63 · 1, n = 64.
        let values: Vec<f32> = (0..64)
            .map(|i| if i % 2 == 0 { 0.0 } else { 2.0 })
            .collect();
        let (b, f) = pixel(&values);
        let expected = (64.0f64 / 63.0 / 64.0).sqrt() / (1.0 + INTENSITY_FLOOR).sqrt();
        let error = Schedule::error(&b, &f, 64);
        assert!((error / expected - 1.0).abs() < 1e-6, "{error} {expected}");
        let (flat, flat_f) = pixel(&[0.5; 20]);
        assert!(Schedule::error(&flat, &flat_f, 20) < 1e-6);
        let schedule = Schedule::new(0.01, 1024);
        assert_eq!(schedule.min_samples, 32);
        assert!(!schedule.converged(&flat, &flat_f, 20), "below the minimum");
        assert!(Schedule::new(0.01, 64).converged(&flat, &flat_f, 20));
        assert!(!schedule.converged(&b, &f, 64));
    }
}
