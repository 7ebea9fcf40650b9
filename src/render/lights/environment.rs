//! The environment as a light: a constant colour sampled uniformly over the sphere, or a
//! latitude–longitude map importance-sampled by a piecewise-constant density over its
//! texels, proportional to luminance × cos(latitude) (pbrt-v4 §12.5.2, "Image Infinite
//! Lights"), mapped to directions with density p(u, v) / (2π² cos(latitude)).

use std::f32::consts::PI;

use glam::{Vec2, Vec3};

use super::sample::LightSample;
use super::tree::{Distant, TreeInput};
use crate::render::sampling::{Distribution2d, uniform_sphere};
use crate::scene::{Environment, EnvironmentMap, map_direction, map_uv};

/// Luminance weights of linear Rec. 709 / sRGB primaries (ITU-R BT.709).
const LUMINANCE: Vec3 = Vec3::new(0.2126, 0.7152, 0.0722);

/// An environment prepared for sampling.
pub struct EnvironmentLight {
    environment: Environment,
    /// Over the map's texels; `None` for a constant environment (sampled uniformly).
    distribution: Option<Distribution2d>,
}

impl EnvironmentLight {
    /// Prepares `environment`'s sampling density.
    pub fn new(environment: &Environment) -> EnvironmentLight {
        EnvironmentLight {
            distribution: environment.map.as_ref().map(texel_density),
            environment: environment.clone(),
        }
    }

    /// The environment this light shows.
    pub fn environment(&self) -> &Environment {
        &self.environment
    }

    /// Radiance seen looking along world direction `direction`.
    pub fn radiance(&self, direction: Vec3) -> Vec3 {
        self.environment.radiance(direction)
    }

    /// A world direction towards the environment, its radiance and its solid-angle density.
    pub fn sample(&self, u: Vec2) -> Option<(Vec3, Vec3, f32)> {
        let Some(distribution) = &self.distribution else {
            let wi = uniform_sphere(u);
            return Some((wi, self.environment.tint, 1.0 / (4.0 * PI)));
        };
        let (uv, density) = distribution.sample(u)?;
        let local = map_direction(uv);
        let cos_latitude = (1.0 - local.y * local.y).max(0.0).sqrt();
        if cos_latitude == 0.0 {
            return None;
        }
        let wi = self.environment.world_from_map * local;
        let pdf = density / (2.0 * PI * PI * cos_latitude);
        Some((wi, self.radiance(wi), pdf))
    }

    /// A direction towards the environment from `p`, chosen with probability `pmf`, as a
    /// light sample: a point `far` away, past the whole scene.
    pub fn sample_from(&self, pmf: f32, p: Vec3, far: f32, u: Vec2) -> Option<LightSample> {
        let (wi, radiance, pdf) = self.sample(u)?;
        Some(LightSample {
            point: p + far * wi,
            point_error: Vec3::ZERO,
            normal: -wi,
            wi,
            distance: far,
            radiance,
            pdf: pmf * pdf,
            is_delta: false,
        })
    }

    /// What the environment brings, for the light tree: the irradiance of its `power`
    /// (what crosses the scene's disc of area `disc`) over that disc, from every side.
    pub fn tree_input(power: f32, disc: f32) -> TreeInput {
        TreeInput::Infinite(Distant {
            irradiance: if disc > 0.0 { power / disc } else { power },
            towards: None,
        })
    }

    /// The solid-angle density with which [`EnvironmentLight::sample`] draws `direction`.
    pub fn pdf(&self, direction: Vec3) -> f32 {
        let Some(distribution) = &self.distribution else {
            return 1.0 / (4.0 * PI);
        };
        let local = self.environment.world_from_map.transpose() * direction;
        let cos_latitude = (1.0 - local.y * local.y).max(0.0).sqrt();
        if cos_latitude == 0.0 {
            return 0.0;
        }
        let uv = map_uv(local).clamp(Vec2::ZERO, Vec2::ONE);
        distribution.pdf(uv) / (2.0 * PI * PI * cos_latitude)
    }
}

