//! Exact triangle–box overlap by the separating axis theorem, after Akenine-Möller (2001),
//! "Fast 3D triangle-box overlap testing".

use glam::Vec3;

use crate::geometry::Aabb;

/// True when the triangle `v` overlaps the box with centre `center` and half-size `half`.
///
/// Touching counts as overlapping; callers pad the box to stay conservative under rounding.
#[cfg(test)]
pub fn triangle_overlaps_box(v: [Vec3; 3], center: Vec3, half: Vec3) -> bool {
    TriangleBoxTest::new(v, half).overlaps(center)
}

/// One triangle made ready to be tested against many boxes of one half-size (the cells
/// of a grid): the thirteen separating axes of the test and the triangle's extent along
/// each depend on the triangle alone, so they are found once and each box costs a dot
/// product per axis. Positions are taken from the triangle's first corner, so the
/// arithmetic stays at the scale of the triangle and its cell, not of the coordinates.
pub struct TriangleBoxTest {
    origin: Vec3,
    half: Vec3,
    /// The triangle's bounds, from `origin`.
    lo: Vec3,
    hi: Vec3,
    normal: Vec3,
    /// The box's extent along the normal.
    normal_reach: f32,
    /// The nine cross products of box axes and triangle edges (axis by axis, padded to
    /// [`AXES`] with zero axes that never separate), the triangle's interval on each and the
    /// box's half-extent along each: laid out so the nine tests compile to vector code.
    axes: [[f32; AXES]; 3],
    min: [f32; AXES],
    max: [f32; AXES],
    reach: [f32; AXES],
}

/// Lanes for the nine edge-cross-axis tests: three vectors of four.
const AXES: usize = 12;

impl TriangleBoxTest {
    /// Prepares triangle `v` for boxes of half-size `half`.
    #[inline(always)]
    pub fn new(v: [Vec3; 3], half: Vec3) -> TriangleBoxTest {
        let origin = v[0];
        let v = v.map(|p| p - origin);
        let edges = [v[1] - v[0], v[2] - v[1], v[0] - v[2]];
        let normal = edges[0].cross(edges[1]);
        let mut test = TriangleBoxTest {
            origin,
            half,
            lo: v[0].min(v[1]).min(v[2]),
            hi: v[0].max(v[1]).max(v[2]),
            normal,
            normal_reach: half.dot(normal.abs()),
            axes: [[0.0; AXES]; 3],
            min: [0.0; AXES],
            max: [0.0; AXES],
            reach: [0.0; AXES],
        };
        let mut k = 0;
        for edge in edges {
            for axis in [Vec3::X, Vec3::Y, Vec3::Z] {
                let a = axis.cross(edge);
                let p = [a.dot(v[0]), a.dot(v[1]), a.dot(v[2])];
                for (i, component) in a.to_array().into_iter().enumerate() {
                    test.axes[i][k] = component;
                }
                test.min[k] = p[0].min(p[1]).min(p[2]);
                test.max[k] = p[0].max(p[1]).max(p[2]);
                test.reach[k] = half.dot(a.abs());
                k += 1;
            }
        }
        test
    }

