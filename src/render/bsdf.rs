//! The scattering models: Lambertian, ideal mirror and ideal dielectric.
//!
//! Directions are world-space unit vectors pointing away from the surface. `n` is the
//! shading normal turned to the side `wo` lies on (see [`crate::render::integrator`]).

use glam::{Vec2, Vec3};
use std::f32::consts::FRAC_1_PI;

use super::sampling::{Frame, cosine_hemisphere};
use crate::scene::MaterialKind;

/// A material's scattering model, with the operations the integrator needs: evaluate,
/// give the pdf of, and sample directions.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Bsdf(pub MaterialKind);

/// A direction drawn from a BSDF.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BsdfSample {
    /// Incident direction (towards the next vertex).
    pub wi: Vec3,
    /// f·|cos θi| / pdf: what the path throughput is multiplied by.
    pub weight: Vec3,
    /// Solid-angle density of `wi`; for delta lobes the discrete probability of the lobe.
    pub pdf: f32,
    /// True for a delta lobe, which light sampling can never produce.
    pub is_delta: bool,
    /// True when `wi` crosses the surface.
    pub is_transmission: bool,
    /// The factor radiance is scaled by at a refraction, (η_i/η_t)²; 1 otherwise.
    pub eta_scale: f32,
}

impl Bsdf {
    /// True when every lobe is a delta (light sampling is useless there).
    pub fn is_delta(&self) -> bool {
        !matches!(self.0, MaterialKind::Diffuse { .. })
    }

    /// f(wo, wi) for non-delta lobes; zero for delta lobes and for `wi` below the surface.
    pub fn eval(&self, n: Vec3, _wo: Vec3, wi: Vec3) -> Vec3 {
        match self.0 {
            MaterialKind::Diffuse { albedo } if n.dot(wi) > 0.0 => albedo * FRAC_1_PI,
            _ => Vec3::ZERO,
        }
    }

    /// Solid-angle pdf with which [`Bsdf::sample`] picks `wi`; zero for delta lobes.
    pub fn pdf(&self, n: Vec3, _wo: Vec3, wi: Vec3) -> f32 {
        match self.0 {
            MaterialKind::Diffuse { .. } => n.dot(wi).max(0.0) * FRAC_1_PI,
            _ => 0.0,
        }
    }

    /// Draws an incident direction. `front` says whether `wo` is on the side the mesh's
    /// winding calls outside, which for glass decides whether the ray enters or leaves.
    pub fn sample(
        &self,
        n: Vec3,
        wo: Vec3,
        front: bool,
        u: Vec2,
        u_lobe: f32,
    ) -> Option<BsdfSample> {
        match self.0 {
            MaterialKind::Diffuse { albedo } => {
                let wi = Frame::from_normal(n).to_world(cosine_hemisphere(u));
                let pdf = n.dot(wi) * FRAC_1_PI;
                (pdf > 0.0).then_some(BsdfSample {
                    wi,
                    weight: albedo,
                    pdf,
                    is_delta: false,
                    is_transmission: false,
                    eta_scale: 1.0,
                })
            }
            MaterialKind::Mirror { reflectance } => {
                Some(delta_sample(reflect(wo, n), reflectance, 1.0, false, 1.0))
            }
            MaterialKind::Glass { ior, tint } => {
                // η = η_i / η_t for light arriving along wi, which is where wo's side is.
                let eta = if front { 1.0 / ior } else { ior };
                let cos_o = n.dot(wo);
                let f = fresnel_dielectric(cos_o, eta);
                if u_lobe < f {
                    return Some(delta_sample(reflect(wo, n), Vec3::ONE, f, false, 1.0));
                }
                let wi = refract(wo, n, eta)?;
                // Radiance is compressed or spread across the interface: scale by (η_i/η_t)²
                // with η_i on wo's side (Veach 1997, §5.2; pbrt-v3 §8.2).
                let scale = eta * eta;
                Some(delta_sample(wi, tint * scale, 1.0 - f, true, scale))
            }
        }
    }
}

fn delta_sample(
    wi: Vec3,
    weight: Vec3,
    pdf: f32,
    is_transmission: bool,
    eta_scale: f32,
) -> BsdfSample {
    BsdfSample {
        wi,
        weight,
        pdf,
        is_delta: true,
        is_transmission,
        eta_scale,
    }
}

