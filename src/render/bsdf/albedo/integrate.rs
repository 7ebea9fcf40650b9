//! Integrating the albedo tables from the lobes themselves: stratified samples of their
//! own sampling routines. Tests only: what this gives is shipped in `albedo_tables.bin`
//! ([`super::shipped`]), and a test checks that the two agree.

use glam::{Vec2, Vec3};

use super::super::fresnel::{fresnel_dielectric, refract, schlick_weight};
use super::super::microfacet::{DELTA_ALPHA, Ggx, reflect};
use super::super::sheen::{SHEEN_MIN_ALPHA, charlie_brdf};
use super::{AlbedoTables, GLASS_MAX_IOR, GLASS_N, GlassTable, N};

/// Stratified samples per table entry, per axis.
const STRATA: usize = 24;

/// The μ or roughness of grid point `i` of the GGX and sheen tables.
pub(super) fn grid(i: usize) -> f32 {
    i as f32 / (N - 1) as f32
}

/// The GGX and sheen tables.
pub fn albedo_tables() -> AlbedoTables {
    let mut schlick = Vec::with_capacity(N * N);
    let mut sheen = Vec::with_capacity(N * N);
    for j in 0..N {
        let roughness = grid(j);
        let ggx = Ggx::isotropic((roughness * roughness).max(DELTA_ALPHA));
        let sheen_alpha = (roughness * roughness).max(SHEEN_MIN_ALPHA);
        for i in 0..N {
            let mu = grid(i).max(1e-4);
            let wo = Vec3::new((1.0 - mu * mu).sqrt(), 0.0, mu);
            schlick.push(integrate_schlick(&ggx, wo));
            sheen.push(integrate_sheen(sheen_alpha, wo));
        }
    }
    let white_average = (0..N)
        .map(|j| cosine_average(|i| schlick[j * N + i]).element_sum())
        .collect();
    AlbedoTables {
        schlick,
        white_average,
        sheen,
    }
}

/// The glass table.
pub fn glass_table() -> GlassTable {
    let grid = |i: usize| i as f32 / (GLASS_N - 1) as f32;
    let mut values = Vec::with_capacity(2 * GLASS_N * GLASS_N * GLASS_N);
    for side in 0..2 {
        for k in 0..GLASS_N {
            let ior = 1.0 + (GLASS_MAX_IOR - 1.0) * grid(k);
            let eta = if side == 0 { ior } else { 1.0 / ior };
            for j in 0..GLASS_N {
                let roughness = grid(j);
                let ggx = Ggx::isotropic((roughness * roughness).max(DELTA_ALPHA));
                for i in 0..GLASS_N {
                    let mu = grid(i).max(1e-3);
                    let wo = Vec3::new((1.0 - mu * mu).sqrt(), 0.0, mu);
                    values.push(integrate_glass(&ggx, eta, wo));
                }
            }
        }
    }
    let fresnel_average = (0..GLASS_N)
        .map(|k| {
            let ior = 1.0 + (GLASS_MAX_IOR - 1.0) * grid(k);
            let n = 512;
            (0..n)
                .map(|i| {
                    let mu = (i as f32 + 0.5) / n as f32;
                    2.0 * mu * fresnel_dielectric(mu, 1.0 / ior)
                })
                .sum::<f32>()
                / n as f32
        })
        .collect();
    GlassTable {
        values,
        fresnel_average,
    }
}

fn strata() -> impl Iterator<Item = Vec2> {
    (0..STRATA * STRATA).map(|k| {
        Vec2::new(
            ((k % STRATA) as f32 + 0.5) / STRATA as f32,
            ((k / STRATA) as f32 + 0.5) / STRATA as f32,
        )
    })
}

/// (A, B) by sampling visible normals: each sample weighs G2/G1 (Heitz 2018, eq. 19).
fn integrate_schlick(ggx: &Ggx, wo: Vec3) -> Vec2 {
    let mut sum = Vec2::ZERO;
    for u in strata() {
        let h = ggx.sample_visible(wo, u);
        let wi = reflect(wo, h);
        if wi.z <= 0.0 {
            continue;
        }
        let weight = ggx.g2(wo, wi) / ggx.g1(wo);
        let s = schlick_weight(wo.dot(h));
        sum += weight * Vec2::new(1.0 - s, s);
    }
    sum / (STRATA * STRATA) as f32
}

/// The white sheen's albedo by the midpoint rule over (s, φ) with μi = s², which crowds
/// the nodes towards grazing directions where the sheen peaks (cosine sampling from
/// stratified numbers never reaches them): E = ∫∫ f·μi dμi dφ = ∫∫ f·s²·2s ds dφ, over half
/// the φ range since `wo` lies in the xz-plane.
fn integrate_sheen(alpha: f32, wo: Vec3) -> f32 {
    const S: usize = 48;
    const PHI: usize = 24;
    let mut sum = 0.0;
    for i in 0..S {
        let s = (i as f32 + 0.5) / S as f32;
        let mu = s * s;
        let r = (1.0 - mu * mu).max(0.0).sqrt();
        for j in 0..PHI {
            let phi = std::f32::consts::PI * (j as f32 + 0.5) / PHI as f32;
            let wi = Vec3::new(r * phi.cos(), r * phi.sin(), mu);
            sum += charlie_brdf(alpha, wo, wi) * mu * 2.0 * s;
        }
    }
    sum * 2.0 * std::f32::consts::PI / (S * PHI) as f32
}

/// Reflection and refraction through each stratified visible normal, both branches weighed
/// by their Fresnel share (no random choice): G2/G1 per valid direction (Heitz 2018).
fn integrate_glass(ggx: &Ggx, eta: f32, wo: Vec3) -> Vec2 {
    const S: usize = 12;
    let mut reflection = 0.0;
    let mut transmission = 0.0;
    for k in 0..S * S {
        let u = Vec2::new(
            ((k % S) as f32 + 0.5) / S as f32,
            ((k / S) as f32 + 0.5) / S as f32,
        );
        let h = ggx.sample_visible(wo, u);
        let f = fresnel_dielectric(wo.dot(h), 1.0 / eta);
        let wr = reflect(wo, h);
        if wr.z > 0.0 {
            reflection += f * ggx.g2(wo, wr) / ggx.g1(wo);
        }
        if let Some(wt) = refract(wo, h, 1.0 / eta)
            && wt.z < 0.0
        {
            transmission += (1.0 - f) * ggx.g2(wo, wt) / ggx.g1(wo);
        }
    }
    Vec2::new(reflection, reflection + transmission) / (S * S) as f32
}

/// ∫ 2μ E(μ) dμ of the piecewise-linear E through the grid values, exactly: on [a, b] the
/// integral of 2μ·(eₐ + (e_b − eₐ)(μ − a)/(b − a)) is (b − a)·(eₐ(2a + b) + e_b(a + 2b))/3.
pub(super) fn cosine_average(value: impl Fn(usize) -> Vec2) -> Vec2 {
    (0..N - 1)
        .map(|i| {
            let (a, b) = (grid(i), grid(i + 1));
            (b - a) * (value(i) * (2.0 * a + b) + value(i + 1) * (a + 2.0 * b)) / 3.0
        })
        .sum()
}
