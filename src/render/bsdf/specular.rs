//! A GGX reflection lobe with Schlick's Fresnel: glTF's dielectric specular layer, its
//! metals and its clear coat. Single scattering is compensated for the energy GGX loses to
//! masking by Kulla & Conty's (2017) multiple-scattering lobe, which is reciprocal and makes
//! a white lobe reflect exactly everything; and the lobe says how much light it leaves to
//! what lies beneath it.
//!
//! Directions are local (normal +Z) with `wo` above the surface.

use std::f32::consts::FRAC_1_PI;

use glam::{Vec2, Vec3};

use super::albedo::tables;
use super::fresnel::{fresnel_schlick, schlick_average};
use super::microfacet::{Ggx, reflect};

/// Below this, 1 − Ē is treated as zero: nothing gets past the lobe.
const OPAQUE: f32 = 1e-5;

/// A Schlick-Fresnel GGX lobe, or a delta mirror when it is sharp.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SpecularLobe {
    /// The distribution; `None`: a delta mirror.
    ggx: Option<Ggx>,
    /// Perceptual roughness, the tables' coordinate.
    roughness: f32,
    /// Reflectance at normal incidence.
    f0: Vec3,
    /// Reflectance at grazing incidence.
    f90: f32,
    /// Kulla–Conty's multiple-scattering factor F_avg²·Ē₁ / (1 − F_avg(1 − Ē₁)), divided by
    /// π(1 − Ē₁): f_ms = this·(1 − E₁(μo))(1 − E₁(μi)). E₁ is the albedo with F = 1.
    multiple: Vec3,
    /// Ē₁: the cosine-weighted average albedo of the lobe with F = 1.
    average_white: f32,
}

impl SpecularLobe {
    /// The lobe of perceptual `roughness` with Fresnel F0 → F90.
    pub fn new(roughness: f32, f0: Vec3, f90: f32) -> SpecularLobe {
        let ggx = Ggx::from_roughness(roughness);
        let fresnel_average = schlick_average(f0, f90);
        let Some(ggx) = ggx else {
            return SpecularLobe {
                ggx,
                roughness,
                f0,
                f90,
                multiple: Vec3::ZERO,
                average_white: 1.0,
            };
        };
        let ab = tables().schlick_average(roughness);
        let average_white = ab.x + ab.y;
        let loss = 1.0 - average_white;
        let multiple = if loss > OPAQUE {
            let factor = fresnel_average * fresnel_average * average_white
                / (Vec3::ONE - fresnel_average * loss);
            factor * FRAC_1_PI / loss
        } else {
            Vec3::ZERO
        };
        SpecularLobe {
            ggx: Some(ggx),
            roughness,
            f0,
            f90,
            multiple,
            average_white,
        }
    }

    /// True for a sharp lobe: a mirror direction only.
    pub fn is_delta(&self) -> bool {
        self.ggx.is_none()
    }

    /// E(μ): the fraction of light arriving at cosine μ that the lobe reflects.
    pub fn albedo(&self, mu: f32) -> Vec3 {
        if self.ggx.is_none() {
            return fresnel_schlick(self.f0, self.f90, mu);
        }
        let ab = tables().schlick(mu, self.roughness);
        let multiple = self.multiple * std::f32::consts::PI * (1.0 - ab.x - ab.y);
        self.f0 * ab.x + Vec3::splat(self.f90) * ab.y + multiple * (1.0 - self.average_white)
    }

    /// The part of the lobe's albedo that its visible-normal sampling covers (single
    /// scattering); the rest is drawn like a diffuse lobe.
    pub fn single_albedo(&self, mu: f32) -> Vec3 {
        if self.ggx.is_none() {
            return self.albedo(mu);
        }
        let ab = tables().schlick(mu, self.roughness);
        self.f0 * ab.x + Vec3::splat(self.f90) * ab.y
    }

    /// What the lobe lets through to a layer beneath it, as a factor on that layer's BSDF:
    /// 1 − E(μo), the light the layer does not reflect towards the viewer. This is how
    /// Cycles' Principled BSDF v2 weighs its layers (its "closure layering weight"), so it
    /// is what Blender users see: over a white base the two reflect exactly everything.
    /// Kulla & Conty's reciprocal form (1 − E(μo))(1 − E(μi))/(1 − Ē) was tried first; it
    /// made Blender's default material 1–1.3 % brighter than Cycles (README, "Materials").
    pub fn transmitted(&self, mu_o: f32) -> Vec3 {
        (Vec3::ONE - self.albedo(mu_o)).max(Vec3::ZERO)
    }

