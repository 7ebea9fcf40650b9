//! Random numbers and the warps that turn them into directions and points.

use glam::{Vec2, Vec3};

/// PCG32 (O'Neill 2014, "PCG: A family of simple fast space-efficient statistically good
/// algorithms for random number generation"), XSH-RR output. Small, fast and reproducible
/// on every platform, which is what per-pixel streams need.
#[derive(Clone, Debug)]
pub struct Rng {
    state: u64,
    inc: u64,
}

const PCG_MULTIPLIER: u64 = 6364136223846793005;

impl Rng {
    /// A generator whose stream depends only on `seed` and `stream`.
    pub fn new(seed: u64, stream: u64) -> Rng {
        let mut rng = Rng {
            state: 0,
            inc: (mix64(stream) << 1) | 1,
        };
        rng.next_u32();
        rng.state = rng.state.wrapping_add(mix64(seed));
        rng.next_u32();
        rng
    }

    /// The generator of one camera sample: its numbers depend on (seed, pixel, sample index)
    /// alone, so a sample is the same whichever process, thread or pass takes it, and sample
    /// ranges rendered apart merge into exactly the image of one render.
    pub fn for_sample(seed: u64, pixel: u64, sample: u32) -> Rng {
        Rng::new(seed ^ mix64(u64::from(sample)), pixel)
    }

    /// The next 32 random bits.
    pub fn next_u32(&mut self) -> u32 {
        let old = self.state;
        self.state = old.wrapping_mul(PCG_MULTIPLIER).wrapping_add(self.inc);
        let xorshifted = (((old >> 18) ^ old) >> 27) as u32;
        let rot = (old >> 59) as u32;
        xorshifted.rotate_right(rot)
    }

    /// Uniform in [0, 1).
    pub fn uniform(&mut self) -> f32 {
        (self.next_u32() >> 8) as f32 * (1.0 / (1u32 << 24) as f32)
    }

    /// Two uniforms in [0, 1).
    pub fn uniform2(&mut self) -> Vec2 {
        Vec2::new(self.uniform(), self.uniform())
    }
}

/// SplitMix64's finaliser (Steele, Lea & Flood 2014): spreads nearby seeds far apart.
pub fn mix64(mut z: u64) -> u64 {
    z = z.wrapping_add(0x9e3779b97f4a7c15);
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58476d1ce4e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d049bb133111eb);
    z ^ (z >> 31)
}

/// Uniform point on the unit disk by Shirley & Chiu's (1997) concentric map.
pub fn concentric_disk(u: Vec2) -> Vec2 {
    let o = 2.0 * u - Vec2::ONE;
    if o == Vec2::ZERO {
        return Vec2::ZERO;
    }
    let (r, theta) = if o.x.abs() > o.y.abs() {
        (o.x, std::f32::consts::FRAC_PI_4 * (o.y / o.x))
    } else {
        (
            o.y,
            std::f32::consts::FRAC_PI_2 - std::f32::consts::FRAC_PI_4 * (o.x / o.y),
        )
    };
    r * Vec2::new(theta.cos(), theta.sin())
}

/// Cosine-weighted direction about +Z (Malley's method); pdf = cos θ / π.
pub fn cosine_hemisphere(u: Vec2) -> Vec3 {
    let d = concentric_disk(u);
    Vec3::new(d.x, d.y, (1.0 - d.length_squared()).max(0.0).sqrt())
}

/// A direction uniform over the unit sphere, density 1/(4π) (pbrt-v3 §13.6.1).
pub fn uniform_sphere(u: Vec2) -> Vec3 {
    let z = 1.0 - 2.0 * u.x;
    let r = (1.0 - z * z).max(0.0).sqrt();
    let phi = std::f32::consts::TAU * u.y;
    Vec3::new(r * phi.cos(), r * phi.sin(), z)
}

/// A direction uniform over the cone of directions within θmax of +Z, given
/// 1 − cos θmax (passed that way so that narrow cones keep their precision); density
/// 1/(2π(1 − cos θmax)) (pbrt-v4 §A.5.4).
pub fn uniform_cone(u: Vec2, one_minus_cos_max: f32) -> Vec3 {
    let one_minus_cos = u.x * one_minus_cos_max;
    let cos_theta = 1.0 - one_minus_cos;
    // sin² = (1 − cos)(1 + cos), without the cancellation of 1 − cos².
    let sin_theta = (one_minus_cos * (2.0 - one_minus_cos)).max(0.0).sqrt();
    let phi = std::f32::consts::TAU * u.y;
    Vec3::new(sin_theta * phi.cos(), sin_theta * phi.sin(), cos_theta)
}

