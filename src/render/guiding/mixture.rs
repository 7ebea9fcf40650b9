//! A BSDF and a guiding distribution sampled as one mixture: with probability
//! [`GUIDE_FRACTION`] the guide proposes the direction, otherwise the BSDF does, and the
//! sample is weighed by the mixture's density (one-sample MIS with the balance heuristic,
//! Veach 1997 §9.2.4, as the paper's §5 combines them). Next-event estimation sees the
//! mixture's density too, so its MIS weights stay right.

use glam::{Vec2, Vec3};

use super::quadtree::Distribution;
use crate::render::bsdf::{Bsdf, BsdfSample};
use crate::render::sampler::Sampler;

/// The share of directions the guide proposes (the paper's fixed α = 0.5).
pub const GUIDE_FRACTION: f32 = 0.5;

/// A BSDF at a vertex, and the guide's distribution there when the vertex is guided.
pub struct GuidedBsdf<'a> {
    /// The surface's BSDF.
    pub bsdf: &'a Bsdf,
    /// The guide's distribution at the vertex: `None` samples the BSDF alone.
    pub guide: Option<&'a Distribution>,
}

impl GuidedBsdf<'_> {
    /// Solid-angle density with which [`GuidedBsdf::sample`] picks `wi` by its non-delta
    /// strategies.
    pub fn pdf(&self, n: Vec3, wo: Vec3, wi: Vec3) -> f32 {
        let bsdf = self.bsdf.pdf(n, wo, wi);
        match self.guide {
            None => bsdf,
            Some(guide) => mix(guide.pdf(wi), bsdf),
        }
    }

    /// Draws an incident direction from the BSDF's numbers (direction pair, then lobe
    /// choice). With a guide, the pair's first number also chooses the strategy and is
    /// rescaled within the share chosen, so that each strategy's directions stay
    /// stratified over the pixel's samples, as the BSDF's alone are.
    pub fn sample(&self, n: Vec3, wo: Vec3, sampler: &mut Sampler) -> Option<BsdfSample> {
        let (u, u_lobe) = (sampler.uniform2(), sampler.uniform());
        let Some(guide) = self.guide else {
            return self.bsdf.sample(n, wo, u, u_lobe);
        };
        let below_one = 1.0 - f32::EPSILON;
        if u.x < GUIDE_FRACTION {
            let u = Vec2::new((u.x / GUIDE_FRACTION).min(below_one), u.y);
            let (wi, guide_pdf) = guide.sample(u);
            let f = self.bsdf.eval(n, wo, wi);
            let pdf = mix(guide_pdf, self.bsdf.pdf(n, wo, wi));
            if f == Vec3::ZERO || pdf <= 0.0 {
                return None;
            }
            return Some(BsdfSample {
                wi,
                weight: f / pdf,
                pdf,
                is_delta: false,
                is_transmission: wi.dot(n) < 0.0,
            });
        }
        let rest = ((u.x - GUIDE_FRACTION) / (1.0 - GUIDE_FRACTION)).clamp(0.0, below_one);
        let sample = self.bsdf.sample(n, wo, Vec2::new(rest, u.y), u_lobe)?;
        if sample.is_delta {
            // The guide cannot draw a delta lobe's direction: only the BSDF's share counts.
            let share = 1.0 - GUIDE_FRACTION;
            return Some(BsdfSample {
                weight: sample.weight / share,
                pdf: sample.pdf * share,
                ..sample
            });
        }
        let pdf = mix(guide.pdf(sample.wi), sample.pdf);
        Some(BsdfSample {
            weight: sample.weight * (sample.pdf / pdf),
            pdf,
            ..sample
        })
    }
}

/// The mixture's density from the guide's and the BSDF's.
fn mix(guide_pdf: f32, bsdf_pdf: f32) -> f32 {
    GUIDE_FRACTION * guide_pdf + (1.0 - GUIDE_FRACTION) * bsdf_pdf
}
