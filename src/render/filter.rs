//! Pixel reconstruction filters, applied by filter importance sampling (Ernst et al. 2006,
//! "Filter importance sampling"; pbrt-v4 §8.8): each camera sample's position is drawn
//! from the filter's footprint around the pixel centre and counts with weight 1 in that one
//! pixel, so the film stays a per-pixel mean and split renders still merge exactly.
//!
//! The separable filters are sampled per axis by inverting a fine tabulated CDF: exactly
//! a piecewise-constant density of 4096 steps, which follows even the near-zero tails of
//! Blackman–Harris (a coarse inverse-CDF table interpolated linearly, Cycles' way, puts a
//! flat 0.1 % of the samples there). Box (gridtrace's default) is the plain jitter over the
//! pixel.

use glam::Vec2;

/// Which filter, by name on the command line.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum FilterKind {
    /// Uniform over a square `width` pixels wide (1: the pixel itself).
    #[default]
    Box,
    /// A Gaussian of σ = width/4, truncated at ±1.5·width (Cycles' definition).
    Gaussian,
    /// The 4-term Blackman–Harris window (Harris 1978) spanning ±width pixels: Cycles'
    /// definition, whose default "1.5 px" spans three pixels.
    BlackmanHarris,
}

impl FilterKind {
    /// The name on the command line and in render records.
    pub fn name(self) -> &'static str {
        match self {
            FilterKind::Box => "box",
            FilterKind::Gaussian => "gaussian",
            FilterKind::BlackmanHarris => "blackman-harris",
        }
    }

    /// The width a filter has unless told otherwise: the pixel for a box, Cycles' 1.5 px
    /// for the others.
    pub fn default_width(self) -> f32 {
        match self {
            FilterKind::Box => 1.0,
            _ => 1.5,
        }
    }
}

/// Steps of the tabulated CDF.
const STEPS: usize = 4096;

/// A filter ready to draw sample positions.
#[derive(Clone, Debug)]
pub struct PixelFilter {
    kind: FilterKind,
    width: f32,
    /// The footprint's full width in pixels.
    support: f32,
    /// The CDF over [−½, ½] (in units of the width) at `STEPS` + 1 evenly spaced points,
    /// from 0 to 1; empty for a box.
    cdf: Vec<f32>,
}

impl PixelFilter {
    /// The filter `kind`, `width` pixels wide (clamped to at least 1/64).
    pub fn new(kind: FilterKind, width: f32) -> PixelFilter {
        let width = if width.is_finite() {
            width.max(1.0 / 64.0)
        } else {
            1.0
        };
        let cdf = match kind {
            FilterKind::Box => Vec::new(),
            _ => tabulated_cdf(|t| profile(kind, t)),
        };
        PixelFilter {
            kind,
            width,
            support: width * support_per_width(kind),
            cdf,
        }
    }

    /// The default: a one-pixel box.
    pub fn pixel_box() -> PixelFilter {
        PixelFilter::new(FilterKind::Box, 1.0)
    }

    /// Its kind.
    pub fn kind(&self) -> FilterKind {
        self.kind
    }

    /// Its width in pixels.
    pub fn width(&self) -> f32 {
        self.width
    }

    /// The sample position relative to the pixel's top-left corner for uniforms `u`: the
    /// pixel's centre plus an offset drawn from the filter. A one-pixel box returns `u`
    /// itself.
    pub fn sample(&self, u: Vec2) -> Vec2 {
        match self.kind {
            FilterKind::Box if self.width == 1.0 => u,
            FilterKind::Box => Vec2::splat(0.5) + (u - 0.5) * self.width,
            _ => Vec2::new(
                0.5 + self.support * self.lookup(u.x),
                0.5 + self.support * self.lookup(u.y),
            ),
        }
    }

