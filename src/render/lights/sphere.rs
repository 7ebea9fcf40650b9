//! Sphere lights: sampled uniformly over the cone of directions the sphere subtends from the
//! shading point (pbrt-v4 §6.2.4, "Sampling spheres"; what Cycles does for lamps with a
//! radius), which wastes no samples on its far side, and found by bounce rays by
//! intersecting them directly, since they are not part of the meshes.

use std::f32::consts::PI;

use glam::{Vec2, Vec3};

use crate::render::sampling::{Frame, concentric_disk, uniform_cone};

/// A point drawn on a sphere as seen from a shading point.
pub struct SpherePoint {
    /// Unit direction from the shading point.
    pub wi: Vec3,
    /// Distance to the point on the sphere.
    pub distance: f32,
    /// The point.
    pub point: Vec3,
    /// Outward unit normal there.
    pub normal: Vec3,
    /// Solid-angle density of `wi`.
    pub pdf: f32,
}

/// 1 − cos θmax of the cone the sphere (`center`, `radius`) subtends from `p`, or `None`
/// when `p` is inside it.
fn one_minus_cos_max(center: Vec3, radius: f32, p: Vec3) -> Option<f32> {
    let d2 = center.distance_squared(p);
    let sin2 = radius * radius / d2;
    // Inside the sphere, or at a NaN distance: no cone.
    if sin2.is_nan() || sin2 >= 1.0 {
        return None;
    }
    // 1 − √(1 − s) = s / (1 + √(1 − s)), exact for tiny spheres too.
    Some(sin2 / (1.0 + (1.0 - sin2).sqrt()))
}

/// A point on the part of the sphere visible from `p`, drawn uniformly in solid angle.
pub fn sample(center: Vec3, radius: f32, p: Vec3, u: Vec2) -> Option<SpherePoint> {
    let cone = one_minus_cos_max(center, radius, p)?;
    let d = center.distance(p);
    let axis = (center - p) / d;
    let wi = Frame::from_normal(axis).to_world(uniform_cone(u, cone));
    // Where the ray along wi meets the sphere first; at the cone's edge it grazes it.
    let along = d * wi.dot(axis);
    let off_axis2 = (d * d - along * along).max(0.0);
    let distance = along - (radius * radius - off_axis2).max(0.0).sqrt();
    let point = p + distance * wi;
    let normal = (point - center).normalize_or(-wi);
    Some(SpherePoint {
        wi,
        distance,
        point,
        normal,
        pdf: 1.0 / (2.0 * PI * cone),
    })
}

/// The solid-angle density with which [`sample`] draws any direction towards the sphere
/// from `p`.
pub fn pdf(center: Vec3, radius: f32, p: Vec3) -> f32 {
    one_minus_cos_max(center, radius, p).map_or(0.0, |cone| 1.0 / (2.0 * PI * cone))
}

/// Distance along unit direction `d` from `origin` to the sphere's near side, if it lies
/// between `t_min` and `t_max` (an origin inside the sphere sees nothing: lamps emit
/// outwards).
pub fn intersect(
    center: Vec3,
    radius: f32,
    origin: Vec3,
    d: Vec3,
    t_min: f32,
    t_max: f32,
) -> Option<f32> {
    let to_center = center - origin;
    let along = to_center.dot(d);
    let off_axis2 = to_center.length_squared() - along * along;
    let r2 = radius * radius;
    if along <= 0.0 || off_axis2 > r2 || to_center.length_squared() <= r2 {
        return None;
    }
    let t = along - (r2 - off_axis2).sqrt();
    (t > t_min && t < t_max).then_some(t)
}

/// The disc of `radius` around `center` turned towards `p`: Cycles' point lamp with Soft
/// Falloff (`kernel/light/point.h` without `is_sphere`). Its unit normal points at `p`.
fn facing_disc(center: Vec3, p: Vec3) -> Option<Vec3> {
    (p - center).try_normalize()
}