/// Barycentrics (b1, b2) of a uniform point on a triangle (pbrt-v3 §13.6.5).
pub fn uniform_triangle(u: Vec2) -> Vec2 {
    let s = u.x.sqrt();
    Vec2::new(1.0 - s, u.y * s)
}

/// Veach's (1997) power heuristic with β = 2, one sample from each strategy.
pub fn power_heuristic(pdf_f: f32, pdf_g: f32) -> f32 {
    let f = pdf_f * pdf_f;
    let g = pdf_g * pdf_g;
    if f + g == 0.0 { 0.0 } else { f / (f + g) }
}

/// An orthonormal basis whose third axis is `n` (Duff et al. 2017, "Building an
/// orthonormal basis, revisited").
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Frame {
    /// First tangent.
    pub s: Vec3,
    /// Second tangent.
    pub t: Vec3,
    /// The normal.
    pub n: Vec3,
}

impl Frame {
    /// The frame around unit vector `n`.
    pub fn from_normal(n: Vec3) -> Frame {
        let sign = 1.0f32.copysign(n.z);
        let a = -1.0 / (sign + n.z);
        let b = n.x * n.y * a;
        Frame {
            s: Vec3::new(1.0 + sign * n.x * n.x * a, sign * b, -sign * n.x),
            t: Vec3::new(b, sign + n.y * n.y * a, -n.y),
            n,
        }
    }

    /// A local direction expressed in world space.
    pub fn to_world(&self, v: Vec3) -> Vec3 {
        v.x * self.s + v.y * self.t + v.z * self.n
    }

    /// A world direction expressed in the frame (normal = +Z).
    pub fn to_local(&self, v: Vec3) -> Vec3 {
        Vec3::new(v.dot(self.s), v.dot(self.t), v.dot(self.n))
    }
}

/// A discrete distribution proportional to non-negative weights, sampled by inverting its CDF.
#[derive(Clone, Debug)]
pub struct Distribution1d {
    weights: Vec<f32>,
    cdf: Vec<f64>,
    total: f64,
}

impl Distribution1d {
    /// The distribution over `weights`; non-finite and negative weights count as zero.
    pub fn new(weights: Vec<f32>) -> Distribution1d {
        let weights: Vec<f32> = weights
            .into_iter()
            .map(|w| if w.is_finite() && w > 0.0 { w } else { 0.0 })
            .collect();
        let mut cdf = Vec::with_capacity(weights.len());
        let mut total = 0.0f64;
        for &w in &weights {
            total += w as f64;
            cdf.push(total);
        }
        Distribution1d {
            weights,
            cdf,
            total,
        }
    }

    /// Sum of the weights.
    pub fn total(&self) -> f64 {
        self.total
    }

    /// An index drawn with probability weight/total, and that probability. `None` when all
    /// weights are zero.
    pub fn sample(&self, u: f32) -> Option<(usize, f32)> {
        if self.total <= 0.0 {
            return None;
        }
        let target = u as f64 * self.total;
        let i = self
            .cdf
            .partition_point(|&c| c <= target)
            .min(self.cdf.len() - 1);
        // Skip zero-weight entries that share a CDF value with their successor.
        let i = (i..self.weights.len())
            .find(|&j| self.weights[j] > 0.0)
            .unwrap_or(i);
        Some((i, self.pmf(i)))
    }

    /// Probability of drawing index `i`.
    pub fn pmf(&self, i: usize) -> f32 {
        if self.total <= 0.0 {
            0.0
        } else {
            (self.weights[i] as f64 / self.total) as f32
        }
    }

    /// As [`Distribution1d::sample`], also giving where `u` fell inside the chosen entry's
    /// share of [0, 1), itself in [0, 1): the continuous offset of a piecewise-constant
    /// density (pbrt-v4 §A.4.1).
    pub fn sample_continuous(&self, u: f32) -> Option<(usize, f32, f32)> {
        let (i, pmf) = self.sample(u)?;
        let before = if i == 0 { 0.0 } else { self.cdf[i - 1] };
        let width = self.weights[i] as f64;
        let offset = ((u as f64 * self.total - before) / width).clamp(0.0, 1.0 - f64::EPSILON);
        Some((i, pmf, offset as f32))
    }
}

