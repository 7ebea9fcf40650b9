//! Sheen: the back-scattering of fibres on cloth and velvet, in the two models files are
//! authored against ([`crate::scene::SheenModel`]): `KHR_materials_sheen`'s "Charlie"
//! distribution (Estevez & Kulla 2017, "Production friendly microfacet sheen BRDF") with
//! Neubelt & Pettineo's (2013) visibility term, and Cycles' [`Microfiber`] layer.

use std::f32::consts::{FRAC_1_PI, TAU};

use glam::{Vec2, Vec3};

use super::albedo::tables;
use super::sheen_table;
use crate::render::sampling::cosine_hemisphere;
use crate::scene::SheenModel;

/// Smallest sheen α (roughness 0.07, as Filament clamps it): the distribution's exponent
/// 1/α stays finite.
pub const SHEEN_MIN_ALPHA: f32 = 0.0049;

/// The white sheen BRDF at width α (= sheen roughness²), for `wo` and `wi` above the
/// surface: D(h)·V with D(h) = (2 + 1/α)·sin(θh)^(1/α) / 2π and
/// V = 1 / (4(μi + μo − μi·μo)).
pub fn charlie_brdf(alpha: f32, wo: Vec3, wi: Vec3) -> f32 {
    if wo.z <= 0.0 || wi.z <= 0.0 {
        return 0.0;
    }
    let h = (wo + wi).normalize();
    let inv = 1.0 / alpha.max(SHEEN_MIN_ALPHA);
    let sin2 = (1.0 - h.z * h.z).max(0.0);
    let d = (2.0 + inv) * sin2.powf(0.5 * inv) / TAU;
    let v = 1.0 / (4.0 * (wi.z + wo.z - wi.z * wo.z));
    d * v
}

/// A sheen layer of one material: its colour, roughness and model.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SheenLayer {
    pub colour: Vec3,
    pub roughness: f32,
    pub model: SheenModel,
}

impl SheenLayer {
    /// True when the sheen lies over the clear coat (Cycles' Principled BSDF layers it on
    /// top, `svm/closure.h`); glTF puts the coat over the sheen.
    pub fn over_coat(&self) -> bool {
        self.model == SheenModel::Microfiber
    }

    /// The microfibre lobe seen from `wo` (sheen frame), for the microfibre model.
    pub fn microfiber(&self, wo: Vec3) -> Option<Microfiber> {
        match self.model {
            SheenModel::Microfiber => Microfiber::at(self.roughness, wo),
            SheenModel::Charlie => None,
        }
    }

    /// Albedo of the white sheen seen from `wo` (sheen frame).
    pub fn white_albedo(&self, wo: Vec3) -> f32 {
        match self.model {
            SheenModel::Charlie => tables().sheen(wo.z.max(0.0), self.roughness),
            SheenModel::Microfiber => self.microfiber(wo).map_or(0.0, |m| m.reflectance()),
        }
    }

    /// What the sheen leaves to the layers beneath it: 1 − max(colour)·E(μo), glTF's
    /// albedo scaling and Cycles' `closure_layering_weight` alike.
    pub fn transmitted(&self, wo: Vec3) -> Vec3 {
        Vec3::splat((1.0 - self.colour.max_element() * self.white_albedo(wo)).max(0.0))
    }

    /// f·cos θi in the sheen frame, for `wo` and `wi` above it.
    pub fn eval(&self, wo: Vec3, wi: Vec3) -> Vec3 {
        let white = match self.model {
            SheenModel::Charlie => {
                charlie_brdf(self.roughness * self.roughness, wo, wi) * wi.z.max(0.0)
            }
            SheenModel::Microfiber => self.microfiber(wo).map_or(0.0, |m| m.eval(wi)),
        };
        self.colour * white
    }
}

/// Cycles' sheen (Blender's Principled BSDF): the fibre layer of Zeltner, Burley & Chiang
/// 2022, "Practical Multiple-Scattering Sheen Using Linearly Transformed Cosines", as a
/// linearly transformed cosine (Heitz et al. 2016) whose inverse matrix
/// [[a, 0, b], [0, a, 0], [0, 0, 1]] and albedo R depend on (μo, roughness) through
/// the table `tools/dev/fit_sheen_ltc.py` fits to a simulation of the layer. The lobe is
/// written in a frame whose x axis points towards `wo`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Microfiber {
    a: f32,
    b: f32,
    reflectance: f32,
    /// cos φ and sin φ of `wo` about the normal.
    azimuth: (f32, f32),
}

impl Microfiber {
    /// The lobe seen from `wo` (local frame, above the surface); `None` where the layer
    /// reflects nothing, as Cycles drops the closure there.
    pub fn at(roughness: f32, wo: Vec3) -> Option<Microfiber> {
        let mu = wo.z.clamp(0.0, 1.0);
        let roughness = roughness.clamp(0.0, 1.0);
        let a = table_lookup(&sheen_table::A, mu, roughness);
        let reflectance = table_lookup(&sheen_table::REFLECTANCE, mu, roughness);
        if a.abs() < 1e-5 || reflectance < 1e-5 {
            return None;
        }
        let azimuth = Vec2::new(wo.x, wo.y)
            .try_normalize()
            .map_or((1.0, 0.0), |d| (d.x, d.y));
        Some(Microfiber {
            a,
            b: table_lookup(&sheen_table::B, mu, roughness),
            reflectance,
            azimuth,
        })
    }