    /// The offset (in units of the support) where the CDF reaches `u`: the step it falls in,
    /// and the place within the step where the CDF, linear over it, reaches `u`.
    fn lookup(&self, u: f32) -> f32 {
        let j = self.cdf.partition_point(|&c| c <= u).clamp(1, STEPS);
        let (a, b) = (self.cdf[j - 1], self.cdf[j]);
        let within = if b > a { (u - a) / (b - a) } else { 0.5 };
        ((j - 1) as f32 + within.clamp(0.0, 1.0)) / STEPS as f32 - 0.5
    }
}

/// The footprint's full width over the filter's nominal width (Cycles' film.cpp: Gaussian
/// ×3, Blackman–Harris ×2).
pub fn support_per_width(kind: FilterKind) -> f32 {
    match kind {
        FilterKind::Box => 1.0,
        FilterKind::Gaussian => 3.0,
        FilterKind::BlackmanHarris => 2.0,
    }
}

/// The 1D filter's shape at `t` in [−½, ½] (in units of its support), not normalised.
pub fn profile(kind: FilterKind, t: f32) -> f32 {
    match kind {
        FilterKind::Box => 1.0,
        // exp(−x²/2σ²) with x = 3·width·t and σ = width/4.
        FilterKind::Gaussian => (-72.0 * t * t).exp(),
        FilterKind::BlackmanHarris => {
            let x = std::f32::consts::TAU * (t + 0.5);
            0.35875 - 0.48829 * x.cos() + 0.14128 * (2.0 * x).cos() - 0.01168 * (3.0 * x).cos()
        }
    }
}

/// The CDF of `f` over [−½, ½] at `STEPS` + 1 evenly spaced points, normalised to end at 1
/// (each step's mass by the midpoint rule).
fn tabulated_cdf(f: impl Fn(f32) -> f32) -> Vec<f32> {
    let mut sum = 0.0f64;
    let mut cdf = vec![0.0f64];
    for i in 0..STEPS {
        sum += f((i as f32 + 0.5) / STEPS as f32 - 0.5).max(0.0) as f64;
        cdf.push(sum);
    }
    cdf.iter().map(|&c| (c / sum) as f32).collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::render::sampling::Rng;

    /// χ² test of each filter's samples against its footprint: 40 bins across the width,
    /// expected counts from the profile's integral over each bin.
    #[test]
    fn filter_samples_match_their_footprint_chi_square() {
        for kind in [
            FilterKind::Gaussian,
            FilterKind::BlackmanHarris,
            FilterKind::Box,
        ] {
            let width = 1.5;
            let filter = PixelFilter::new(kind, width);
            let support = width * support_per_width(kind);
            let (bins, samples) = (40usize, 400_000usize);
            let mut counts = vec![0f64; bins];
            let mut r = Rng::new(29, kind as u64);
            for _ in 0..samples {
                let p = filter.sample(r.uniform2());
                let t = (p.x - 0.5) / support + 0.5;
                assert!((0.0..=1.0).contains(&t), "{kind:?}: {p}");
                counts[((t * bins as f32) as usize).min(bins - 1)] += 1.0;
            }
            let fine = 200;
            let integral: Vec<f64> = (0..bins)
                .map(|b| {
                    (0..fine)
                        .map(|k| {
                            let t = (b * fine + k) as f32 / (bins * fine) as f32
                                + 0.5 / (bins * fine) as f32
                                - 0.5;
                            profile(kind, t) as f64
                        })
                        .sum::<f64>()
                })
                .collect();
            let total: f64 = integral.iter().sum();
            let mut chi2 = 0.0;
            let mut dof = 0;
            for (c, w) in counts.iter().zip(&integral) {
                let e = samples as f64 * w / total;
                if e > 5.0 {
                    chi2 += (c - e).powi(2) / e;
                    dof += 1;
                }
            }
            // At most 39 degrees of freedom: the 99.9th percentile is about 73.4.
            assert!(chi2 < 73.4, "{kind:?}: chi2 = {chi2} over {dof} bins");
        }
    }

    #[test]
    fn a_one_pixel_box_is_the_plain_jitter() {
        let filter = PixelFilter::pixel_box();
        let u = Vec2::new(0.123, 0.987);
        assert_eq!(filter.sample(u), u);
    }
}
