//! Directional albedo tables: how much of the light arriving from a direction a lobe
//! reflects, E(μ) = ∫ f(wo, wi) cos θi dωi. Energy compensation (Turquin 2019) and the
//! layering of lobes over one another are built from them.
//!
//! The tables are integrated with stratified samples of the lobes' own sampling routines
//! ([`integrate`]) and shipped in the binary ([`shipped`]): integrating them costs about
//! 0.1 s of a core, which every process, and every task of a farm render, would otherwise
//! spend before its first sample. A test integrates them again and compares, so they
//! always describe exactly the lobes that are rendered. Between grid points they are linear
//! in μ and in roughness.

#[cfg(test)]
mod integrate;
mod shipped;

use std::sync::OnceLock;

use glam::Vec2;

/// Grid points in μ = cos θ and in perceptual roughness, each over [0, 1].
const N: usize = 32;

/// Albedo tables of the lobes whose reflectance is not known in closed form.
pub struct AlbedoTables {
    /// Split-sum terms of GGX with Schlick's Fresnel: E(μ) = F0·A + F90·B. Index
    /// `roughness · N + μ`.
    schlick: Vec<Vec2>,
    /// Cosine-weighted average of the albedo with F = 1, Ē = ∫ 2μ (A + B) dμ, per roughness.
    white_average: Vec<f32>,
    /// Albedo of the Charlie sheen lobe with a white sheen colour.
    sheen: Vec<f32>,
}

/// The process's tables, read from the shipped ones on first use.
pub fn tables() -> &'static AlbedoTables {
    &shipped_tables().0
}

/// The process's glass table, read from the shipped one on first use.
pub fn glass_table() -> &'static GlassTable {
    &shipped_tables().1
}

/// Both tables, decoded together once: they share one shipped file.
fn shipped_tables() -> &'static (AlbedoTables, GlassTable) {
    static TABLES: OnceLock<(AlbedoTables, GlassTable)> = OnceLock::new();
    TABLES.get_or_init(shipped::decode)
}

impl AlbedoTables {
    /// (A, B) at (μ, roughness): GGX's albedo with Schlick's Fresnel is F0·A + F90·B.
    pub fn schlick(&self, mu: f32, roughness: f32) -> Vec2 {
        bilinear(&self.schlick, mu, roughness)
    }

    /// Ē at `roughness`: the cosine-weighted average albedo of GGX with F = 1.
    pub fn white_average(&self, roughness: f32) -> f32 {
        linear(&self.white_average, roughness)
    }

    /// Albedo of the white Charlie sheen at (μ, roughness).
    pub fn sheen(&self, mu: f32, roughness: f32) -> f32 {
        bilinear(&self.sheen, mu, roughness)
    }
}

/// Grid points per axis of the glass table (μ, roughness, index of refraction).
const GLASS_N: usize = 16;

/// Largest index of refraction in the glass table (diamond is 2.42).
const GLASS_MAX_IOR: f32 = 3.0;

/// Albedos of a rough dielectric interface per (side, ior, roughness, μ), before
/// compensation: x = reflection alone (the specular layer and the coat), y = reflection plus
/// transmission in energy (glass). Side 0: light arrives from the lower index (η = ior),
/// side 1: from the higher (η = 1/ior).
pub struct GlassTable {
    values: Vec<Vec2>,
    /// Cosine-weighted average of the exact Fresnel reflectance per ior, from outside.
    fresnel_average: Vec<f32>,
}

impl GlassTable {
    /// The cosine-weighted average of the exact Fresnel reflectance of index `ior` seen
    /// from outside.
    pub fn fresnel_average(&self, ior: f32) -> f32 {
        let (k, t) = position_in((ior - 1.0) / (GLASS_MAX_IOR - 1.0), GLASS_N);
        self.fresnel_average[k] * (1.0 - t) + self.fresnel_average[k + 1] * t
    }

    /// The energy albedo of glass at `mu` for roughness `roughness` and relative index
    /// `eta` (η_other / η_wo): reflection plus transmission.
    pub fn albedo(&self, mu: f32, roughness: f32, eta: f32) -> f32 {
        self.lookup(mu, roughness, eta).y
    }

    /// The albedo of reflection alone (exact Fresnel) off a dielectric of index `eta` ≥ 1
    /// seen from outside.
    pub fn reflection(&self, mu: f32, roughness: f32, eta: f32) -> f32 {
        self.lookup(mu, roughness, eta.max(1.0)).x
    }

    /// Both albedos, trilinear between grid points.
    fn lookup(&self, mu: f32, roughness: f32, eta: f32) -> Vec2 {
        let (side, ior) = if eta >= 1.0 { (0, eta) } else { (1, 1.0 / eta) };
        let (k, tk) = position_in((ior - 1.0) / (GLASS_MAX_IOR - 1.0), GLASS_N);
        let (j, tj) = position_in(roughness, GLASS_N);
        let (i, ti) = position_in(mu, GLASS_N);
        let at = |k: usize, j: usize, i: usize| {
            self.values[((side * GLASS_N + k) * GLASS_N + j) * GLASS_N + i]
        };
        let mut sum = Vec2::ZERO;
        for (dk, wk) in [(0, 1.0 - tk), (1, tk)] {
            for (dj, wj) in [(0, 1.0 - tj), (1, tj)] {
                for (di, wi) in [(0, 1.0 - ti), (1, ti)] {
                    sum += wk * wj * wi * at(k + dk, j + dj, i + di);
                }
            }
        }
        sum
    }
}