/// Sampling weights of a map: each texel's luminance × cos(latitude), the luminance taken as
/// the largest over the texel and its eight neighbours, since bilinear filtering lets a
/// bright texel light its neighbours' area; a floor of a thousandth of the mean keeps every
/// direction that may carry light reachable by light sampling alone.
fn texel_density(map: &EnvironmentMap) -> Distribution2d {
    let (w, h) = (map.width as usize, map.height as usize);
    let luminance: Vec<f32> = map
        .texels
        .iter()
        .map(|&t| Vec3::from(t).max(Vec3::ZERO).dot(LUMINANCE))
        .collect();
    let mut weights = vec![0.0f32; w * h];
    for y in 0..h {
        for x in 0..w {
            let mut brightest = 0.0f32;
            for dy in [-1i64, 0, 1] {
                let yy = (y as i64 + dy).clamp(0, h as i64 - 1) as usize;
                for dx in [-1i64, 0, 1] {
                    let xx = (x as i64 + dx).rem_euclid(w as i64) as usize;
                    brightest = brightest.max(luminance[yy * w + xx]);
                }
            }
            weights[y * w + x] = brightest;
        }
    }
    let mean = weights.iter().map(|&v| v as f64).sum::<f64>() / (w * h).max(1) as f64;
    let floor = (1e-3 * mean) as f32;
    for y in 0..h {
        let latitude = (0.5 - (y as f32 + 0.5) / h as f32) * PI;
        for x in 0..w {
            let v = &mut weights[y * w + x];
            *v = (*v + floor) * latitude.cos();
        }
    }
    Distribution2d::new(&weights, w, h)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::render::sampling::Rng;
    use crate::scene::blender_world_rotation;

    /// A map with a smooth gradient, a dark band and one bright texel, turned in the world.
    fn test_environment() -> Environment {
        let (w, h) = (16u32, 8u32);
        let texels = (0..w * h)
            .map(|i| {
                let (x, y) = (i % w, i / w);
                if (x, y) == (11, 2) {
                    [50.0, 40.0, 30.0]
                } else if y == 6 {
                    [0.0; 3]
                } else {
                    [0.2 + 0.05 * x as f32, 0.3, 0.1 * y as f32]
                }
            })
            .collect();
        let map = EnvironmentMap {
            name: "test".into(),
            width: w,
            height: h,
            texels,
        };
        Environment::from_map(map, Vec3::ONE, blender_world_rotation(30.0), "test")
    }

    /// χ² test of environment sampling against its `pdf`, over bins of (cos θ, φ) in
    /// world space, where equal bins have equal solid angle.
    #[test]
    fn environment_sampling_matches_its_pdf_chi_square() {
        let light = EnvironmentLight::new(&test_environment());
        let (n_theta, n_phi, samples) = (16usize, 32usize, 400_000usize);
        let bin = |d: Vec3| {
            let t = (((d.y + 1.0) * 0.5) * n_theta as f32).min(n_theta as f32 - 1.0) as usize;
            let phi = d.z.atan2(d.x).rem_euclid(std::f32::consts::TAU);
            let p = ((phi / std::f32::consts::TAU) * n_phi as f32).min(n_phi as f32 - 1.0);
            t * n_phi + p as usize
        };
        let mut counts = vec![0f64; n_theta * n_phi];
        let mut r = Rng::new(17, 3);
        for _ in 0..samples {
            let (wi, _, pdf) = light.sample(r.uniform2()).unwrap();
            assert!(
                (pdf - light.pdf(wi)).abs() <= 2e-3 * pdf,
                "{pdf} vs {}",
                light.pdf(wi)
            );
            counts[bin(wi)] += 1.0;
        }
        // Expected counts: the pdf integrated over each bin by a fine midpoint rule.
        let mut expected = vec![0f64; counts.len()];
        let fine = 24;
        for t in 0..n_theta * fine {
            let y = -1.0 + 2.0 * (t as f32 + 0.5) / (n_theta * fine) as f32;
            let r_xz = (1.0 - y * y).sqrt();
            for p in 0..n_phi * fine {
                let phi = std::f32::consts::TAU * (p as f32 + 0.5) / (n_phi * fine) as f32;
                let d = Vec3::new(r_xz * phi.cos(), y, r_xz * phi.sin());
                let solid_angle = 4.0 * PI / (n_theta * fine * n_phi * fine) as f32;
                expected[bin(d)] += (light.pdf(d) * solid_angle) as f64 * samples as f64;
            }
        }
        let mut chi2 = 0.0;
        let mut dof = 0;
        for (&c, &e) in counts.iter().zip(&expected) {
            if e > 5.0 {
                chi2 += (c - e).powi(2) / e;
                dof += 1;
            }
        }
        // ~500 degrees of freedom: the 99.9th percentile is below dof + 4.5·√(2·dof).
        let limit = dof as f64 + 4.5 * (2.0 * dof as f64).sqrt();
        assert!(
            chi2 < limit,
            "chi2 = {chi2} over {dof} bins (limit {limit})"
        );
    }

    #[test]
    fn environment_pdf_integrates_to_one_and_covers_every_lit_direction() {
        let light = EnvironmentLight::new(&test_environment());
        let (n, mut integral) = (400usize, 0.0f64);
        for t in 0..n {
            let y = -1.0 + 2.0 * (t as f32 + 0.5) / n as f32;
            for p in 0..2 * n {
                let phi = std::f32::consts::TAU * (p as f32 + 0.5) / (2 * n) as f32;
                let r = (1.0 - y * y).sqrt();
                let d = Vec3::new(r * phi.cos(), y, r * phi.sin());
                let pdf = light.pdf(d);
                if light.radiance(d).max_element() > 0.0 {
                    assert!(pdf > 0.0, "{d} carries light but cannot be sampled");
                }
                integral += pdf as f64 * (4.0 * std::f64::consts::PI) / (2 * n * n) as f64;
            }
        }
        assert!((integral - 1.0).abs() < 2e-3, "{integral}");
    }
}
