//! A BSDF and a guiding distribution sampled as one mixture: with probability α, the
//! region's share ([`super::fraction`]), the guide proposes the direction, otherwise the
//! BSDF does, and the sample is weighed by the mixture's density (one-sample MIS with the
//! balance heuristic, Veach 1997 §9.2.4, as the paper's §5 combines them). Next-event
//! estimation sees the mixture's density too, so its MIS weights stay right.

use glam::{Vec2, Vec3};

use super::quadtree::Distribution;
use crate::render::bsdf::{Bsdf, BsdfSample};
use crate::render::sampler::Sampler;

/// A BSDF at a vertex, and the guide's distribution there when the vertex is guided.
pub struct GuidedBsdf<'a> {
    /// The surface's BSDF.
    pub bsdf: &'a Bsdf,
    /// The guide's distribution at the vertex: `None` samples the BSDF alone.
    pub guide: Option<&'a Distribution>,
    /// The share α of directions the guide proposes.
    pub fraction: f32,
}

impl GuidedBsdf<'_> {
    /// Solid-angle density with which [`GuidedBsdf::sample_with_densities`] picks `wi` by
    /// its non-delta strategies.
    pub fn pdf(&self, n: Vec3, wo: Vec3, wi: Vec3) -> f32 {
        let bsdf = self.bsdf.pdf(n, wo, wi);
        match self.guide {
            // A share of 0 (a region that only records, while training) needs no lookup.
            Some(guide) if self.fraction > 0.0 => self.mix(guide.pdf(wi), bsdf),
            _ => bsdf,
        }
    }

    /// Draws an incident direction from the BSDF's set of numbers (direction pair and lobe
    /// choice, stratified together). With a guide, the pair's first number also chooses
    /// the strategy and is rescaled within the share chosen, so that each strategy's
    /// directions stay stratified over the pixel's samples, as the BSDF's alone are. Also
    /// gives the guide's density and the BSDF's at the direction (the guide's 0 without a
    /// guide, or for a delta lobe's direction, whose BSDF density is then given as 1): what
    /// a training record keeps to score other shares.
    pub fn sample_with_densities(
        &self,
        n: Vec3,
        wo: Vec3,
        sampler: &mut Sampler,
    ) -> Option<(BsdfSample, (f32, f32))> {
        let (u, u_lobe) = sampler.uniform3();
        let Some(guide) = self.guide else {
            let sample = self.bsdf.sample(n, wo, u, u_lobe)?;
            let bsdf_pdf = if sample.is_delta { 1.0 } else { sample.pdf };
            return Some((sample, (0.0, bsdf_pdf)));
        };
        let below_one = 1.0 - f32::EPSILON;
        let alpha = self.fraction;
        if u.x < alpha {
            let u = Vec2::new((u.x / alpha).min(below_one), u.y);
            let (wi, guide_pdf) = guide.sample(u);
            let f = self.bsdf.eval(n, wo, wi);
            let bsdf_pdf = self.bsdf.pdf(n, wo, wi);
            let pdf = self.mix(guide_pdf, bsdf_pdf);
            if f == Vec3::ZERO || pdf <= 0.0 {
                return None;
            }
            let sample = BsdfSample {
                wi,
                weight: f / pdf,
                pdf,
                is_delta: false,
                is_transmission: wi.dot(n) < 0.0,
            };
            return Some((sample, (guide_pdf, bsdf_pdf)));
        }
        let rest = ((u.x - alpha) / (1.0 - alpha)).clamp(0.0, below_one);
        let sample = self.bsdf.sample(n, wo, Vec2::new(rest, u.y), u_lobe)?;
        if sample.is_delta {
            // The guide cannot draw a delta lobe's direction: only the BSDF's share counts.
            let share = 1.0 - alpha;
            let sample = BsdfSample {
                weight: sample.weight / share,
                pdf: sample.pdf * share,
                ..sample
            };
            return Some((sample, (0.0, 1.0)));
        }
        let guide_pdf = guide.pdf(sample.wi);
        let pdf = self.mix(guide_pdf, sample.pdf);
        let mixed = BsdfSample {
            weight: sample.weight * (sample.pdf / pdf),
            pdf,
            ..sample
        };
        Some((mixed, (guide_pdf, sample.pdf)))
    }

    /// The mixture's density from the guide's and the BSDF's.
    fn mix(&self, guide_pdf: f32, bsdf_pdf: f32) -> f32 {
        self.fraction * guide_pdf + (1.0 - self.fraction) * bsdf_pdf
    }
}
