//! The image being rendered: per pixel the sums of its samples' radiance, coverage and,
//! when asked, auxiliary features ([`Film`]); and the image they resolve to ([`Image`]).

use std::ops::Range;

use glam::{DVec3, Vec3};

use super::aov::{AovImage, AovSet, FeatureAccumulator, Features};

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
    /// Auxiliary layers (albedo, normal, depth, …) and the noisy beauty of a denoised image.
    pub aovs: AovImage,
    /// Samples each pixel holds when adaptive sampling stopped some early (row-major);
    /// `None` when every pixel holds `spp`.
    pub pixel_samples: Option<Vec<u32>>,
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
            aovs: AovImage::default(),
            pixel_samples: None,
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

    /// The image with every radiance multiplied by `factor` (alpha and features unchanged,
    /// variance by its square).
    pub fn scaled(mut self, factor: f32) -> Image {
        if factor != 1.0 {
            self.pixels.iter_mut().for_each(|p| *p *= factor);
            self.aovs.scale_radiance(factor);
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

    /// The radiance sum.
    pub fn sum(&self) -> DVec3 {
        self.sum
    }

    /// The box-filtered value over `spp` samples: (radiance, alpha). A dropped sample counts
    /// as black, which biases that pixel slightly dark instead of poisoning it.
    pub fn resolve(&self, spp: u32) -> (Vec3, f32) {
        let n = f64::from(spp.max(1));
        ((self.sum / n).as_vec3(), (self.hits as f64 / n) as f32)
    }
}

/// The sums of every pixel's samples while an image is rendered.
pub struct Film {
    width: usize,
    height: usize,
    first_sample: u32,
    aovs: AovSet,
    beauty: Vec<PixelAccumulator>,
    /// One per pixel when auxiliary layers or adaptive sampling need them, else empty.
    features: Vec<FeatureAccumulator>,
    /// Samples taken per pixel, kept only when adaptive sampling may stop pixels early.
    counts: Vec<u32>,
    /// Pixels still being sampled (adaptive sampling), or empty: all.
    active: Vec<bool>,
}

/// One row of the film, given to one worker.
pub struct FilmRow<'a> {
    /// Row index, top to bottom.
    pub y: usize,
    beauty: &'a mut [PixelAccumulator],
    features: Option<&'a mut [FeatureAccumulator]>,
    counts: Option<&'a mut [u32]>,
    active: Option<&'a [bool]>,
}

impl FilmRow<'_> {
    /// Pixels in the row.
    pub fn len(&self) -> usize {
        self.beauty.len()
    }

    /// True for an empty row (never, for a film of width ≥ 1).
    pub fn is_empty(&self) -> bool {
        self.beauty.is_empty()
    }

    /// True when pixel `x` is still to be sampled.
    pub fn is_active(&self, x: usize) -> bool {
        self.active.is_none_or(|a| a[x])
    }

    /// Adds one sample to pixel `x`.
    pub fn add(&mut self, x: usize, radiance: Vec3, hit: bool, features: &Features) {
        self.beauty[x].add(radiance, hit);
        if let Some(f) = &mut self.features {
            f[x].add(features, radiance);
        }
        if let Some(c) = &mut self.counts {
            c[x] += 1;
        }
    }
}

impl Film {
    /// A film holding sums already taken: `beauty` per pixel and, if any layer is kept,
    /// `features` per pixel (else empty), every pixel over the same samples from
    /// `first_sample` on. What a merge of parts resolves, with the arithmetic of a render.
    pub fn from_sums(
        width: u32,
        height: u32,
        first_sample: u32,
        aovs: AovSet,
        beauty: Vec<PixelAccumulator>,
        features: Vec<FeatureAccumulator>,
    ) -> Film {
        Film {
            width: width as usize,
            height: height as usize,
            first_sample,
            aovs,
            beauty,
            features,
            counts: Vec::new(),
            active: Vec::new(),
        }
    }

