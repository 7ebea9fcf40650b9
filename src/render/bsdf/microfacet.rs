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

/// GGX with widths αx and αy along an axis of the tangent plane (α = roughness² when
/// isotropic). Anisotropic GGX: Heitz 2014, §5.4; its visible normals are drawn by the
/// same stretch (Heitz 2018, §3).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ggx {
    /// Width along the axis: the RMS slope that way is αx/√2.
    pub alpha_x: f32,
    /// Width across the axis.
    pub alpha_y: f32,
    /// The axis in the local frame, as (cos, sin) of its angle from local x.
    pub axis: Vec2,
}

impl Ggx {
    /// The isotropic distribution of a perceptual roughness, or `None` when it is sharp
    /// enough to be a delta lobe.
    pub fn from_roughness(roughness: f32) -> Option<Ggx> {
        let alpha = roughness.clamp(0.0, 1.0).powi(2);
        (alpha >= DELTA_ALPHA).then(|| Ggx::isotropic(alpha))
    }

    /// Width α in every direction.
    pub fn isotropic(alpha: f32) -> Ggx {
        Ggx {
            alpha_x: alpha,
            alpha_y: alpha,
            axis: Vec2::X,
        }
    }

    /// Widths `alpha_x` along local x and `alpha_y` along local y, or `None` when both are
    /// sharp enough for a delta lobe; a sharp one beside a rough one is held at
    /// [`DELTA_ALPHA`].
    pub fn anisotropic(alpha_x: f32, alpha_y: f32) -> Option<Ggx> {
        (alpha_x.max(alpha_y) >= DELTA_ALPHA).then(|| Ggx {
            alpha_x: alpha_x.clamp(DELTA_ALPHA, 1.0),
            alpha_y: alpha_y.clamp(DELTA_ALPHA, 1.0),
            axis: Vec2::X,
        })
    }

    /// The same distribution with its x axis turned to `axis` (a unit vector of the local
    /// tangent plane).
    pub fn turned(self, axis: Vec2) -> Ggx {
        Ggx { axis, ..self }
    }

    /// The isotropic width with the same area of slopes, √(αx·αy): what tables of
    /// isotropic GGX are read at (as Cycles reads its albedo tables).
    pub fn mean_alpha(&self) -> f32 {
        (self.alpha_x * self.alpha_y).sqrt()
    }

    /// `w` in the frame whose x is the axis.
    fn aligned(&self, w: Vec3) -> Vec3 {
        let (c, s) = (self.axis.x, self.axis.y);
        Vec3::new(c * w.x + s * w.y, c * w.y - s * w.x, w.z)
    }

    /// `w` from the axis' frame back to the local frame.
    fn unaligned(&self, w: Vec3) -> Vec3 {
        let (c, s) = (self.axis.x, self.axis.y);
        Vec3::new(c * w.x - s * w.y, s * w.x + c * w.y, w.z)
    }

    /// D(h): microfacet normals per unit projected area, per steradian,
    /// 1/(π αx αy (hx²/αx² + hy²/αy² + hz²)²).
    pub fn d(&self, h: Vec3) -> f32 {
        if h.z <= 0.0 {
            return 0.0;
        }
        let h = self.aligned(h);
        let (x, y) = (h.x / self.alpha_x, h.y / self.alpha_y);
        let t = x * x + y * y + h.z * h.z;
        1.0 / (PI * self.alpha_x * self.alpha_y * t * t)
    }

    /// Smith's Λ(w) for GGX: G1 = 1/(1 + Λ), with α² tan²θ taken along w's azimuth,
    /// (αx² wx² + αy² wy²)/wz².
    pub fn lambda(&self, w: Vec3) -> f32 {
        let cos2 = w.z * w.z;
        if cos2 == 0.0 {
            return f32::INFINITY;
        }
        let w = self.aligned(w);
        let (x, y) = (self.alpha_x * w.x, self.alpha_y * w.y);
        0.5 * ((1.0 + (x * x + y * y) / cos2).sqrt() - 1.0)
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
        let w = self.aligned(if w.z < 0.0 { -w } else { w });
        let stretched = Vec3::new(self.alpha_x * w.x, self.alpha_y * w.y, w.z).normalize();
        let phi = TAU * u.x;
        let z = (1.0 - u.y) * (1.0 + stretched.z) - stretched.z;
        let sin = (1.0 - z * z).max(0.0).sqrt();
        let h = Vec3::new(sin * phi.cos(), sin * phi.sin(), z) + stretched;
        let h = Vec3::new(self.alpha_x * h.x, self.alpha_y * h.y, h.z.max(1e-7)).normalize();
        self.unaligned(h)
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
        let turned = Vec2::new(0.6, 0.8);
        let cases = [0.05f32, 0.2, 0.5, 1.0]
            .map(Ggx::isotropic)
            .into_iter()
            .chain([Ggx::anisotropic(0.1, 0.5).unwrap().turned(turned)]);
        for ggx in cases {
            let alpha = ggx.alpha_x.min(ggx.alpha_y);
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
                "{ggx:?}: ∫D cos = {projected}"
            );
            assert!(
                (visible - 1.0).abs() < tolerance,
                "{ggx:?}: ∫D_wo = {visible}"
            );
        }
    }

    #[test]
    fn sharp_roughness_is_a_delta() {
        assert!(Ggx::from_roughness(0.0).is_none());
        assert!(Ggx::from_roughness(0.03).is_none());
        assert_eq!(Ggx::from_roughness(0.5).unwrap().alpha_x, 0.25);
        assert!(Ggx::anisotropic(1e-4, 2e-4).is_none());
        assert_eq!(Ggx::anisotropic(1e-4, 0.3).unwrap().alpha_x, DELTA_ALPHA);
    }

    /// Turning the axis turns the distribution: D of a turned lobe at a turned normal is
    /// D of the unturned one, and an isotropic lobe is the same whatever its axis.
    #[test]
    fn turning_the_axis_turns_the_distribution() {
        let ggx = Ggx::anisotropic(0.1, 0.6).unwrap();
        let angle = 0.7f32;
        let turned = ggx.turned(Vec2::new(angle.cos(), angle.sin()));
        let h = Vec3::new(0.3, 0.1, 0.9).normalize();
        let rotated = Vec3::new(
            h.x * angle.cos() - h.y * angle.sin(),
            h.x * angle.sin() + h.y * angle.cos(),
            h.z,
        );
        assert!((turned.d(rotated) - ggx.d(h)).abs() < 1e-4 * ggx.d(h));
        assert!((turned.lambda(rotated) - ggx.lambda(h)).abs() < 1e-5);
        let iso = Ggx::isotropic(0.3);
        assert!((iso.turned(Vec2::new(0.6, 0.8)).d(h) - iso.d(h)).abs() < 1e-5);
        // Wider along x: a normal tilted along x is likelier than one tilted along y.
        let (along, across) = (Vec3::new(0.3, 0.0, 1.0), Vec3::new(0.0, 0.3, 1.0));
        let wide = Ggx::anisotropic(0.5, 0.1).unwrap();
        assert!(wide.d(along.normalize()) > wide.d(across.normalize()));
    }
}