/// A piecewise-constant density over [0, 1]², one value per cell of a `width × height`
/// grid, sampled by its marginal over rows and then the chosen row (pbrt-v4 §A.4.2).
#[derive(Clone, Debug)]
pub struct Distribution2d {
    width: usize,
    height: usize,
    rows: Vec<Distribution1d>,
    marginal: Distribution1d,
}

impl Distribution2d {
    /// The density proportional to `weights`, row by row (`width × height` values).
    pub fn new(weights: &[f32], width: usize, height: usize) -> Distribution2d {
        assert_eq!(weights.len(), width * height);
        let rows: Vec<Distribution1d> = weights
            .chunks(width)
            .map(|row| Distribution1d::new(row.to_vec()))
            .collect();
        let marginal = Distribution1d::new(rows.iter().map(|r| r.total() as f32).collect());
        Distribution2d {
            width,
            height,
            rows,
            marginal,
        }
    }

    /// A point drawn with the density, and the density there (with respect to area in
    /// [0, 1]²). `None` when every weight is zero.
    pub fn sample(&self, u: Vec2) -> Option<(Vec2, f32)> {
        let (row, row_pmf, dy) = self.marginal.sample_continuous(u.x)?;
        let (column, column_pmf, dx) = self.rows[row].sample_continuous(u.y)?;
        let point = Vec2::new(
            (column as f32 + dx) / self.width as f32,
            (row as f32 + dy) / self.height as f32,
        );
        let density = row_pmf * column_pmf * (self.width * self.height) as f32;
        Some((point, density))
    }

