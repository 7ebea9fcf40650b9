//! Sampling a triangle light by the solid angle it subtends (Arvo 1995, "Stratified
//! sampling of spherical triangles"; the formulation of pbrt-v4 §6.5.4): every direction
//! towards the triangle is equally likely, so a large or near light is sampled without the
//! distance² / cos weight that makes area sampling noisy up close.
//!
//! A triangle far from the point, compared with its size, gains nothing: its distance² /
//! cos weight hardly varies over it, and working out its solid angle costs more than the
//! rest of the light sample. Such a triangle (its longest edge shorter than its plane's
//! distance from the point, Cycles' rule in `kernel/light/triangle.h`) is sampled by area.
//! Very small solid angles lose precision and nearly hemispherical ones are unstable:
//! outside [`MIN_SOLID_ANGLE`, `MAX_SOLID_ANGLE`] a triangle is sampled by area too
//! (pbrt-v4's thresholds). The choice depends only on the shading point and the triangle,
//! so the density that MIS weighs a hit with is the one the sample was drawn with.

use glam::{DVec3, Vec2, Vec3};

/// Below this solid angle (sr), a triangle is sampled by area.
pub const MIN_SOLID_ANGLE: f64 = 3e-4;
/// Above this solid angle (sr), likewise.
pub const MAX_SOLID_ANGLE: f64 = 6.22;

/// Unit directions from `p` to the corners of a triangle: what both the solid angle and
/// the sample start from, computed once when both are needed.
pub fn directions(p: Vec3, corners: [Vec3; 3]) -> [DVec3; 3] {
    corners.map(|v| (v - p).as_dvec3().normalize_or_zero())
}

/// The solid angle triangle `corners` subtends at `p`.
#[cfg(test)]
pub fn solid_angle(p: Vec3, corners: [Vec3; 3]) -> f64 {
    solid_angle_of(directions(p, corners))
}

/// The solid angle of the spherical triangle with unit corners `[a, b, c]` (Van Oosterom &
/// Strackee 1983: tan(Ω/2) = |a · (b × c)| / (1 + a·b + b·c + c·a)).
pub fn solid_angle_of([a, b, c]: [DVec3; 3]) -> f64 {
    let numerator = a.dot(b.cross(c)).abs();
    let denominator = 1.0 + a.dot(b) + b.dot(c) + c.dot(a);
    let half = numerator.atan2(denominator);
    let omega = 2.0 * half;
    if omega.is_finite() {
        omega.max(0.0)
    } else {
        0.0
    }
}

/// True when a triangle of solid angle `omega` is sampled by solid angle, if near.
pub fn use_solid_angle(omega: f64) -> bool {
    (MIN_SOLID_ANGLE..=MAX_SOLID_ANGLE).contains(&omega)
}

/// How triangle `corners` is sampled from `p`: by solid angle, with the corners'
/// [`directions`] and the solid angle, when it is near and [`use_solid_angle`] agrees;
/// `None`: by area.
pub fn by_solid_angle(p: Vec3, corners: [Vec3; 3]) -> Option<([DVec3; 3], f64)> {
    if !is_near(p, corners) {
        return None;
    }
    let directions = directions(p, corners);
    let omega = solid_angle_of(directions);
    use_solid_angle(omega).then_some((directions, omega))
}

/// True when the triangle's longest edge is longer than the distance from `p` to its
/// plane: (n · (v0 − p))² < longest² · |n|² with n the unnormalised normal, no division.
fn is_near(p: Vec3, [v0, v1, v2]: [Vec3; 3]) -> bool {
    let (e0, e1, e2) = (v1 - v0, v2 - v0, v2 - v1);
    let longest = e0
        .length_squared()
        .max(e1.length_squared())
        .max(e2.length_squared());
    let n = e0.cross(e1);
    let height = n.dot(v0 - p);
    height * height < longest * n.length_squared()
}

/// A direction from `p` uniform over the solid angle of triangle `corners`, whose solid
/// angle [`solid_angle`] gave as `area`, and the barycentrics (b1, b2) of the point where it
/// meets the triangle; `None` when the triangle is degenerate as seen from `p`.
#[cfg(test)]
pub fn sample(p: Vec3, corners: [Vec3; 3], area: f64, u: Vec2) -> Option<(Vec3, Vec2)> {
    sample_from(p, corners, directions(p, corners), area, u)
}

/// [`sample`], given the corners' [`directions`] from `p`.
pub fn sample_from(
    p: Vec3,
    corners: [Vec3; 3],
    [a, b, c]: [DVec3; 3],
    area: f64,
    u: Vec2,
) -> Option<(Vec3, Vec2)> {
    let n_ab = a.cross(b).normalize_or_zero();
    let n_ca = c.cross(a).normalize_or_zero();
    if n_ab == DVec3::ZERO || n_ca == DVec3::ZERO || area.is_nan() || area <= 0.0 {
        return None;
    }
    // The spherical triangle's interior angle α at a (its area, the sum of the three angles
    // less π, is the solid angle already known), by its cosine and sine: no inverse cosine.
    let cos_alpha = n_ab.dot(-n_ca).clamp(-1.0, 1.0);
    let sin_alpha = n_ab.cross(n_ca).length().min(1.0);
    // The sub-triangle (a, b, c') of area u₀·A fixes c' on the great arc from a to c; with
    // φ = u₀·A + π − α, sin φ and cos φ follow from those of u₀·A and α.
    let (sin_sub, cos_sub) = (f64::from(u.x) * area).sin_cos();
    let sin_phi = cos_sub * sin_alpha - sin_sub * cos_alpha;
    let cos_phi = -(cos_sub * cos_alpha + sin_sub * sin_alpha);
    let k1 = cos_phi + cos_alpha;
    let k2 = sin_phi - sin_alpha * a.dot(b);
    let cos_b = ((k2 + (k2 * cos_phi - k1 * sin_phi) * cos_alpha)
        / ((k2 * sin_phi + k1 * cos_phi) * sin_alpha))
        .clamp(-1.0, 1.0);
    let sin_b = (1.0 - cos_b * cos_b).max(0.0).sqrt();
    let c_prime = cos_b * a + sin_b * orthogonal_part(c, a);
    // … and the direction is uniform in z along the arc from b to c'.
    let cos_theta = 1.0 - f64::from(u.y) * (1.0 - c_prime.dot(b));
    let sin_theta = (1.0 - cos_theta * cos_theta).max(0.0).sqrt();
    let w = cos_theta * b + sin_theta * orthogonal_part(c_prime, b);
    let barycentrics = hit_barycentrics(p.as_dvec3(), w, corners.map(Vec3::as_dvec3))?;
    Some((w.as_vec3().normalize(), barycentrics))
}

