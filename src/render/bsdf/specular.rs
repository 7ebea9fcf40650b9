//! A GGX reflection lobe: glTF's metals (Schlick's Fresnel), its dielectric specular layer
//! and its clear coat (exact dielectric Fresnel); and how much light it leaves to what lies
//! beneath it.
//!
//! Single scattering loses the energy that masking stops (up to 60 % for a white rough
//! conductor). The lobe is scaled by 1 + F_ms·(1 − E(μo))/E(μo) (Turquin 2019, "Practical
//! multiple scattering compensation for microfacet models"), with E the albedo of the lobe
//! with F = 1 and F_ms = F_avg·Ē/(1 − F_avg(1 − Ē)) the colour of light that bounced several
//! times (Kulla & Conty 2017's series with one bounce's Fresnel taken out, F_avg the
//! cosine-weighted average Fresnel, Ē the average of E). This is what Cycles' Principled BSDF
//! does: a white lobe reflects everything and keeps its single-scattering shape, and a
//! coloured one saturates as real multiple bounces would (with F_avg alone, rough copper
//! came out 6–7 % too bright in green and blue against Cycles). Kulla & Conty's (2017) reciprocal diffuse-like lobe was tried first; on Blender's
//! rough copper (0.8) it put the compensated energy into a flat glow, dimmer at the centre
//! of the sphere and brighter at its rim than Cycles (README, "Materials").
//!
//! Directions are local (normal +Z) with `wo` above the surface.

use glam::{Vec2, Vec3};

use super::albedo::{glass_table, tables};
use super::fresnel::{Fresnel, schlick_average};
use super::microfacet::{Ggx, reflect};

/// A GGX reflection lobe, or a delta mirror when it is sharp.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SpecularLobe {
    /// The distribution; `None`: a delta mirror.
    ggx: Option<Ggx>,
    /// Perceptual roughness, the tables' coordinate.
    roughness: f32,
    /// The Fresnel factor.
    fresnel: Fresnel,
    /// F_ms: the Fresnel colour of multiply scattered light.
    multiple: Vec3,
}

impl SpecularLobe {
    /// The lobe of perceptual `roughness` with Fresnel factor `fresnel`.
    pub fn new(roughness: f32, fresnel: Fresnel) -> SpecularLobe {
        SpecularLobe::with_ggx(Ggx::from_roughness(roughness), roughness, fresnel)
    }

    /// The lobe of an anisotropic distribution; it reads the isotropic albedo tables at
    /// its mean width (as Cycles does).
    pub fn anisotropic(ggx: Option<Ggx>, fresnel: Fresnel) -> SpecularLobe {
        let roughness = ggx.map_or(0.0, |g| g.mean_alpha().sqrt());
        SpecularLobe::with_ggx(ggx, roughness, fresnel)
    }

    fn with_ggx(ggx: Option<Ggx>, roughness: f32, fresnel: Fresnel) -> SpecularLobe {
        let multiple = if ggx.is_some() {
            let average = match fresnel {
                Fresnel::Schlick { f0, f90 } => schlick_average(f0, f90),
                Fresnel::Dielectric { eta, scale, offset } => {
                    offset + scale * glass_table().fresnel_average(eta)
                }
            };
            let e = tables().white_average(roughness);
            average * e / (Vec3::ONE - average * (1.0 - e)).max(Vec3::splat(1e-4))
        } else {
            Vec3::ZERO
        };
        SpecularLobe {
            ggx,
            roughness,
            fresnel,
            multiple,
        }
    }

    /// The same lobe with its anisotropy axis turned to `axis` (a unit vector of the local
    /// tangent plane).
    pub fn turned(self, axis: Vec2) -> SpecularLobe {
        SpecularLobe {
            ggx: self.ggx.map(|g| g.turned(axis)),
            ..self
        }
    }

    /// True for a sharp lobe: a mirror direction only.
    pub fn is_delta(&self) -> bool {
        self.ggx.is_none()
    }

    /// The energy compensation at `mu_o`, 1 + F_ms·(1 − E)/E, and the split-sum terms
    /// (A, B) of GGX's albedo there (E = A + B with F = 1).
    fn compensation(&self, mu_o: f32) -> (Vec3, Vec2) {
        let ab = tables().schlick(mu_o, self.roughness);
        let white = (ab.x + ab.y).max(1e-4);
        (Vec3::ONE + self.multiple * ((1.0 - white) / white), ab)
    }