    /// An empty film for samples from `first_sample` on, keeping the layers of `aovs`, and
    /// per-pixel counts when `adaptive`.
    pub fn new(width: u32, height: u32, first_sample: u32, aovs: AovSet, adaptive: bool) -> Film {
        let n = width as usize * height as usize;
        let keep_features = aovs.any() || adaptive;
        Film {
            width: width as usize,
            height: height as usize,
            first_sample,
            aovs,
            beauty: vec![PixelAccumulator::default(); n],
            features: if keep_features {
                vec![FeatureAccumulator::default(); n]
            } else {
                Vec::new()
            },
            counts: if adaptive { vec![0; n] } else { Vec::new() },
            active: if adaptive { vec![true; n] } else { Vec::new() },
        }
    }

    /// Memory a film of `width`×`height` needs, with a second image and its encoding while
    /// a checkpoint or the output is written.
    pub fn bytes(width: u32, height: u32, aovs: AovSet, adaptive: bool) -> u64 {
        let mut per_pixel = std::mem::size_of::<PixelAccumulator>() as u64 + 3 * 16;
        if aovs.any() || adaptive {
            // The sums, and up to 14 more f32 channels in the image and its encoding.
            per_pixel += std::mem::size_of::<FeatureAccumulator>() as u64 + 3 * 14 * 4;
        }
        if adaptive {
            per_pixel += 5;
        }
        (width as u64 * height as u64).saturating_mul(per_pixel)
    }

    /// Pixels per row.
    pub fn width(&self) -> usize {
        self.width
    }

    /// True when the film keeps features, so paths should report them.
    pub fn wants_features(&self) -> bool {
        !self.features.is_empty()
    }

    /// The rows, to be filled in parallel.
    pub fn rows(&mut self) -> Vec<FilmRow<'_>> {
        let w = self.width.max(1);
        let mut features = self.features.chunks_mut(w);
        let mut counts = self.counts.chunks_mut(w);
        let mut active = self.active.chunks(w);
        self.beauty
            .chunks_mut(w)
            .enumerate()
            .map(|(y, beauty)| FilmRow {
                y,
                beauty,
                features: features.next(),
                counts: counts.next(),
                active: active.next(),
            })
            .collect()
    }

    /// Marks which pixels are still to be sampled; `converged(i, beauty, features, count)`
    /// says whether pixel `i` may stop. A pixel keeps sampling while any pixel within one
    /// of it does not converge (the dilation Cycles applies, so no seam of early-stopped
    /// pixels cuts through a noisy region). Returns the number of active pixels.
    pub fn update_active(
        &mut self,
        converged: impl Fn(&PixelAccumulator, &FeatureAccumulator, u32) -> bool,
    ) -> usize {
        if self.active.is_empty() {
            return self.beauty.len();
        }
        let (w, h) = (self.width, self.height);
        let done: Vec<bool> = (0..w * h)
            .map(|i| converged(&self.beauty[i], &self.features[i], self.counts[i]))
            .collect();
        let mut active = 0;
        for y in 0..h {
            for x in 0..w {
                let neighbour_busy = (y.saturating_sub(1)..(y + 2).min(h))
                    .any(|ny| (x.saturating_sub(1)..(x + 2).min(w)).any(|nx| !done[ny * w + nx]));
                self.active[y * w + x] = neighbour_busy;
                active += usize::from(neighbour_busy);
            }
        }
        active
    }

    /// The image of the first `passes` passes (each pixel over the samples it holds), and
    /// the number of dropped non-finite samples.
    pub fn resolve(&self, passes: u32) -> (Image, u64) {
        let mut image = Image::new(self.width as u32, self.height as u32);
        image.spp = passes;
        image.first_sample = self.first_sample;
        image.aovs = AovImage::with_layers(self.aovs, self.beauty.len());
        let mut nonfinite = 0;
        for (i, acc) in self.beauty.iter().enumerate() {
            let spp = self.counts.get(i).copied().unwrap_or(passes);
            (image.pixels[i], image.alpha[i]) = acc.resolve(spp);
            nonfinite += acc.nonfinite as u64;
            if let Some(f) = self.features.get(i) {
                image.aovs.set_pixel(i, &f.resolve(spp, acc.sum()));
            }
        }
        if !self.counts.is_empty() {
            image.pixel_samples = Some(self.counts.clone());
        }
        (image, nonfinite)
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
