//! χ² tests of sampling routines over the sphere (pbrt-v4's test): bins of equal
//! (cos θ, φ) area, expected counts from the pdf integrated over each bin, bins expected
//! under 5 pooled. The statistic goes through the Wilson–Hilferty normal approximation;
//! callers fail above z = 4.5 (p ≈ 3·10⁻⁶ per test).

use glam::Vec3;

/// Bins in cos θ.
const THETA: usize = 24;
/// Bins in φ.
const PHI: usize = 48;

/// The bin of the unit direction `w`.
fn bin_of(w: Vec3) -> usize {
    let t = (((w.z + 1.0) * 0.5 * THETA as f32) as usize).min(THETA - 1);
    let phi = w.y.atan2(w.x).rem_euclid(std::f32::consts::TAU);
    let p = ((phi / std::f32::consts::TAU * PHI as f32) as usize).min(PHI - 1);
    t * PHI + p
}

/// The z-score of `samples` draws of `sample` (a direction, or none) against `pdf`,
/// with χ² and its degrees of freedom. `pdf` is integrated over each bin on a 16×16
/// sub-grid, fine enough for a GGX lobe of α = 0.04.
pub fn sphere_z_score(
    samples: usize,
    mut sample: impl FnMut() -> Option<Vec3>,
    pdf: impl Fn(Vec3) -> f32,
) -> (f64, f64, usize) {
    let mut observed = vec![0f64; THETA * PHI];
    for _ in 0..samples {
        if let Some(wi) = sample() {
            observed[bin_of(wi)] += 1.0;
        }
    }
    let sub = 16;
    let mut expected = vec![0f64; THETA * PHI];
    let bin_area = 4.0 * std::f64::consts::PI / (THETA * PHI) as f64;
    for t in 0..THETA {
        for p in 0..PHI {
            let mut sum = 0.0f64;
            for i in 0..sub {
                for j in 0..sub {
                    let z = -1.0 + 2.0 * (t as f32 + (i as f32 + 0.5) / sub as f32) / THETA as f32;
                    let phi = std::f32::consts::TAU * (p as f32 + (j as f32 + 0.5) / sub as f32)
                        / PHI as f32;
                    let r = (1.0 - z * z).max(0.0).sqrt();
                    sum += f64::from(pdf(Vec3::new(r * phi.cos(), r * phi.sin(), z)));
                }
            }
            expected[t * PHI + p] = sum / (sub * sub) as f64 * bin_area * samples as f64;
        }
    }
    let (chi2, dof) = pooled_chi_square(&observed, &expected);
    let k = dof as f64;
    let z = ((chi2 / k).cbrt() - (1.0 - 2.0 / (9.0 * k))) / (2.0 / (9.0 * k)).sqrt();
    (z, chi2, dof)
}

/// χ² of `counts` against expected counts in proportion to `weights` (each bin's share of
/// the whole, up to a common factor), for as many samples as `counts` holds.
pub fn against_weights(counts: &[u64], weights: &[f64]) -> f64 {
    let samples: u64 = counts.iter().sum();
    let whole: f64 = weights.iter().sum();
    counts
        .iter()
        .zip(weights)
        .map(|(&c, &w)| {
            let e = w / whole * samples as f64;
            (c as f64 - e).powi(2) / e
        })
        .sum()
}

/// The value a χ² statistic with `dof` degrees of freedom exceeds with probability 10⁻⁴
/// (z = 3.719 through Wilson–Hilferty): the limit of tests with equal or known bin shares.
pub fn upper_point(dof: f64) -> f64 {
    let z = 3.719;
    dof * (1.0 - 2.0 / (9.0 * dof) + z * (2.0 / (9.0 * dof)).sqrt()).powi(3)
}

/// χ² over bins with expected count ≥ 5, the rest pooled into one bin.
fn pooled_chi_square(observed: &[f64], expected: &[f64]) -> (f64, usize) {
    let (mut chi2, mut dof) = (0.0, 0usize);
    let (mut pooled_o, mut pooled_e) = (0.0, 0.0);
    for (&o, &e) in observed.iter().zip(expected) {
        if e < 5.0 {
            pooled_o += o;
            pooled_e += e;
        } else {
            chi2 += (o - e) * (o - e) / e;
            dof += 1;
        }
    }
    if pooled_e >= 5.0 {
        chi2 += (pooled_o - pooled_e) * (pooled_o - pooled_e) / pooled_e;
        dof += 1;
    }
    (chi2, dof.saturating_sub(1).max(1))
}