/// The unit vector along the part of `v` orthogonal to unit `onto`.
fn orthogonal_part(v: DVec3, onto: DVec3) -> DVec3 {
    (v - v.dot(onto) * onto).normalize_or_zero()
}

/// Barycentrics (b1, b2) of the point where the ray from `p` along `w` crosses the plane of
/// the triangle, clamped into it (the direction lies in the triangle's cone up to rounding).
fn hit_barycentrics(p: DVec3, w: DVec3, [v0, v1, v2]: [DVec3; 3]) -> Option<Vec2> {
    let (e1, e2) = (v1 - v0, v2 - v0);
    let q = w.cross(e2);
    let det = e1.dot(q);
    if det == 0.0 || !det.is_finite() {
        return None;
    }
    let s = p - v0;
    let b1 = s.dot(q) / det;
    let b2 = w.dot(s.cross(e1)) / det;
    let (b1, b2) = (b1.clamp(0.0, 1.0), b2.clamp(0.0, 1.0));
    let total = b1 + b2;
    let (b1, b2) = if total > 1.0 {
        (b1 / total, b2 / total)
    } else {
        (b1, b2)
    };
    Some(Vec2::new(b1 as f32, b2 as f32))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::render::chi_square::{against_weights, upper_point};
    use crate::render::sampling::Rng;

    #[test]
    fn solid_angles_of_known_shapes() {
        // One face of a cube seen from its centre is 4π/6, in two triangles.
        let p = Vec3::ZERO;
        let [a, b, c, d] = [
            Vec3::new(-1.0, -1.0, 1.0),
            Vec3::new(1.0, -1.0, 1.0),
            Vec3::new(1.0, 1.0, 1.0),
            Vec3::new(-1.0, 1.0, 1.0),
        ];
        let face = solid_angle(p, [a, b, c]) + solid_angle(p, [a, c, d]);
        assert!((face - 4.0 * std::f64::consts::PI / 6.0).abs() < 1e-6);
    }

    /// The sampled directions are uniform over the solid angle: subdivide the triangle
    /// into 64 pieces, and the share of samples in each matches its share of the solid
    /// angle (χ², against the 99.99 % point).
    #[test]
    fn directions_are_uniform_over_the_solid_angle() {
        let p = Vec3::new(0.1, -0.2, 0.0);
        let corners = [
            Vec3::new(-1.0, -0.5, 0.8),
            Vec3::new(1.5, -0.3, 1.2),
            Vec3::new(0.2, 1.4, 0.5),
        ];
        let n = 8; // pieces per edge: n² sub-triangles
        let point = |i: usize, j: usize| {
            let (s, t) = (i as f32 / n as f32, j as f32 / n as f32);
            corners[0] + s * (corners[1] - corners[0]) + t * (corners[2] - corners[0])
        };
        let total = solid_angle(p, corners);
        assert!(use_solid_angle(total));
        let mut expected = Vec::new();
        let mut cell_of = std::collections::HashMap::new();
        for i in 0..n {
            for j in 0..n - i {
                cell_of.insert((i, j, false), expected.len());
                expected.push(solid_angle(
                    p,
                    [point(i, j), point(i + 1, j), point(i, j + 1)],
                ));
                if i + j + 1 < n {
                    cell_of.insert((i, j, true), expected.len());
                    expected.push(solid_angle(
                        p,
                        [point(i + 1, j), point(i + 1, j + 1), point(i, j + 1)],
                    ));
                }
            }
        }
        let covered: f64 = expected.iter().sum();
        assert!((covered / total - 1.0).abs() < 1e-6);
        let samples = 400_000;
        let mut counts = vec![0u64; expected.len()];
        let mut rng = Rng::new(5, 8);
        for _ in 0..samples {
            let (w, b) = sample(p, corners, total, rng.uniform2()).unwrap();
            // The direction meets the triangle at the barycentrics returned.
            let hit =
                corners[0] + b.x * (corners[1] - corners[0]) + b.y * (corners[2] - corners[0]);
            assert!(((hit - p).normalize() - w).length() < 1e-4);
            let (s, t) = (b.x * n as f32, b.y * n as f32);
            let (i, j) = ((s as usize).min(n - 1), (t as usize).min(n - 1));
            let upper = s.fract() + t.fract() > 1.0 && i + j + 1 < n;
            let key = if i + j >= n {
                (i.min(n - 1 - j), j, false)
            } else {
                (i, j, upper)
            };
            counts[cell_of[&key]] += 1;
        }
        let chi = against_weights(&counts, &expected);
        let dof = (counts.len() - 1) as f64;
        let limit = upper_point(dof);
        assert!(chi < limit, "χ² {chi:.1} over the 99.99 % point {limit:.1}");
    }
}
