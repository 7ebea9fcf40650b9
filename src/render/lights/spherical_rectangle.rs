//! Sampling a rectangular light by the solid angle it subtends (Ureña, Fajardo & King 2013,
//! "An Area-Preserving Parametrization for Spherical Rectangles", EGSR; Algorithm 1): every
//! direction towards the rectangle is equally likely. One rectangle replaces a choice
//! between its two triangles ([`super::spherical`]), which the light tree can only make by
//! bounds, so near a lamp the direct light's only noise left is the cosine and visibility.
//!
//! The rectangle is seen in its own frame (x and y along its edges, z its normal turned away
//! from the point), where it spans [x0, x1] × [y0, y1] at height z0 < 0. Its four sides are
//! arcs of great circles; its solid angle is the sum of the interior angles γ0…γ3 less 2π,
//! and a sample inverts the solid angle of the part left of x = xu, then goes uniformly in
//! the sine of the elevation along that column.
//!
//! In this frame the arcs' normals are simple (pbrt-v4's `SampleSphericalRectangle` uses
//! the same forms): the angle at corner (x, y) has cosine ±x·y / (r(x)·r(y)) and sine
//! |z0|·|(x, y, z0)| / (r(x)·r(y)), with r(t) = √(t² + z0²). So the angles are added as
//! the arguments of the complex numbers (±x·y, |z0|·|(x, y, z0)|) — one `atan2` of their
//! product instead of four inverse cosines.

use glam::{DVec2, Vec2, Vec3};

use super::spherical::use_solid_angle;

/// A rectangle as seen from a point, ready to be sampled.
#[derive(Clone, Copy, Debug)]
pub struct SphericalRectangle {
    /// The rectangle's extent in its frame seen from the point (z0 < 0), divided by the
    /// largest of them so that products of four stay in range.
    x0: f64,
    x1: f64,
    y0: f64,
    y1: f64,
    z0: f64,
    /// cos γ + i·sin γ at corners (x0, y1) and (x0, y0), unnormalised (the two angles
    /// the inversion starts after).
    start: [DVec2; 2],
    solid_angle: f64,
}

/// The product of complex numbers `a` and `b`.
fn times(a: DVec2, b: DVec2) -> DVec2 {
    DVec2::new(a.x * b.x - a.y * b.y, a.x * b.y + a.y * b.x)
}

impl SphericalRectangle {
    /// The rectangle with corner `corner` and perpendicular edges `edges` as seen from `p`,
    /// or `None` when `p` lies in its plane (it subtends nothing).
    pub fn new(p: Vec3, corner: Vec3, edges: [Vec3; 2]) -> Option<SphericalRectangle> {
        let [ex, ey] = edges.map(Vec3::as_dvec3);
        let (width, height) = (ex.length(), ey.length());
        let (x, y) = (ex / width, ey / height);
        let d = (corner - p).as_dvec3();
        let z0 = -d.dot(x.cross(y)).abs();
        let (x0, y0) = (d.dot(x), d.dot(y));
        let (x1, y1) = (x0 + width, y0 + height);
        let scale = x0.abs().max(x1.abs()).max(y0.abs()).max(y1.abs()).max(-z0);
        if z0 == 0.0 || !scale.is_finite() {
            return None;
        }
        let [x0, x1, y0, y1, z0] = [x0, x1, y0, y1, z0].map(|t| t / scale);
        // The angle at each corner, as an unnormalised complex number; corners in the order
        // (x1, y0), (x1, y1), (x0, y1), (x0, y0) of Ureña et al.'s γ0…γ3.
        let angle = |x: f64, y: f64, sign: f64| {
            DVec2::new(sign * x * y, -z0 * (x * x + y * y + z0 * z0).sqrt())
        };
        let start = [angle(x0, y1, 1.0), angle(x0, y0, -1.0)];
        let all = times(
            times(angle(x1, y0, 1.0), angle(x1, y1, -1.0)),
            times(start[0], start[1]),
        );
        // The angles sum to Ω + 2π, and Ω lies in [0, 2π).
        let solid_angle = match all.y.atan2(all.x) {
            negative if negative < 0.0 => negative + std::f64::consts::TAU,
            angle => angle,
        };
        solid_angle.is_finite().then_some(SphericalRectangle {
            x0,
            x1,
            y0,
            y1,
            z0,
            start,
            solid_angle,
        })
    }