    /// The layer's directional albedo R(μo): the white lobe's weight and what it takes
    /// from the layers beneath.
    pub fn reflectance(&self) -> f32 {
        self.reflectance
    }

    /// Solid-angle density of `wi` (local frame): the transformed cosine
    /// D(ω) = max(z, 0)·a² / (π·|M⁻¹ω|⁴).
    pub fn pdf(&self, wi: Vec3) -> f32 {
        let (c, s) = self.azimuth;
        let (x, y) = (c * wi.x + s * wi.y, c * wi.y - s * wi.x);
        let z = wi.z.max(0.0);
        let len2 = (self.a * x + self.b * z).powi(2) + (self.a * y).powi(2) + z * z;
        if len2 <= 0.0 {
            return 0.0;
        }
        z * self.a * self.a * FRAC_1_PI / (len2 * len2)
    }

    /// f·cos θi of the white lobe: R·D(wi).
    pub fn eval(&self, wi: Vec3) -> f32 {
        self.reflectance * self.pdf(wi)
    }

    /// A direction with density [`Microfiber::pdf`]: a cosine-distributed direction mapped
    /// by M = (M⁻¹)⁻¹; may fall below the surface, where the lobe is zero.
    pub fn sample(&self, u: Vec2) -> Vec3 {
        let c = cosine_hemisphere(u);
        let local = Vec3::new(c.x - self.b * c.z, c.y, self.a * c.z).normalize();
        let (cos, sin) = self.azimuth;
        Vec3::new(
            cos * local.x - sin * local.y,
            sin * local.x + cos * local.y,
            local.z,
        )
    }
}

/// Linear interpolation in a table of [`sheen_table::SIZE`]² entries, rows by roughness,
/// columns by μ, both at k/(SIZE − 1).
fn table_lookup(
    table: &[[f32; sheen_table::SIZE]; sheen_table::SIZE],
    mu: f32,
    roughness: f32,
) -> f32 {
    let last = (sheen_table::SIZE - 1) as f32;
    let position = |x: f32| {
        let x = x.clamp(0.0, 1.0) * last;
        let i = (x.floor() as usize).min(sheen_table::SIZE - 2);
        (i, x - i as f32)
    };
    let (i, s) = position(mu);
    let (j, t) = position(roughness);
    let row = |j: usize| table[j][i] * (1.0 - s) + table[j][i + 1] * s;
    row(j) * (1.0 - t) + row(j + 1) * t
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sheen_is_reciprocal_and_peaks_at_grazing_half_vectors() {
        let a = Vec3::new(0.3, 0.1, 0.9).normalize();
        let b = Vec3::new(-0.7, 0.2, 0.4).normalize();
        assert!((charlie_brdf(0.25, a, b) - charlie_brdf(0.25, b, a)).abs() < 1e-6);
        // Retro-reflection at grazing angles (h near the tangent plane) beats the mirror
        // configuration at normal incidence.
        let grazing = Vec3::new(0.99, 0.0, 0.14).normalize();
        assert!(charlie_brdf(0.25, grazing, grazing) > charlie_brdf(0.25, Vec3::Z, Vec3::Z));
        assert_eq!(charlie_brdf(0.25, a, -b), 0.0);
    }

    /// The microfibre lobe's density integrates to at most 1 over the hemisphere (what the
    /// transformed cosine puts below the horizon is lost) and its albedo is a fraction.
    #[test]
    fn microfiber_density_is_normalised_above_the_surface() {
        const N: usize = 400;
        for roughness in [0.2f32, 0.5, 0.8] {
            for mu in [0.2f32, 0.5, 0.9] {
                let wo = Vec3::new((1.0 - mu * mu).sqrt(), 0.0, mu);
                let lobe = Microfiber::at(roughness, wo).expect("a lobe");
                assert!(lobe.reflectance() > 0.0 && lobe.reflectance() < 1.0);
                // Midpoint rule over (cos θ, φ): dω = d(cos θ) dφ.
                let mut total = 0.0f64;
                for i in 0..N {
                    let z = (i as f32 + 0.5) / N as f32;
                    let r = (1.0 - z * z).sqrt();
                    for j in 0..N {
                        let phi = (j as f32 + 0.5) / N as f32 * TAU;
                        let wi = Vec3::new(r * phi.cos(), r * phi.sin(), z);
                        total += f64::from(lobe.pdf(wi));
                    }
                }
                total *= f64::from(TAU) / (N * N) as f64;
                assert!(
                    total <= 1.0 + 2e-3 && total > 0.5,
                    "roughness {roughness}, μo {mu}: ∫D = {total}"
                );
            }
        }
    }
}
