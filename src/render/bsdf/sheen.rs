//! Sheen: the back-scattering of fibres on cloth and velvet, as `KHR_materials_sheen`
//! defines it: the "Charlie" distribution (Estevez & Kulla 2017, "Production friendly
//! microfacet sheen BRDF") with Neubelt & Pettineo's (2013) visibility term.

use std::f32::consts::TAU;

use glam::Vec3;

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
}
