//! Polygons with more than three corners (USD and PLY faces) split into triangles.

use glam::{Vec2, Vec3};

/// Most corners of a concave polygon given to ear clipping. Earcut's z-order hashing keeps
/// ordinary polygons fast, but thin ears degrade it towards quadratic time (a 200,000-corner
/// star takes 5–15 s here, found by hostile testing); past this size a concave polygon
/// becomes a fan, in linear time, and the caller says so.
pub const MAX_EAR_CLIPPED_CORNERS: usize = 1 << 16;

/// Triangles (as corner positions in `polygon`) covering a planar polygon, each wound like
/// the polygon: a fan when it is convex, else ear clipping with z-order hashing by the
/// `earcut` crate (a port of Mapbox's earcut). `None` for a concave polygon of more than
/// [`MAX_EAR_CLIPPED_CORNERS`] corners, which [`fan`] must cover instead.
pub fn triangulate(polygon: &[Vec3]) -> Option<Vec<[usize; 3]>> {
    let n = polygon.len();
    if n < 3 {
        return Some(Vec::new());
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
    let convex = (0..n).all(|i| convex_at(polygon[i], polygon[(i + 1) % n], polygon[(i + 2) % n]));
    if n == 4 && convex {
        // A convex quad splits along its shorter diagonal: the closer fit to a curved
        // (non-planar) quad, and the same split whichever corner the quad starts at. When
        // the diagonals are equal to 0.1 % (the isosceles trapezoids of a UV sphere or a
        // cylinder) neither fits better, and the quad splits from its first corner as
        // Blender does for Cycles, so that smooth shading interpolates as in Blender.
        let short_02 = polygon[0].distance_squared(polygon[2])
            <= polygon[1].distance_squared(polygon[3]) * 1.002;
        return Some(if short_02 {
            vec![[0, 1, 2], [0, 2, 3]]
        } else {
            vec![[1, 2, 3], [1, 3, 0]]
        });
    }
    if n == 3 || convex {
        return Some(fan(n));
    }
    if n > MAX_EAR_CLIPPED_CORNERS {
        return None;
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
    let triangles = corners
        .chunks_exact(3)
        .map(|t| {
            let [a, b, c] = [t[0] as usize, t[1] as usize, t[2] as usize];
            let facing = (polygon[b] - polygon[a])
                .cross(polygon[c] - polygon[a])
                .dot(normal);
            if facing < 0.0 { [a, c, b] } else { [a, b, c] }
        })
        .collect();
    Some(triangles)
}

/// The fan from corner 0 over an `n`-gon: exact for convex polygons.
pub fn fan(n: usize) -> Vec<[usize; 3]> {
    (1..n.saturating_sub(1)).map(|i| [0, i, i + 1]).collect()
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
        assert_eq!(triangulate(&square), Some(vec![[0, 1, 2], [0, 2, 3]]));
        // An L shape (area 3) whose fan from corner 0 would cover the notch.
        let l = [
            Vec3::new(1.0, 1.0, 0.0),
            Vec3::new(2.0, 1.0, 0.0),
            Vec3::new(2.0, 2.0, 0.0),
            Vec3::new(0.0, 2.0, 0.0),
            Vec3::new(0.0, 0.0, 0.0),
            Vec3::new(1.0, 0.0, 0.0),
        ];
        let tris = triangulate(&l).unwrap();
        assert_eq!(tris.len(), 4);
        assert!((area(&l, &tris) - 3.0).abs() < 1e-6, "{tris:?}");
        // Every triangle keeps the polygon's orientation (positive area).
        assert!(tris.iter().all(|t| area(&l, &[*t]) > 0.0), "{tris:?}");
    }

    /// A star whose alternating radii make every other corner reflex.
    fn star(n: usize) -> Vec<Vec3> {
        (0..n)
            .map(|i| {
                let angle = std::f64::consts::TAU * i as f64 / n as f64;
                let r = if i % 2 == 0 { 1.0 } else { 0.9 };
                Vec3::new((r * angle.cos()) as f32, (r * angle.sin()) as f32, 0.0)
            })
            .collect()
    }

    #[test]
    fn large_concave_polygons_are_ear_clipped_up_to_the_limit() {
        let n = 4096;
        let star = star(n);
        let expected: f32 = (0..n)
            .map(|i| 0.5 * star[i].cross(star[(i + 1) % n]).z)
            .sum();
        let tris = triangulate(&star).unwrap();
        assert_eq!(tris.len(), n - 2);
        let got = area(&star, &tris);
        assert!(
            (got - expected).abs() < 1e-4 * expected,
            "{got} vs {expected}"
        );
        assert!(triangulate(&self::star(MAX_EAR_CLIPPED_CORNERS + 2)).is_none());
        assert_eq!(fan(5), vec![[0, 1, 2], [0, 2, 3], [0, 3, 4]]);
    }
}