    /// True when the triangle overlaps the box centred at `center` (Akenine-Möller 2001:
    /// no separating axis among the box's three, the triangle's normal and the nine cross
    /// products). Touching counts as overlapping.
    #[inline(always)]
    pub fn overlaps(&self, center: Vec3) -> bool {
        let c = center - self.origin;
        // The box's own axes: compare bounding intervals.
        if (self.lo - c).cmpgt(self.half).any() || (self.hi - c).cmplt(-self.half).any() {
            return false;
        }
        // The triangle's plane (through `origin`, the first corner).
        if self.normal.dot(c).abs() > self.normal_reach {
            return false;
        }
        let [x, y, z] = &self.axes;
        let separated: [bool; AXES] = std::array::from_fn(|k| {
            let d = x[k] * c.x + y[k] * c.y + z[k] * c.z;
            (self.min[k] - d > self.reach[k]) | (self.max[k] - d < -self.reach[k])
        });
        !separated.iter().any(|&s| s)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn separates_and_overlaps_as_geometry_says() {
        let unit = (Vec3::ZERO, Vec3::splat(0.5));
        let through = [
            Vec3::new(-1.0, -1.0, 0.0),
            Vec3::new(1.0, -1.0, 0.0),
            Vec3::new(0.0, 1.0, 0.0),
        ];
        assert!(triangle_overlaps_box(through, unit.0, unit.1));
        let above = through.map(|p| p + Vec3::Z);
        assert!(!triangle_overlaps_box(above, unit.0, unit.1));
        // Bounding boxes overlap, but the triangle passes beside the box corner.
        let beside = [
            Vec3::new(0.6, 2.0, 0.0),
            Vec3::new(2.0, 0.6, 0.0),
            Vec3::new(2.0, 2.0, 0.0),
        ];
        assert!(!triangle_overlaps_box(
            beside.map(|p| p - Vec3::splat(0.5)),
            unit.0,
            unit.1
        ));
        // A large triangle wholly containing the box's cross-section.
        let big = [
            Vec3::new(-10.0, -10.0, 0.1),
            Vec3::new(10.0, -10.0, 0.1),
            Vec3::new(0.0, 10.0, 0.1),
        ];
        assert!(triangle_overlaps_box(big, unit.0, unit.1));
    }
}

/// A convex polygon of at most 9 corners: a triangle clipped by up to three slabs.
#[derive(Clone, Copy, Debug)]
pub struct Polygon {
    corners: [Vec3; 9],
    len: usize,
}

impl Polygon {
    /// The triangle as a polygon.
    pub fn from_triangle([a, b, c]: [Vec3; 3]) -> Polygon {
        let mut corners = [Vec3::ZERO; 9];
        corners[..3].copy_from_slice(&[a, b, c]);
        Polygon { corners, len: 3 }
    }

    /// The part of the polygon with `lo ≤ p[axis] ≤ hi` (Sutherland & Hodgman 1974, against
    /// the slab's two planes). Each plane adds at most one corner.
    pub fn clip(&self, axis: usize, lo: f32, hi: f32) -> Polygon {
        self.clip_plane(|p| p[axis] - lo, axis, lo)
            .clip_plane(|p| hi - p[axis], axis, hi)
    }

    /// Keeps the side where `inside(p) ≥ 0`; new corners lie on the plane `p[axis] = at`.
    fn clip_plane(&self, inside: impl Fn(Vec3) -> f32, axis: usize, at: f32) -> Polygon {
        let mut out = Polygon {
            corners: [Vec3::ZERO; 9],
            len: 0,
        };
        let corners = &self.corners[..self.len];
        for (i, &p) in corners.iter().enumerate() {
            let q = corners[(i + 1) % corners.len()];
            let (dp, dq) = (inside(p), inside(q));
            if dp >= 0.0 {
                out.push(p);
            }
            if (dp >= 0.0) != (dq >= 0.0) {
                let mut crossing = p + (q - p) * (dp / (dp - dq));
                crossing[axis] = at;
                out.push(crossing);
            }
        }
        out
    }

    fn push(&mut self, p: Vec3) {
        if self.len < self.corners.len() {
            self.corners[self.len] = p;
            self.len += 1;
        }
    }

    /// The corners' bounding box, or `None` if nothing is left.
    pub fn bounds(&self) -> Option<Aabb> {
        let corners = &self.corners[..self.len];
        (!corners.is_empty()).then(|| Aabb {
            min: corners.iter().fold(Vec3::INFINITY, |m, &p| m.min(p)),
            max: corners.iter().fold(Vec3::NEG_INFINITY, |m, &p| m.max(p)),
        })
    }
}
