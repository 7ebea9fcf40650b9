//! Sphere lights: sampled uniformly over the cone of directions the sphere subtends from the
//! shading point (pbrt-v4 §6.2.4, "Sampling spheres"; what Cycles does for lamps with a
//! radius), which wastes no samples on its far side, and found by bounce rays by
//! intersecting them directly, since they are not part of the meshes.

use std::f32::consts::PI;

use glam::{Vec2, Vec3};

use crate::render::sampling::{Frame, uniform_cone};

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
}
