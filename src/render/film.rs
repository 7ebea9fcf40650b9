//! The image being rendered: one averaged radiance value and coverage per pixel.

use std::ops::Range;

use glam::{DVec3, Vec3};

/// A linear-radiance RGB image with coverage alpha, rows top to bottom.
#[derive(Clone, Debug, PartialEq)]
pub struct Image {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// Mean radiance per pixel, row-major.
    pub pixels: Vec<Vec3>,
    /// Fraction of camera rays per pixel that hit geometry.
    pub alpha: Vec<f32>,
    /// Samples per pixel the image holds.
    pub spp: u32,
    /// Index of the first of those samples: the image holds samples
    /// `first_sample..first_sample + spp` of every pixel ([`Image::samples`]).
    pub first_sample: u32,
}

impl Image {
    /// A black, transparent image.
    pub fn new(width: u32, height: u32) -> Image {
        let n = width as usize * height as usize;
        Image {
            width,
            height,
            pixels: vec![Vec3::ZERO; n],
            alpha: vec![0.0; n],
            spp: 0,
            first_sample: 0,
        }
    }

    /// The sample indices every pixel holds.
    pub fn samples(&self) -> Range<u32> {
        self.first_sample..self.first_sample + self.spp
    }

    /// The pixel at column `x`, row `y`.
    pub fn pixel(&self, x: u32, y: u32) -> Vec3 {
        self.pixels[(y * self.width + x) as usize]
    }

    /// The image with every radiance multiplied by `factor` (alpha unchanged).
    pub fn scaled(mut self, factor: f32) -> Image {
        if factor != 1.0 {
            self.pixels.iter_mut().for_each(|p| *p *= factor);
        }
        self
    }

    /// Mean of all pixels.
    pub fn mean(&self) -> Vec3 {
        let sum = self
            .pixels
            .iter()
            .fold(glam::DVec3::ZERO, |s, p| s + p.as_dvec3());
        (sum / self.pixels.len().max(1) as f64).as_vec3()
    }
}

/// Sums samples for one pixel. Non-finite samples are dropped and counted, never averaged in.
///
/// The sum is kept in f64 so that a pixel's mean does not depend on how its samples were
/// grouped: the means of sample ranges rendered apart, weighted by their counts, add up to
/// the mean of one render to within f32 rounding (see [`PixelAccumulator::from_mean`]).
#[derive(Clone, Copy, Debug, Default)]
pub struct PixelAccumulator {
    sum: DVec3,
    hits: u64,
    /// Samples dropped for being NaN or infinite.
    pub nonfinite: u32,
}

impl PixelAccumulator {
    /// Adds one sample.
    pub fn add(&mut self, radiance: Vec3, hit: bool) {
        if radiance.is_finite() {
            self.sum += radiance.as_dvec3();
        } else {
            self.nonfinite += 1;
        }
        self.hits += u64::from(hit);
    }

    /// The accumulator of `spp` samples whose resolved mean was (`mean`, `alpha`): what a
    /// merge starts from. The hit count is recovered exactly (alpha · spp rounds to it for
    /// fewer than 2^23 samples); the radiance sum to within the f32 rounding of `mean`.
    pub fn from_mean(mean: Vec3, alpha: f32, spp: u32) -> PixelAccumulator {
        let n = f64::from(spp);
        PixelAccumulator {
            sum: mean.as_dvec3() * n,
            hits: (f64::from(alpha) * n).round() as u64,
            nonfinite: 0,
        }
    }

    /// Adds the samples of another accumulator of the same pixel.
    pub fn merge(&mut self, other: &PixelAccumulator) {
        self.sum += other.sum;
        self.hits += other.hits;
        self.nonfinite += other.nonfinite;
    }

    /// The box-filtered value over `spp` samples: (radiance, alpha). A dropped sample counts
    /// as black, which biases that pixel slightly dark instead of poisoning it.
    pub fn resolve(&self, spp: u32) -> (Vec3, f32) {
        let n = f64::from(spp.max(1));
        ((self.sum / n).as_vec3(), (self.hits as f64 / n) as f32)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn one_range_merged_alone_is_bit_exact() {
        let mut acc = PixelAccumulator::default();
        for i in 0..37 {
            acc.add(
                Vec3::new(0.1 * i as f32, 1.0 / (i + 1) as f32, 3.7),
                i % 3 == 0,
            );
        }
        let (mean, alpha) = acc.resolve(37);
        let again = PixelAccumulator::from_mean(mean, alpha, 37).resolve(37);
        assert_eq!(again, (mean, alpha));
    }
}
