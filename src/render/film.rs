//! The image being rendered: one averaged radiance value and coverage per pixel.

use glam::Vec3;

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
        }
    }

    /// The pixel at column `x`, row `y`.
    pub fn pixel(&self, x: u32, y: u32) -> Vec3 {
        self.pixels[(y * self.width + x) as usize]
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
#[derive(Clone, Copy, Debug, Default)]
pub struct PixelAccumulator {
    sum: Vec3,
    hits: u32,
    /// Samples dropped for being NaN or infinite.
    pub nonfinite: u32,
}

impl PixelAccumulator {
    /// Adds one sample.
    pub fn add(&mut self, radiance: Vec3, hit: bool) {
        if radiance.is_finite() {
            self.sum += radiance;
        } else {
            self.nonfinite += 1;
        }
        self.hits += u32::from(hit);
    }

    /// The box-filtered value over `spp` samples: (radiance, alpha). A dropped sample counts
    /// as black, which biases that pixel slightly dark instead of poisoning it.
    pub fn resolve(&self, spp: u32) -> (Vec3, f32) {
        (self.sum / spp as f32, self.hits as f32 / spp as f32)
    }
}
