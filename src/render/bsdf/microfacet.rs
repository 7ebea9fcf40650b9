//! The GGX (Trowbridge–Reitz) microfacet distribution with Smith's height-correlated
//! masking-shadowing (Walter et al. 2007, "Microfacet models for refraction through rough
//! surfaces"; Heitz 2014, "Understanding the masking-shadowing function"), and sampling of
//! its visible normals (Heitz 2018) by spherical caps (Dupuy & Benyoub 2023, "Sampling
//! visible GGX normals with spherical caps").
//!
//! Directions are in the local shading frame: the macro-normal is +Z.

use glam::{Vec2, Vec3};
use std::f32::consts::{PI, TAU};

/// Below this α (roughness ≈ 0.03) a lobe is an exact delta: GGX that sharp is a mirror to
/// within a pixel, and its pdf would overflow what f32 can weigh.
pub const DELTA_ALPHA: f32 = 1e-3;

/// GGX with width α = roughness².
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ggx {
    /// Width: the RMS slope of the microsurface is α/√2.
    pub alpha: f32,
}

impl Ggx {
    /// The distribution of a perceptual roughness, or `None` when it is sharp enough to be a
    /// delta lobe.
    pub fn from_roughness(roughness: f32) -> Option<Ggx> {
        let alpha = roughness.clamp(0.0, 1.0).powi(2);
        (alpha >= DELTA_ALPHA).then_some(Ggx { alpha })
    }

    /// D(h): microfacet normals per unit projected area, per steradian.
    pub fn d(&self, h: Vec3) -> f32 {
        if h.z <= 0.0 {
            return 0.0;
        }
        let a2 = self.alpha * self.alpha;
        let t = h.z * h.z * (a2 - 1.0) + 1.0;
        a2 / (PI * t * t)
    }

    /// Smith's Λ(w) for GGX: G1 = 1/(1 + Λ).
    pub fn lambda(&self, w: Vec3) -> f32 {
        let cos2 = w.z * w.z;
        if cos2 == 0.0 {
            return f32::INFINITY;
        }
        let tan2 = (1.0 - cos2).max(0.0) / cos2;
        0.5 * ((1.0 + self.alpha * self.alpha * tan2).sqrt() - 1.0)
    }

    /// Masking of one direction.
    pub fn g1(&self, w: Vec3) -> f32 {
        1.0 / (1.0 + self.lambda(w))
    }

    /// Height-correlated masking-shadowing of a pair of directions (Heitz 2014, eq. 99).
    pub fn g2(&self, wo: Vec3, wi: Vec3) -> f32 {
        1.0 / (1.0 + self.lambda(wo) + self.lambda(wi))
    }

    /// Density of the normals visible from `w`, D_w(h) = G1(w)·|w·h|·D(h)/|cos θ_w|
    /// (Heitz 2018, eq. 1); what [`Ggx::sample_visible`] draws from.
    pub fn visible_d(&self, w: Vec3, h: Vec3) -> f32 {
        if w.z == 0.0 {
            return 0.0;
        }
        self.g1(w) * w.dot(h).abs() * self.d(h) / w.z.abs()
    }

    /// A microfacet normal drawn in proportion to [`Ggx::visible_d`] from `w` (taken on the
    /// upper side): the stretched view direction plus a point on a spherical cap (Dupuy &
    /// Benyoub 2023, listing 3), unstretched.
    pub fn sample_visible(&self, w: Vec3, u: Vec2) -> Vec3 {
        let w = if w.z < 0.0 { -w } else { w };
        let stretched = Vec3::new(self.alpha * w.x, self.alpha * w.y, w.z).normalize();
        let phi = TAU * u.x;
        let z = (1.0 - u.y) * (1.0 + stretched.z) - stretched.z;
        let sin = (1.0 - z * z).max(0.0).sqrt();
        let h = Vec3::new(sin * phi.cos(), sin * phi.sin(), z) + stretched;
        Vec3::new(self.alpha * h.x, self.alpha * h.y, h.z.max(1e-7)).normalize()
    }
}

/// `w` mirrored about the unit normal `n`.
pub fn reflect(w: Vec3, n: Vec3) -> Vec3 {
    2.0 * w.dot(n) * n - w
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::render::sampling::{Rng, uniform_sphere};

    /// ∫ D(h) cos θh dh = 1 over the hemisphere, and the visible normals of any direction
    /// integrate to 1 (Heitz 2014, eqs. 4 and 18): checked by uniform sphere sampling.
    #[test]
    fn distribution_and_visible_normals_are_normalised() {
        for alpha in [0.05f32, 0.2, 0.5, 1.0] {
            let ggx = Ggx { alpha };
            let wo = Vec3::new(0.6, 0.0, 0.8);
            let mut rng = Rng::new(1, 2);
            let n = 2_000_000;
            let (mut projected, mut visible) = (0.0f64, 0.0f64);
            for _ in 0..n {
                let h = uniform_sphere(rng.uniform2());
                let d = ggx.d(h);
                projected += f64::from(d * h.z.max(0.0) * 4.0 * PI);
                if wo.dot(h) > 0.0 {
                    visible += f64::from(ggx.visible_d(wo, h) * 4.0 * PI);
                }
            }
            let (projected, visible) = (projected / n as f64, visible / n as f64);
            // Sharp lobes make uniform sampling noisy: the limit scales with the peak.
            let tolerance = 0.01 + 0.002 / f64::from(alpha * alpha);
            assert!(
                (projected - 1.0).abs() < tolerance,
                "α {alpha}: ∫D cos = {projected}"
            );
            assert!(
                (visible - 1.0).abs() < tolerance,
                "α {alpha}: ∫D_wo = {visible}"
            );
        }
    }

    #[test]
    fn sharp_roughness_is_a_delta() {
        assert!(Ggx::from_roughness(0.0).is_none());
        assert!(Ggx::from_roughness(0.03).is_none());
        assert_eq!(Ggx::from_roughness(0.5).unwrap().alpha, 0.25);
    }
}