    /// The density at `point` in [0, 1]².
    pub fn pdf(&self, point: Vec2) -> f32 {
        let column = ((point.x * self.width as f32) as usize).min(self.width - 1);
        let row = ((point.y * self.height as f32) as usize).min(self.height - 1);
        self.marginal.pmf(row) * self.rows[row].pmf(column) * (self.width * self.height) as f32
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn uniform_stays_in_unit_interval_and_streams_differ() {
        let mut a = Rng::new(7, 0);
        let mut b = Rng::new(7, 1);
        let same = (0..100).filter(|_| a.next_u32() == b.next_u32()).count();
        assert!(same < 3);
        let mut r = Rng::new(1, 2);
        let mean = (0..100_000)
            .map(|_| r.uniform())
            .inspect(|&x| assert!((0.0..1.0).contains(&x)))
            .sum::<f32>()
            / 1e5;
        assert!((mean - 0.5).abs() < 0.005, "{mean}");
    }

    #[test]
    fn frame_is_orthonormal() {
        let mut r = Rng::new(3, 3);
        for _ in 0..1000 {
            let n = (Vec3::new(r.uniform(), r.uniform(), r.uniform()) - 0.5).normalize();
            let f = Frame::from_normal(n);
            for (a, b) in [(f.s, f.t), (f.s, f.n), (f.t, f.n)] {
                assert!(a.dot(b).abs() < 1e-5);
            }
            assert!((f.s.length() - 1.0).abs() < 1e-5 && (f.t.length() - 1.0).abs() < 1e-5);
        }
    }

    /// Pearson's χ² of 200 counts that should be equal, against the 99.9th percentile of
    /// 199 degrees of freedom (about 268).
    fn assert_equal_bins(counts: &[f64]) {
        assert_eq!(counts.len(), 200);
        let expected = counts.iter().sum::<f64>() / counts.len() as f64;
        let chi2: f64 = counts
            .iter()
            .map(|c| (c - expected).powi(2) / expected)
            .sum();
        assert!(chi2 < 268.0, "chi2 = {chi2}");
    }

    /// χ² test of cosine sampling against cos θ/π over a grid of (cos θ, φ) bins.
    #[test]
    fn cosine_hemisphere_matches_its_pdf_chi_square() {
        let (n_theta, n_phi, samples) = (10usize, 20usize, 200_000usize);
        let mut counts = vec![0f64; n_theta * n_phi];
        let mut r = Rng::new(11, 0);
        for _ in 0..samples {
            let d = cosine_hemisphere(r.uniform2());
            let ti = ((d.z * d.z) * n_theta as f32).min(n_theta as f32 - 1.0) as usize;
            let phi = d.y.atan2(d.x).rem_euclid(std::f32::consts::TAU);
            let pi =
                ((phi / std::f32::consts::TAU) * n_phi as f32).min(n_phi as f32 - 1.0) as usize;
            counts[ti * n_phi + pi] += 1.0;
        }
        // With pdf cos θ/π, cos²θ is uniform on [0, 1] and φ is uniform: all bins are equal.
        assert_equal_bins(&counts);
    }

    /// χ² test of cone sampling: with a uniform density over the cone, cos θ is uniform on
    /// [cos θmax, 1] and φ on [0, 2π), so equal bins of (cos θ, φ) are equally likely.
    #[test]
    fn uniform_cone_matches_its_pdf_chi_square() {
        let (n_theta, n_phi, samples) = (10usize, 20usize, 200_000usize);
        let cos_max = 0.8f32;
        let mut counts = vec![0f64; n_theta * n_phi];
        let mut r = Rng::new(19, 4);
        for _ in 0..samples {
            let d = uniform_cone(r.uniform2(), 1.0 - cos_max);
            assert!(
                (d.length() - 1.0).abs() < 1e-5 && d.z >= cos_max - 1e-6,
                "{d}"
            );
            let t = ((d.z - cos_max) / (1.0 - cos_max) * n_theta as f32) as usize;
            let phi = d.y.atan2(d.x).rem_euclid(std::f32::consts::TAU);
            let p = (phi / std::f32::consts::TAU * n_phi as f32) as usize;
            counts[t.min(n_theta - 1) * n_phi + p.min(n_phi - 1)] += 1.0;
        }
        assert_equal_bins(&counts);
    }

    #[test]
    fn distribution_draws_in_proportion_and_skips_zero_weights() {
        let d = Distribution1d::new(vec![0.0, 1.0, 0.0, 3.0, f32::NAN]);
        assert_eq!(d.pmf(0), 0.0);
        assert!((d.pmf(3) - 0.75).abs() < 1e-6);
        let mut counts = [0usize; 5];
        let mut r = Rng::new(5, 5);
        for _ in 0..40_000 {
            counts[d.sample(r.uniform()).unwrap().0] += 1;
        }
        assert_eq!(counts[0] + counts[2] + counts[4], 0);
        assert!(
            (counts[3] as f64 / 40_000.0 - 0.75).abs() < 0.01,
            "{counts:?}"
        );
        assert!(Distribution1d::new(vec![0.0; 3]).sample(0.5).is_none());
    }

    /// χ² test of the 2D piecewise-constant sampler against its own density, on bins finer
    /// than its cells (so the offsets inside a cell are tested too), and of `pdf` against
    /// the density `sample` reports.
    #[test]
    fn distribution_2d_matches_its_density_chi_square() {
        let (w, h) = (6usize, 4usize);
        let weights: Vec<f32> = (0..w * h)
            .map(|i| {
                if i % 7 == 3 {
                    0.0
                } else {
                    1.0 + (i * i % 5) as f32
                }
            })
            .collect();
        let d = Distribution2d::new(&weights, w, h);
        let total: f32 = weights.iter().sum();
        let (bx, by, samples) = (2 * w, 2 * h, 200_000usize);
        let mut counts = vec![0f64; bx * by];
        let mut r = Rng::new(13, 1);
        for _ in 0..samples {
            let (p, density) = d.sample(r.uniform2()).unwrap();
            assert!(
                (density - d.pdf(p)).abs() <= 1e-4 * density,
                "{density} vs {}",
                d.pdf(p)
            );
            let (x, y) = ((p.x * bx as f32) as usize, (p.y * by as f32) as usize);
            counts[y.min(by - 1) * bx + x.min(bx - 1)] += 1.0;
        }
        let mut chi2 = 0.0;
        for (i, &count) in counts.iter().enumerate() {
            let cell = (i / bx / 2) * w + (i % bx) / 2;
            let expected = samples as f64 * (weights[cell] / total) as f64 / 4.0;
            if expected == 0.0 {
                assert_eq!(count, 0.0, "a sample in a zero-weight cell");
            } else {
                chi2 += (count - expected).powi(2) / expected;
            }
        }
        // At most 95 degrees of freedom: the 99.9th percentile is about 141.
        assert!(chi2 < 141.0, "chi2 = {chi2}");
    }
}