/// A point drawn uniformly over the disc of `radius` at `center` that faces `p`, with its
/// solid-angle density t²/(πr²·cos θ).
pub fn sample_disc(center: Vec3, radius: f32, p: Vec3, u: Vec2) -> Option<SpherePoint> {
    let normal = facing_disc(center, p)?;
    let offset = concentric_disk(u) * radius;
    let point = center + Frame::from_normal(normal).to_world(offset.extend(0.0));
    let to_point = point - p;
    let distance = to_point.length();
    let wi = to_point / distance;
    let cos = normal.dot(-wi);
    (distance > 0.0 && cos > 0.0).then(|| SpherePoint {
        wi,
        distance,
        point,
        normal,
        pdf: distance * distance / (PI * radius * radius * cos),
    })
}

/// The solid-angle density with which [`sample_disc`] from `p` draws unit direction `d`
/// (zero when `d` misses the disc).
pub fn pdf_disc(center: Vec3, radius: f32, p: Vec3, d: Vec3) -> f32 {
    let Some(t) = intersect_disc(center, radius, p, p, d, 0.0, f32::INFINITY) else {
        return 0.0;
    };
    let normal = facing_disc(center, p).unwrap_or(-d);
    t * t / (PI * radius * radius * normal.dot(-d).max(1e-12))
}

/// Distance along unit direction `d` from `origin` to the disc of `radius` at `center`
/// that faces `vertex` (where the path last scattered), between `t_min` and `t_max`.
pub fn intersect_disc(
    center: Vec3,
    radius: f32,
    vertex: Vec3,
    origin: Vec3,
    d: Vec3,
    t_min: f32,
    t_max: f32,
) -> Option<f32> {
    let normal = facing_disc(center, vertex)?;
    let approach = d.dot(normal);
    if approach >= 0.0 {
        return None;
    }
    let t = (center - origin).dot(normal) / approach;
    let inside = (origin + t * d).distance_squared(center) <= radius * radius;
    (inside && t > t_min && t < t_max).then_some(t)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::render::sampling::Rng;

    #[test]
    fn samples_lie_on_the_visible_side_and_rays_find_them_again() {
        let (center, radius, p) = (Vec3::new(1.0, 2.0, -3.0), 0.5, Vec3::new(0.2, -1.0, 4.0));
        let mut r = Rng::new(23, 1);
        for _ in 0..10_000 {
            let s = sample(center, radius, p, r.uniform2()).unwrap();
            assert!((s.point.distance(center) - radius).abs() < 1e-4);
            assert!(s.normal.dot(-s.wi) >= -1e-3, "far side");
            let t = intersect(center, radius, p, s.wi, 0.0, f32::INFINITY).unwrap();
            assert!(
                (t - s.distance).abs() < 1e-3 * s.distance,
                "{t} vs {}",
                s.distance
            );
            assert_eq!(s.pdf, pdf(center, radius, p));
        }
        assert!(sample(center, radius, center + Vec3::X * 0.1, Vec2::splat(0.5)).is_none());
        assert!(intersect(center, radius, p, (p - center).normalize(), 0.0, 1e9).is_none());
    }

    /// Soft falloff's disc: samples face the point, rays find them again, the density is
    /// what `pdf_disc` says, and it integrates to one over the directions to the disc.
    #[test]
    fn facing_disc_samples_are_found_again_with_their_density() {
        let (center, radius, p) = (Vec3::new(1.0, 2.0, -3.0), 0.5, Vec3::new(0.2, -1.0, -2.0));
        let mut r = Rng::new(5, 2);
        let mut integral = 0.0f64;
        let n = 200_000;
        for _ in 0..n {
            let s = sample_disc(center, radius, p, r.uniform2()).unwrap();
            let t = intersect_disc(center, radius, p, p, s.wi, 0.0, f32::INFINITY).unwrap();
            assert!((t - s.distance).abs() < 1e-3 * s.distance);
            assert!((pdf_disc(center, radius, p, s.wi) / s.pdf - 1.0).abs() < 1e-3);
            // Uniform directions over the cone around the disc: ∫pdf dω = 1.
            let cone = one_minus_cos_max(center, radius, p).unwrap();
            let axis = (center - p).normalize();
            let d = Frame::from_normal(axis).to_world(uniform_cone(r.uniform2(), cone));
            integral += f64::from(pdf_disc(center, radius, p, d) * 2.0 * PI * cone);
        }
        let mean = integral / n as f64;
        assert!((mean - 1.0).abs() < 0.01, "{mean}");
    }
}
