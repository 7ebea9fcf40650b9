//! Polygons with more than three corners (USD faces) split into triangles.

use glam::{Vec2, Vec3};

/// Triangles (as corner positions in `polygon`) covering a planar polygon, each wound like
/// the polygon: a fan when it is convex, else ear clipping with z-order hashing by the
/// `earcut` crate (a port of Mapbox's earcut), which stays fast on polygons of hundreds of
/// thousands of corners where plain ear clipping (Eberly 2002) is quadratic.
pub fn triangulate(polygon: &[Vec3]) -> Vec<[usize; 3]> {
    let n = polygon.len();
    if n < 3 {
        return Vec::new();
    }
    // Newell's normal: robust for any planar polygon.
    let mut normal = Vec3::ZERO;
    for i in 0..n {
        let (a, b) = (polygon[i], polygon[(i + 1) % n]);
        normal += Vec3::new(
            (a.y - b.y) * (a.z + b.z),
            (a.z - b.z) * (a.x + b.x),
            (a.x - b.x) * (a.y + b.y),
        );
    }
    let convex_at = |a: Vec3, b: Vec3, c: Vec3| (b - a).cross(c - b).dot(normal) >= 0.0;
    if n == 3 || (0..n).all(|i| convex_at(polygon[i], polygon[(i + 1) % n], polygon[(i + 2) % n])) {
        return (1..n - 1).map(|i| [0, i, i + 1]).collect();
    }
    // Project onto the plane across the normal's largest component.
    let axis = normal.abs().max_position();
    let flat: Vec<[f64; 2]> = polygon
        .iter()
        .map(|p| {
            let q = match axis {
                0 => Vec2::new(p.y, p.z),
                1 => Vec2::new(p.z, p.x),
                _ => Vec2::new(p.x, p.y),
            };
            [q.x as f64, q.y as f64]
        })
        .collect();
    let mut corners: Vec<u32> = Vec::with_capacity(3 * (n - 2));
    earcut::Earcut::new().earcut(flat, &[] as &[u32], &mut corners);
    corners
        .chunks_exact(3)
        .map(|t| {
            let [a, b, c] = [t[0] as usize, t[1] as usize, t[2] as usize];
            let facing = (polygon[b] - polygon[a])
                .cross(polygon[c] - polygon[a])
                .dot(normal);
            if facing < 0.0 { [a, c, b] } else { [a, b, c] }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn area(polygon: &[Vec3], triangles: &[[usize; 3]]) -> f32 {
        triangles
            .iter()
            .map(|t| {
                let [a, b, c] = t.map(|i| polygon[i]);
                0.5 * (b - a).cross(c - a).dot(Vec3::Z)
            })
            .sum()
    }

    #[test]
    fn convex_polygons_become_fans_and_concave_ones_ears() {
        let square = [
            Vec3::new(0.0, 0.0, 0.0),
            Vec3::new(1.0, 0.0, 0.0),
            Vec3::new(1.0, 1.0, 0.0),
            Vec3::new(0.0, 1.0, 0.0),
        ];
        assert_eq!(triangulate(&square), vec![[0, 1, 2], [0, 2, 3]]);
        // An L shape (area 3) whose fan from corner 0 would cover the notch.
        let l = [
            Vec3::new(1.0, 1.0, 0.0),
            Vec3::new(2.0, 1.0, 0.0),
            Vec3::new(2.0, 2.0, 0.0),
            Vec3::new(0.0, 2.0, 0.0),
            Vec3::new(0.0, 0.0, 0.0),
            Vec3::new(1.0, 0.0, 0.0),
        ];
        let tris = triangulate(&l);
        assert_eq!(tris.len(), 4);
        assert!((area(&l, &tris) - 3.0).abs() < 1e-6, "{tris:?}");
        // Every triangle keeps the polygon's orientation (positive area).
        assert!(tris.iter().all(|t| area(&l, &[*t]) > 0.0), "{tris:?}");
    }

    #[test]
    fn a_star_of_two_hundred_thousand_corners_is_covered_quickly() {
        // Alternating radii make every other corner reflex; the area is known exactly.
        let n = 200_000;
        let star: Vec<Vec3> = (0..n)
            .map(|i| {
                let angle = std::f32::consts::TAU * i as f32 / n as f32;
                let r = if i % 2 == 0 { 1.0 } else { 0.9 };
                Vec3::new(r * angle.cos(), r * angle.sin(), 0.0)
            })
            .collect();
        let expected: f32 = (0..n)
            .map(|i| {
                let (a, b) = (star[i], star[(i + 1) % n]);
                0.5 * a.cross(b).z
            })
            .sum();
        let tris = triangulate(&star);
        assert_eq!(tris.len(), n - 2);
        let got = area(&star, &tris);
        assert!(
            (got - expected).abs() < 1e-3 * expected,
            "{got} vs {expected}"
        );
    }
}