/// `wo` mirrored about `n`.
pub fn reflect(wo: Vec3, n: Vec3) -> Vec3 {
    2.0 * wo.dot(n) * n - wo
}

/// The refracted direction of `wo` through a surface with normal `n` on `wo`'s side and
/// relative index `eta = η_wo / η_other`; `None` on total internal reflection.
pub fn refract(wo: Vec3, n: Vec3, eta: f32) -> Option<Vec3> {
    let cos_i = wo.dot(n);
    let sin2_t = eta * eta * (1.0 - cos_i * cos_i).max(0.0);
    if sin2_t >= 1.0 {
        return None;
    }
    let cos_t = (1.0 - sin2_t).sqrt();
    Some((-eta * wo + (eta * cos_i - cos_t) * n).normalize())
}

/// Unpolarised Fresnel reflectance of a dielectric interface, for a ray on the side of
/// relative index `eta = η_i / η_t` at cosine `cos_i` ≥ 0 (Hecht, Optics, §4.6).
pub fn fresnel_dielectric(cos_i: f32, eta: f32) -> f32 {
    let cos_i = cos_i.clamp(0.0, 1.0);
    let sin2_t = eta * eta * (1.0 - cos_i * cos_i);
    if sin2_t >= 1.0 {
        return 1.0;
    }
    let cos_t = (1.0 - sin2_t).sqrt();
    let r_s = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
    let r_p = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
    0.5 * (r_s * r_s + r_p * r_p)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fresnel_matches_known_values() {
        // Normal incidence: ((n1 - n2)/(n1 + n2))², 0.04 for glass of index 1.5.
        assert!((fresnel_dielectric(1.0, 1.0 / 1.5) - 0.04).abs() < 1e-6);
        assert!((fresnel_dielectric(1.0, 1.5) - 0.04).abs() < 1e-6);
        // Brewster's angle: p-polarised reflectance vanishes, so F = r_s²/2.
        let theta_b = 1.5f32.atan();
        let f = fresnel_dielectric(theta_b.cos(), 1.0 / 1.5);
        let rs = ((theta_b.cos() - 1.5 * (1.0 - (theta_b.sin() / 1.5).powi(2)).sqrt())
            / (theta_b.cos() + 1.5 * (1.0 - (theta_b.sin() / 1.5).powi(2)).sqrt()))
        .powi(2);
        assert!((f - 0.5 * rs).abs() < 1e-5, "{f} vs {}", 0.5 * rs);
        // Beyond the critical angle inside glass: total internal reflection.
        assert_eq!(fresnel_dielectric(0.5, 1.5), 1.0);
        assert_eq!(fresnel_dielectric(0.0, 1.0 / 1.5), 1.0);
    }

    #[test]
    fn refraction_obeys_snell() {
        let n = Vec3::Z;
        let wo = Vec3::new(0.6, 0.0, 0.8);
        let wi = refract(wo, n, 1.0 / 1.5).unwrap();
        let sin_i = 0.6;
        let sin_t = (wi.x * wi.x + wi.y * wi.y).sqrt();
        assert!((sin_i - 1.5 * sin_t).abs() < 1e-5);
        assert!(wi.z < 0.0 && wi.x < 0.0);
        assert!(refract(Vec3::new(0.9, 0.0, 0.1f32.sqrt()).normalize(), n, 1.5).is_none());
    }

    #[test]
    fn glass_lobes_are_picked_with_fresnel_probability() {
        let glass = Bsdf(MaterialKind::Glass {
            ior: 1.5,
            tint: Vec3::ONE,
        });
        let wo = Vec3::new(0.0, 0.6, 0.8);
        let f = fresnel_dielectric(0.8, 1.0 / 1.5);
        let refl = glass
            .sample(Vec3::Z, wo, true, Vec2::ZERO, f * 0.99)
            .unwrap();
        assert!(!refl.is_transmission && (refl.pdf - f).abs() < 1e-6 && refl.weight == Vec3::ONE);
        let trans = glass
            .sample(Vec3::Z, wo, true, Vec2::ZERO, f * 1.01)
            .unwrap();
        assert!(trans.is_transmission && trans.wi.z < 0.0);
        assert!((trans.weight.x - 1.0 / 2.25).abs() < 1e-6);
    }
}