fn position(x: f32) -> (usize, f32) {
    position_in(x, N)
}

/// Index and fraction of `x` ∈ [0, 1] on a grid of `n` points.
fn position_in(x: f32, n: usize) -> (usize, f32) {
    let x = x.clamp(0.0, 1.0) * (n - 1) as f32;
    let i = (x as usize).min(n - 2);
    (i, x - i as f32)
}

fn linear<T>(values: &[T], x: f32) -> T
where
    T: Copy + std::ops::Mul<f32, Output = T> + std::ops::Add<Output = T>,
{
    let (i, t) = position(x);
    values[i] * (1.0 - t) + values[i + 1] * t
}

fn bilinear<T>(values: &[T], mu: f32, roughness: f32) -> T
where
    T: Copy + std::ops::Mul<f32, Output = T> + std::ops::Add<Output = T>,
{
    let (j, t) = position(roughness);
    linear(&values[j * N..(j + 1) * N], mu) * (1.0 - t) + linear(&values[(j + 1) * N..], mu) * t
}

#[cfg(test)]
mod tests {
    use glam::Vec3;

    use super::super::sheen::charlie_brdf;
    use super::integrate::{cosine_average, grid};
    use super::*;

    /// A smooth GGX lobe reflects everything; a rough one loses energy to masking: on
    /// average about 60 % for α = 1 (Kulla & Conty 2017, fig. 2), most of it at normal
    /// incidence, where the widest microfacets send light below the horizon.
    #[test]
    fn single_scattering_albedo_falls_with_roughness() {
        let t = tables();
        let e = |mu, r| t.schlick(mu, r).element_sum();
        assert!((e(1.0, 0.05) - 1.0).abs() < 0.01, "{}", e(1.0, 0.05));
        assert!(e(1.0, 0.5) < 0.95 && e(1.0, 0.5) > 0.85, "{}", e(1.0, 0.5));
        assert!(e(1.0, 1.0) > 0.25 && e(1.0, 1.0) < 0.4, "{}", e(1.0, 1.0));
        let avg = |r| t.white_average(r);
        assert!(avg(1.0) > 0.35 && avg(1.0) < 0.5, "{}", avg(1.0));
        assert!(avg(0.2) > avg(0.5) && avg(0.5) > avg(1.0));
        // Schlick's grazing term B is what F90 weighs: large only near grazing incidence.
        assert!(t.schlick(0.1, 0.2).y > 0.3 && t.schlick(1.0, 0.2).y < 1e-3);
    }

    /// The sheen table against plain Monte Carlo (uniform hemisphere sampling, which reaches
    /// grazing directions), at grid points and between them.
    #[test]
    fn sheen_table_matches_monte_carlo() {
        let t = tables();
        for roughness in [0.3f32, 0.5, 1.0] {
            for mu in [0.05f32, 0.2, 0.5, 0.9] {
                let wo = Vec3::new((1.0 - mu * mu).sqrt(), 0.0, mu);
                let mut rng = crate::render::sampling::Rng::new(1, 1);
                let n = 1_000_000;
                let mut sum = 0.0f64;
                for _ in 0..n {
                    let u = rng.uniform2();
                    let z = u.x;
                    let r = (1.0 - z * z).sqrt();
                    let phi = std::f32::consts::TAU * u.y;
                    let wi = Vec3::new(r * phi.cos(), r * phi.sin(), z);
                    sum += f64::from(charlie_brdf(roughness * roughness, wo, wi) * z);
                }
                let mc = sum / n as f64 * std::f64::consts::TAU;
                let table = f64::from(t.sheen(mu, roughness));
                assert!(
                    (table - mc).abs() < 0.01 * mc.max(0.1),
                    "roughness {roughness}, μ {mu}: table {table} vs Monte Carlo {mc}"
                );
            }
        }
    }

    #[test]
    fn interpolation_is_exact_at_grid_points_and_linear_between() {
        let values: Vec<f32> = (0..N * N).map(|k| k as f32).collect();
        assert_eq!(bilinear(&values, grid(3), grid(5)), (5 * N + 3) as f32);
        let mid = bilinear(&values, 0.5 * (grid(3) + grid(4)), grid(5));
        assert!((mid - ((5 * N + 3) as f32 + 0.5)).abs() < 1e-3);
        // The average of a constant is that constant.
        assert!(
            (cosine_average(|_| Vec2::ONE) - Vec2::ONE)
                .abs()
                .max_element()
                < 1e-6
        );
    }
}