    /// The solid angle it subtends (sr).
    pub fn solid_angle(&self) -> f64 {
        self.solid_angle
    }

    /// True when its solid angle is sampled well ([`use_solid_angle`]).
    pub fn is_well_conditioned(&self) -> bool {
        use_solid_angle(self.solid_angle)
    }

    /// A direction uniform over the solid angle, as the point where it meets the rectangle
    /// in the rectangle's own coordinates: (0, 0) at the corner, (1, 1) at the opposite one.
    pub fn sample(&self, u: Vec2) -> Vec2 {
        let (u, v) = (f64::from(u.x), f64::from(u.y));
        let (x0, x1, y0, y1, z0) = (self.x0, self.x1, self.y0, self.y1, self.z0);
        // The column x = xu that leaves u·Ω of the solid angle on its left: with
        // k = 2π − γ2 − γ3, au = u·Ω + k, whose sine and cosine come from those of u·Ω
        // turned by k (the conjugate of γ2 + γ3).
        let turn = times(self.start[0], self.start[1]);
        let turn = DVec2::new(turn.x, -turn.y) / turn.length();
        let (sin_uo, cos_uo) = (u * self.solid_angle).sin_cos();
        let au = times(DVec2::new(cos_uo, sin_uo), turn);
        // The z components of the normals of the arcs at y0 and y1. (Lengths by square
        // roots rather than `hypot`: the coordinates are scaled to at most 1, and libm's
        // `hypot` is several times slower.)
        let length = |a: f64, b: f64| (a * a + b * b).sqrt();
        let b0 = -y0 / length(y0, z0);
        let b1 = y1 / length(y1, z0);
        let fu = (au.x * b0 - b1) / au.y;
        let cu = (fu.signum() / (fu * fu + b0 * b0).sqrt()).clamp(-1.0, 1.0);
        let xu = -(cu * z0) / (1.0 - cu * cu).max(0.0).sqrt();
        let xu = if xu.is_nan() { x0 } else { xu.clamp(x0, x1) };
        // Uniform in the sine of the elevation along that column.
        let dist = length(xu, z0);
        let h0 = y0 / length(dist, y0);
        let h1 = y1 / length(dist, y1);
        let hv = h0 + v * (h1 - h0);
        let yv = if hv * hv < 1.0 - 1e-12 {
            (hv * dist / (1.0 - hv * hv).sqrt()).clamp(y0, y1)
        } else {
            y1
        };
        Vec2::new(
            (((xu - x0) / (x1 - x0)) as f32).clamp(0.0, 1.0),
            (((yv - y0) / (y1 - y0)) as f32).clamp(0.0, 1.0),
        )
    }
}

#[cfg(test)]
mod tests {
    use super::super::spherical::solid_angle;
    use super::*;
    use crate::render::chi_square::{against_weights, upper_point};
    use crate::render::sampling::Rng;

    /// The solid angle of the rectangle as two spherical triangles (Van Oosterom &
    /// Strackee): an independent formula.
    fn by_triangles(p: Vec3, corner: Vec3, [ex, ey]: [Vec3; 2]) -> f64 {
        solid_angle(p, [corner, corner + ex, corner + ex + ey])
            + solid_angle(p, [corner, corner + ex + ey, corner + ey])
    }

