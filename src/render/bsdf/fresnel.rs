//! How much light an interface reflects: exact for dielectrics, Schlick's approximation for
//! the glTF specular layer and for conductors; and Snell's law.

use glam::Vec3;

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

/// Schlick's (1994) approximation F0 + (F90 − F0)(1 − cos)⁵, as glTF 2.0 Appendix B uses for
/// both its dielectric layer and its metals. With F90 = 1 it is also Cycles' metal Fresnel
/// with a white "specular tint" (the F82 model then adds nothing).
pub fn fresnel_schlick(f0: Vec3, f90: f32, cos: f32) -> Vec3 {
    f0 + (Vec3::splat(f90) - f0) * schlick_weight(cos)
}

/// (1 − cos)⁵.
pub fn schlick_weight(cos: f32) -> f32 {
    (1.0 - cos.clamp(0.0, 1.0)).powi(5)
}

/// The hemispherical average 2∫F(μ)μ dμ of Schlick's Fresnel: F0 + (F90 − F0)/21.
pub fn schlick_average(f0: Vec3, f90: f32) -> Vec3 {
    f0 + (Vec3::splat(f90) - f0) / 21.0
}

/// The Fresnel factor of a reflection lobe.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Fresnel {
    /// Schlick's F0 → F90: conductors (glTF's metal, Cycles' F82 model with a white tint).
    Schlick {
        /// Reflectance at normal incidence.
        f0: Vec3,
        /// Reflectance at grazing incidence.
        f90: f32,
    },
    /// A dielectric of relative index `eta` (exact Fresnel F_η), remapped per channel to
    /// offset + scale·F_η: the glTF specular layer and the clear coat. Cycles' Principled
    /// BSDF uses the exact Fresnel for both; with glTF's Schlick approximation the
    /// highlights of Blender's plastics were 3 % weaker than Cycles' (README, "Materials").
    Dielectric {
        /// η of the material over the outside (≥ 1).
        eta: f32,
        /// Scale of the curve.
        scale: Vec3,
        /// Added to the scaled curve.
        offset: Vec3,
    },
}

impl Fresnel {
    /// F at the cosine between the direction and the microfacet normal.
    pub fn eval(&self, cos: f32) -> Vec3 {
        match *self {
            Fresnel::Schlick { f0, f90 } => fresnel_schlick(f0, f90, cos),
            Fresnel::Dielectric { eta, scale, offset } => {
                offset + scale * fresnel_dielectric(cos, 1.0 / eta)
            }
        }
    }
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::f0_of_ior;

    #[test]
    fn fresnel_matches_known_values() {
        // Normal incidence: ((n1 - n2)/(n1 + n2))², 0.04 for glass of index 1.5.
        assert!((fresnel_dielectric(1.0, 1.0 / 1.5) - 0.04).abs() < 1e-6);
        assert!((fresnel_dielectric(1.0, 1.5) - 0.04).abs() < 1e-6);
        assert!((f0_of_ior(1.5) - 0.04).abs() < 1e-7);
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
    fn schlick_average_is_the_cosine_weighted_mean() {
        let f0 = Vec3::new(0.04, 0.5, 0.9);
        let n = 100_000;
        let mut sum = Vec3::ZERO;
        for i in 0..n {
            let mu = (i as f32 + 0.5) / n as f32;
            sum += 2.0 * mu * fresnel_schlick(f0, 1.0, mu) / n as f32;
        }
        assert!((sum - schlick_average(f0, 1.0)).abs().max_element() < 1e-4);
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
}