    /// E(μ): the fraction of light arriving at cosine μ that the lobe reflects.
    pub fn albedo(&self, mu: f32) -> Vec3 {
        if self.ggx.is_none() {
            return self.fresnel.eval(mu);
        }
        let (scale, ab) = self.compensation(mu);
        let single = match self.fresnel {
            Fresnel::Schlick { f0, f90 } => f0 * ab.x + Vec3::splat(f90) * ab.y,
            Fresnel::Dielectric { eta, scale, offset } => {
                offset * (ab.x + ab.y) + scale * glass_table().reflection(mu, self.roughness, eta)
            }
        };
        single * scale
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

    /// The single-scattering f(wo, wi) = F·D·G2 / (4 cos θo cos θi), reciprocal; zero for a
    /// delta lobe or directions below the surface.
    pub fn eval_single(&self, wo: Vec3, wi: Vec3) -> Vec3 {
        let Some(ggx) = self.ggx else {
            return Vec3::ZERO;
        };
        if wo.z <= 0.0 || wi.z <= 0.0 {
            return Vec3::ZERO;
        }
        let h = (wo + wi).normalize();
        let f = self.fresnel.eval(wo.dot(h));
        f * (ggx.d(h) * ggx.g2(wo, wi) / (4.0 * wo.z * wi.z))
    }

    /// f(wo, wi) of the rough lobe, energy-compensated.
    pub fn eval(&self, wo: Vec3, wi: Vec3) -> Vec3 {
        let single = self.eval_single(wo, wi);
        if single == Vec3::ZERO {
            return single;
        }
        single * self.compensation(wo.z).0
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
    use crate::render::sampling::Rng;

    /// E(μo) by integrating f·cos/pdf over the lobe's own samples.
    fn integrated_albedo(lobe: &SpecularLobe, wo: Vec3, n: usize) -> Vec3 {
        let mut rng = Rng::new(11, 5);
        let mut sum = Vec3::ZERO;
        for _ in 0..n {
            if let Some(wi) = lobe.sample_visible(wo, rng.uniform2()) {
                sum += lobe.eval(wo, wi) * wi.z / lobe.pdf_visible(wo, wi);
            }
        }
        sum / n as f32
    }

    /// White furnace: a white conductor (F0 = 1) reflects everything at every roughness and
    /// angle, thanks to the compensation.
    #[test]
    fn white_rough_conductor_reflects_everything() {
        for roughness in [0.2f32, 0.5, 0.8, 1.0] {
            let lobe = SpecularLobe::new(
                roughness,
                Fresnel::Schlick {
                    f0: Vec3::ONE,
                    f90: 1.0,
                },
            );
            for mu in [0.2f32, 0.6, 1.0] {
                let wo = Vec3::new((1.0 - mu * mu).sqrt(), 0.0, mu);
                let e = integrated_albedo(&lobe, wo, 200_000);
                assert!(
                    (e.x - 1.0).abs() < 0.01,
                    "roughness {roughness}, μ {mu}: white furnace reflects {}",
                    e.x
                );
                assert!(
                    (lobe.albedo(mu).x - 1.0).abs() < 1e-5,
                    "{}",
                    lobe.albedo(mu).x
                );
            }
        }
    }

    /// The albedo the tables give is the albedo the lobe has, for both Fresnel factors.
    #[test]
    fn albedo_matches_integration() {
        let schlick = SpecularLobe::new(
            0.7,
            Fresnel::Schlick {
                f0: Vec3::new(0.04, 0.3, 0.9),
                f90: 0.8,
            },
        );
        let dielectric = SpecularLobe::new(
            0.4,
            Fresnel::Dielectric {
                eta: 1.6,
                scale: Vec3::new(1.0, 0.5, 2.0),
                offset: Vec3::new(0.0, 0.2, 0.05),
            },
        );
        for (lobe, mu) in [
            (schlick, 0.3f32),
            (schlick, 0.9),
            (dielectric, 0.2),
            (dielectric, 0.8),
        ] {
            let wo = Vec3::new((1.0 - mu * mu).sqrt(), 0.0, mu);
            let integrated = integrated_albedo(&lobe, wo, 400_000);
            let table = lobe.albedo(mu);
            assert!(
                (integrated - table).abs().max_element() < 0.01,
                "μ {mu}: integrated {integrated} table {table}"
            );
        }
    }

    /// Single scattering is reciprocal.
    #[test]
    fn single_scattering_is_reciprocal() {
        let lobe = SpecularLobe::new(
            0.6,
            Fresnel::Schlick {
                f0: Vec3::new(0.9, 0.5, 0.2),
                f90: 1.0,
            },
        );
        let a = Vec3::new(0.3, 0.2, 0.9).normalize();
        let b = Vec3::new(-0.8, 0.1, 0.3).normalize();
        let (fab, fba) = (lobe.eval_single(a, b), lobe.eval_single(b, a));
        assert!(
            (fab - fba).abs().max_element() < 1e-5 * fab.max_element(),
            "{fab} {fba}"
        );
    }
}