    #[test]
    fn solid_angle_matches_two_spherical_triangles() {
        // A cube's face from its centre is 4π/6.
        let face = SphericalRectangle::new(
            Vec3::ZERO,
            Vec3::new(-1.0, -1.0, 1.0),
            [Vec3::new(2.0, 0.0, 0.0), Vec3::new(0.0, 2.0, 0.0)],
        )
        .unwrap();
        let expected = 4.0 * std::f64::consts::PI / 6.0;
        assert!(
            (face.solid_angle() - expected).abs() < 1e-9,
            "{}",
            face.solid_angle()
        );
        // Rectangles in each axis plane, seen from points on either side, beside and over
        // them; coordinates on a 1/64 lattice, so both formulas see the same corners.
        let mut rng = Rng::new(3, 1);
        let mut lattice = |scale: f32| (rng.uniform() * scale * 64.0).round() / 64.0;
        for case in 0..300 {
            let (i, j) = [(0, 1), (1, 2), (2, 0)][case % 3];
            let mut edges = [Vec3::ZERO; 2];
            edges[0][i] = (0.125 + lattice(1.0)) * if case % 2 == 0 { 1.0 } else { -1.0 };
            edges[1][j] = 0.125 + lattice(1.0);
            let corner = Vec3::new(lattice(4.0), lattice(4.0), lattice(4.0)) - 2.0;
            let p = Vec3::new(lattice(8.0), lattice(8.0), lattice(8.0)) - 4.0;
            let Some(rect) = SphericalRectangle::new(p, corner, edges) else {
                continue;
            };
            let expected = by_triangles(p, corner, edges);
            assert!(
                (rect.solid_angle() - expected).abs() < 1e-9 * expected.max(1e-3),
                "from {p}: {} against {expected}",
                rect.solid_angle()
            );
        }
    }

    /// The sampled points are uniform over the solid angle: the share of samples in each
    /// of 10 × 10 pieces of the rectangle matches its share of the solid angle (χ², against
    /// the 99.99 % point), from a point close to a corner and from one far to its side.
    #[test]
    fn directions_are_uniform_over_the_solid_angle() {
        let corner = Vec3::new(-1.0, 0.5, -0.4);
        let edges = [Vec3::new(1.6, 0.0, 0.3), Vec3::new(0.0, 0.9, 0.0)];
        let n = 10;
        for p in [Vec3::new(-0.8, 0.6, 0.3), Vec3::new(2.5, 1.0, 1.2)] {
            let rect = SphericalRectangle::new(p, corner, edges).unwrap();
            assert!(rect.is_well_conditioned());
            let piece = |i: usize, j: usize| {
                let c =
                    corner + (i as f32 / n as f32) * edges[0] + (j as f32 / n as f32) * edges[1];
                by_triangles(p, c, edges.map(|e| e / n as f32))
            };
            let expected: Vec<f64> = (0..n * n).map(|k| piece(k % n, k / n)).collect();
            let covered: f64 = expected.iter().sum();
            assert!((covered / rect.solid_angle() - 1.0).abs() < 1e-5);
            let samples = 400_000;
            let mut counts = vec![0u64; n * n];
            let mut rng = Rng::new(11, 2);
            for _ in 0..samples {
                let ab = rect.sample(rng.uniform2());
                let (i, j) = (
                    ((ab.x * n as f32) as usize).min(n - 1),
                    ((ab.y * n as f32) as usize).min(n - 1),
                );
                counts[j * n + i] += 1;
            }
            let chi = against_weights(&counts, &expected);
            let limit = upper_point((counts.len() - 1) as f64);
            assert!(
                chi < limit,
                "from {p}: χ² {chi:.1} over the 99.99 % point {limit:.1}"
            );
        }
    }

    #[test]
    fn a_point_in_the_plane_sees_nothing() {
        let edges = [Vec3::X, Vec3::Y];
        assert!(SphericalRectangle::new(Vec3::new(3.0, 0.5, 0.0), Vec3::ZERO, edges).is_none());
    }
}