    /// f(wo, wi) of the rough lobe, single and multiple scattering; zero for a delta lobe or
    /// directions below the surface.
    pub fn eval(&self, wo: Vec3, wi: Vec3) -> Vec3 {
        let Some(ggx) = self.ggx else {
            return Vec3::ZERO;
        };
        if wo.z <= 0.0 || wi.z <= 0.0 {
            return Vec3::ZERO;
        }
        let h = (wo + wi).normalize();
        let f = fresnel_schlick(self.f0, self.f90, wo.dot(h));
        let single = f * (ggx.d(h) * ggx.g2(wo, wi) / (4.0 * wo.z * wi.z));
        let t = tables();
        let white = |mu: f32| {
            let ab = t.schlick(mu, self.roughness);
            1.0 - ab.x - ab.y
        };
        single + self.multiple * (white(wo.z) * white(wi.z))
    }

    /// Solid-angle density with which [`SpecularLobe::sample_visible`] gives `wi`.
    pub fn pdf_visible(&self, wo: Vec3, wi: Vec3) -> f32 {
        let Some(ggx) = self.ggx else {
            return 0.0;
        };
        if wi.z <= 0.0 {
            return 0.0;
        }
        let h = (wo + wi).normalize();
        ggx.visible_d(wo, h) / (4.0 * wo.dot(h))
    }

    /// A direction reflected about a visible normal (Heitz 2018); `None` if it points below
    /// the surface. The mirror direction for a delta lobe.
    pub fn sample_visible(&self, wo: Vec3, u: Vec2) -> Option<Vec3> {
        let wi = match self.ggx {
            Some(ggx) => reflect(wo, ggx.sample_visible(wo, u)),
            None => Vec3::new(-wo.x, -wo.y, wo.z),
        };
        (wi.z > 0.0).then_some(wi)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::render::sampling::{Rng, cosine_hemisphere};

    /// E(μo) by integrating f·cos over the hemisphere with cosine sampling.
    fn integrated_albedo(lobe: &SpecularLobe, wo: Vec3, n: usize) -> Vec3 {
        let mut rng = Rng::new(7, 3);
        let mut sum = Vec3::ZERO;
        for _ in 0..n {
            let wi = cosine_hemisphere(rng.uniform2());
            sum += lobe.eval(wo, wi) * std::f32::consts::PI;
        }
        sum / n as f32
    }

    /// White furnace: a white conductor (F0 = 1) reflects everything at every roughness and
    /// angle, thanks to the multiple-scattering lobe.
    #[test]
    fn white_rough_conductor_reflects_everything() {
        for roughness in [0.2f32, 0.5, 0.8, 1.0] {
            let lobe = SpecularLobe::new(roughness, Vec3::ONE, 1.0);
            for mu in [0.2f32, 0.6, 1.0] {
                let wo = Vec3::new((1.0 - mu * mu).sqrt(), 0.0, mu);
                // Sharp lobes are noisy under cosine sampling: use the lobe's own sampling.
                let mut rng = Rng::new(11, 5);
                let n = 200_000;
                let mut sum = Vec3::ZERO;
                for _ in 0..n {
                    let wi = if rng.uniform() < 0.5 {
                        lobe.sample_visible(wo, rng.uniform2())
                    } else {
                        Some(cosine_hemisphere(rng.uniform2()))
                    };
                    if let Some(wi) = wi {
                        let pdf =
                            0.5 * lobe.pdf_visible(wo, wi) + 0.5 * wi.z / std::f32::consts::PI;
                        sum += lobe.eval(wo, wi) * wi.z / pdf;
                    }
                }
                let e = sum / n as f32;
                assert!(
                    (e.x - 1.0).abs() < 0.02,
                    "roughness {roughness}, μ {mu}: white furnace reflects {}",
                    e.x
                );
                assert!(
                    (lobe.albedo(mu).x - 1.0).abs() < 0.01,
                    "{}",
                    lobe.albedo(mu).x
                );
            }
        }
    }

    /// The albedo the tables give is the albedo the lobe has.
    #[test]
    fn albedo_matches_integration() {
        let lobe = SpecularLobe::new(0.7, Vec3::new(0.04, 0.3, 0.9), 0.8);
        for mu in [0.3f32, 0.9] {
            let wo = Vec3::new((1.0 - mu * mu).sqrt(), 0.0, mu);
            let integrated = integrated_albedo(&lobe, wo, 400_000);
            let table = lobe.albedo(mu);
            assert!(
                (integrated - table).abs().max_element() < 0.01,
                "μ {mu}: integrated {integrated} table {table}"
            );
        }
    }

    /// The multiple-scattering lobe is reciprocal, as single scattering is.
    #[test]
    fn lobe_is_reciprocal() {
        let lobe = SpecularLobe::new(0.6, Vec3::new(0.9, 0.5, 0.2), 1.0);
        let a = Vec3::new(0.3, 0.2, 0.9).normalize();
        let b = Vec3::new(-0.8, 0.1, 0.3).normalize();
        let (fab, fba) = (lobe.eval(a, b), lobe.eval(b, a));
        assert!(
            (fab - fba).abs().max_element() < 1e-5 * fab.max_element(),
            "{fab} {fba}"
        );
    }
}
