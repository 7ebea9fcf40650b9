//! Exact triangle–box overlap by the separating axis theorem, after Akenine-Möller (2001),
//! "Fast 3D triangle-box overlap testing".

use glam::Vec3;

/// True when the triangle `v` overlaps the box with centre `center` and half-size `half`.
///
/// Touching counts as overlapping; callers pad the box to stay conservative under rounding.
pub fn triangle_overlaps_box(v: [Vec3; 3], center: Vec3, half: Vec3) -> bool {
    let v = v.map(|p| p - center);
    // The box's own axes: compare bounding intervals.
    let lo = v[0].min(v[1]).min(v[2]);
    let hi = v[0].max(v[1]).max(v[2]);
    if lo.cmpgt(half).any() || hi.cmplt(-half).any() {
        return false;
    }
    // The triangle's plane.
    let edges = [v[1] - v[0], v[2] - v[1], v[0] - v[2]];
    let normal = edges[0].cross(edges[1]);
    if normal.dot(v[0]).abs() > half.dot(normal.abs()) {
        return false;
    }
    // The nine cross products of triangle edges and box axes.
    for edge in edges {
        for axis in [Vec3::X, Vec3::Y, Vec3::Z] {
            let a = axis.cross(edge);
            let p = [a.dot(v[0]), a.dot(v[1]), a.dot(v[2])];
            let r = half.dot(a.abs());
            if p[0].min(p[1]).min(p[2]) > r || p[0].max(p[1]).max(p[2]) < -r {
                return false;
            }
        }
    }
    true
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
