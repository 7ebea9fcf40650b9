//! The ray–triangle test of Möller & Trumbore (1997), "Fast, minimum storage ray-triangle
//! intersection", with the edges precomputed.

use glam::Vec3;

use super::Ray;
use crate::geometry::Aabb;

/// A triangle stored as one vertex and two edges, the form Möller–Trumbore wants.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Triangle {
    /// First vertex.
    pub v0: Vec3,
    /// `v1 - v0`.
    pub e1: Vec3,
    /// `v2 - v0`.
    pub e2: Vec3,
}

/// Where a ray meets a triangle.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TriangleHit {
    /// Ray parameter of the hit.
    pub t: f32,
    /// Barycentric weight of `v1`.
    pub u: f32,
    /// Barycentric weight of `v2`.
    pub v: f32,
}

impl Triangle {
    /// The triangle with these corners.
    pub fn new(v0: Vec3, v1: Vec3, v2: Vec3) -> Triangle {
        Triangle {
            v0,
            e1: v1 - v0,
            e2: v2 - v0,
        }
    }

    /// The three corners.
    pub fn vertices(&self) -> [Vec3; 3] {
        [self.v0, self.v0 + self.e1, self.v0 + self.e2]
    }

    /// Bounding box of the corners.
    pub fn bounds(&self) -> Aabb {
        Aabb::from_points(self.vertices())
    }

    /// True when the triangle has no area or non-finite corners; such triangles are never hit.
    pub fn is_degenerate(&self) -> bool {
        crate::geometry::is_degenerate(self.v0, self.e1, self.e2)
    }

    /// The hit with parameter in (`ray.t_min`, `t_max`), if any.
    ///
    /// Rays parallel to the triangle's plane (zero determinant) miss.
    #[inline]
    pub fn intersect(&self, ray: &Ray, t_max: f32) -> Option<TriangleHit> {
        let p = ray.direction.cross(self.e2);
        let det = self.e1.dot(p);
        if det == 0.0 {
            return None;
        }
        let inv_det = 1.0 / det;
        let s = ray.origin - self.v0;
        let u = s.dot(p) * inv_det;
        if !(0.0..=1.0).contains(&u) {
            return None;
        }
        let q = s.cross(self.e1);
        let v = ray.direction.dot(q) * inv_det;
        if v < 0.0 || u + v > 1.0 {
            return None;
        }
        let t = self.e2.dot(q) * inv_det;
        (t > ray.t_min && t < t_max).then_some(TriangleHit { t, u, v })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hits_the_inside_and_reports_barycentrics() {
        let tri = Triangle::new(Vec3::ZERO, Vec3::X, Vec3::Y);
        let ray = Ray::new(Vec3::new(0.25, 0.5, 2.0), -Vec3::Z);
        let hit = tri.intersect(&ray, f32::INFINITY).expect("hit");
        assert!((hit.t - 2.0).abs() < 1e-6);
        assert!((hit.u - 0.25).abs() < 1e-6 && (hit.v - 0.5).abs() < 1e-6);
    }

    #[test]
    fn misses_outside_behind_and_beyond_t_max() {
        let tri = Triangle::new(Vec3::ZERO, Vec3::X, Vec3::Y);
        assert!(
            tri.intersect(&Ray::new(Vec3::new(0.8, 0.8, 1.0), -Vec3::Z), f32::INFINITY)
                .is_none()
        );
        assert!(
            tri.intersect(&Ray::new(Vec3::new(0.2, 0.2, 1.0), Vec3::Z), f32::INFINITY)
                .is_none()
        );
        assert!(
            tri.intersect(&Ray::new(Vec3::new(0.2, 0.2, 1.0), -Vec3::Z), 0.5)
                .is_none()
        );
    }

    #[test]
    fn degenerate_triangles_are_flagged_and_never_hit() {
        let line = Triangle::new(Vec3::ZERO, Vec3::X, 2.0 * Vec3::X);
        assert!(line.is_degenerate());
        assert!(
            line.intersect(&Ray::new(Vec3::new(0.5, 0.0, 1.0), -Vec3::Z), f32::INFINITY)
                .is_none()
        );
        assert!(Triangle::new(Vec3::ZERO, Vec3::X, Vec3::new(0.0, f32::NAN, 0.0)).is_degenerate());
        assert!(!Triangle::new(Vec3::ZERO, Vec3::X * 1e-4, Vec3::Y * 1e-4).is_degenerate());
    }
}
