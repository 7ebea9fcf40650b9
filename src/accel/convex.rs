//! Convex meshes, whose own surface a ray leaving them outward cannot meet again.
//!
//! A mesh all of whose corners lie on or behind the plane of every one of its triangles
//! (the plane's front being the winding's) lies in the back half-space of each: a ray that
//! starts on a triangle and goes to its front never comes back to the mesh, so the top
//! level need not ask the mesh's grid (a mirror ball's reflections, light leaving a glass
//! ball). The same holds for the back side of a mesh all of whose corners lie on or in
//! front of every plane, and for both sides of a flat mesh. The property is kept by any
//! affine placement: the renderer's geometric normal is the object-space one carried by the
//! normal matrix, so the sides it names are the object-space sides.

use glam::{Vec3, Vec4};

/// Past this many corner–plane tests a mesh is not examined (it is taken as not convex):
/// the test costs milliseconds up to here and most meshes fail it within their first
/// triangles.
const MAX_TESTS: usize = 1 << 24;

/// The sides of a mesh's triangles from which a ray cannot meet the mesh again.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct ConvexSides {
    /// Every corner lies on or behind every triangle's plane.
    pub front: bool,
    /// Every corner lies on or in front of every triangle's plane.
    pub back: bool,
}

/// The surface a ray starts on: the instance it leaves, and whether it leaves towards the
/// front of the triangle's geometric normal.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Leaving {
    /// Index into [`crate::scene::Scene::instances`].
    pub instance: u32,
    /// The ray goes to the side the winding calls front.
    pub front: bool,
}

impl ConvexSides {
    /// True when a ray leaving by `front` cannot meet the mesh again.
    #[inline(always)]
    pub fn left_behind(self, front: bool) -> bool {
        if front { self.front } else { self.back }
    }
}

/// Which sides of the mesh (`positions`, `indices`) rays leave for good. A corner counts as
/// on a plane within a few ulps of the mesh's largest coordinate, so a tessellated sphere
/// whose flat quads were rounded to `f32` still counts as convex; a hit that tolerance
/// gives up lies within it of the ray's start, where the ray's own offset already rules
/// hits out. Degenerate triangles (no plane) say nothing.
pub fn convex_sides(positions: &[Vec3], indices: &[[u32; 3]]) -> ConvexSides {
    let none = ConvexSides::default();
    if indices.is_empty() || indices.len().saturating_mul(positions.len()) > MAX_TESTS {
        return none;
    }
    let largest = positions
        .iter()
        .map(|p| p.abs().max_element())
        .fold(0.0f32, f32::max);
    if !largest.is_finite() {
        return none;
    }
    // Heights are computed in `f32` from each corner's offset to the plane's first corner:
    // each offset is rounded by at most ε·2·largest and the dot product adds 3ε of it, so
    // the error stays below 8ε·largest, half the tolerance.
    let tolerance = 16.0 * f32::EPSILON * largest;
    // Each distinct corner once (exported meshes repeat a corner for every normal or UV
    // seam it has, often six times over), its coordinates in three arrays of four lanes
    // (the last padded with a repeat), so the loop over them runs in SIMD lanes (`Vec4`).
    let mut distinct: Vec<[u32; 3]> = positions
        .iter()
        .map(|p| p.to_array().map(f32::to_bits))
        .collect();
    distinct.sort_unstable();
    distinct.dedup();
    let lanes = |k: usize| -> Vec<Vec4> {
        let mut values: Vec<f32> = distinct.iter().map(|p| f32::from_bits(p[k])).collect();
        values.resize(distinct.len().next_multiple_of(4), values[0]);
        values.chunks_exact(4).map(Vec4::from_slice).collect()
    };
    let (xs, ys, zs) = (lanes(0), lanes(1), lanes(2));
    let (mut front, mut back) = (true, true);
    for triangle in indices {
        let corner = |k: usize| positions.get(triangle[k] as usize).copied();
        let (Some(a), Some(b), Some(c)) = (corner(0), corner(1), corner(2)) else {
            return none;
        };
        let Some(n) = (b - a).cross(c - a).try_normalize() else {
            continue;
        };
        let (mut highest, mut lowest) = (Vec4::NEG_INFINITY, Vec4::INFINITY);
        for i in 0..xs.len() {
            let height = (xs[i] - a.x) * n.x + (ys[i] - a.y) * n.y + (zs[i] - a.z) * n.z;
            highest = highest.max(height);
            lowest = lowest.min(height);
        }
        front &= highest.max_element() <= tolerance;
        back &= lowest.min_element() >= -tolerance;
        if !front && !back {
            return none;
        }
    }
    ConvexSides { front, back }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// An octahedron of radius 1 with outward winding.
    fn octahedron() -> (Vec<Vec3>, Vec<[u32; 3]>) {
        let corners = vec![Vec3::X, -Vec3::X, Vec3::Y, -Vec3::Y, Vec3::Z, -Vec3::Z];
        let faces = vec![
            [0, 2, 4],
            [2, 1, 4],
            [1, 3, 4],
            [3, 0, 4],
            [2, 0, 5],
            [1, 2, 5],
            [3, 1, 5],
            [0, 3, 5],
        ];
        (corners, faces)
    }

    #[test]
    fn an_outward_octahedron_is_left_behind_from_its_front_only() {
        let (corners, faces) = octahedron();
        let sides = convex_sides(&corners, &faces);
        assert_eq!(
            sides,
            ConvexSides {
                front: true,
                back: false
            }
        );
        // Wound the other way, the same shape is left behind from its back.
        let flipped: Vec<[u32; 3]> = faces.iter().map(|&[a, b, c]| [a, c, b]).collect();
        assert_eq!(
            convex_sides(&corners, &flipped),
            ConvexSides {
                front: false,
                back: true
            }
        );
    }

    #[test]
    fn a_flat_mesh_is_left_behind_from_both_sides_and_a_dented_one_from_neither() {
        let square = [
            Vec3::new(-1.0, 0.0, -1.0),
            Vec3::new(1.0, 0.0, -1.0),
            Vec3::new(1.0, 0.0, 1.0),
            Vec3::new(-1.0, 0.0, 1.0),
        ];
        let both = ConvexSides {
            front: true,
            back: true,
        };
        assert_eq!(convex_sides(&square, &[[0, 1, 2], [0, 2, 3]]), both);
        // An octahedron with one corner pushed inside is not convex either way.
        let (mut corners, faces) = octahedron();
        corners[4] = Vec3::new(0.0, 0.0, -0.5);
        assert_eq!(convex_sides(&corners, &faces), ConvexSides::default());
        // Two walls at a right angle (a room's corner seen from inside) are not either.
        let corner = [
            Vec3::new(0.0, 0.0, 0.0),
            Vec3::new(1.0, 0.0, 0.0),
            Vec3::new(1.0, 1.0, 0.0),
            Vec3::new(0.0, 0.0, 1.0),
            Vec3::new(0.0, 1.0, 1.0),
            Vec3::new(0.0, 1.0, 0.0),
        ];
        let walls = [[0, 1, 2], [0, 2, 5], [0, 5, 4], [0, 4, 3]];
        let sides = convex_sides(&corner, &walls);
        assert!(!sides.front || !sides.back, "{sides:?}");
    }

    /// A UV sphere as a modeller makes one (corners from `sin`/`cos` in `f32`, each flat
    /// quad split in two) counts as convex despite rounding; moved a hundredth of its
    /// radius inward at one corner, it does not.
    #[test]
    fn a_rounded_uv_sphere_counts_as_convex_and_a_dented_one_does_not() {
        let (rings, segments) = (16u32, 32u32);
        let mut corners = Vec::new();
        for r in 0..=rings {
            // The poles exactly on the axis, as a modeller places them (f32's sin π is not 0).
            let theta = std::f32::consts::PI * r as f32 / rings as f32;
            let theta_sin = if r == 0 || r == rings {
                0.0
            } else {
                theta.sin()
            };
            for s in 0..segments {
                let phi = std::f32::consts::TAU * s as f32 / segments as f32;
                corners.push(
                    Vec3::new(theta_sin * phi.cos(), theta.cos(), theta_sin * phi.sin()) * 3.7
                        + Vec3::new(10.0, -2.0, 5.0),
                );
            }
        }
        let at = |r: u32, s: u32| r * segments + s % segments;
        let mut faces = Vec::new();
        for r in 0..rings {
            for s in 0..segments {
                let quad = [at(r, s), at(r, s + 1), at(r + 1, s + 1), at(r + 1, s)];
                faces.push([quad[0], quad[1], quad[2]]);
                faces.push([quad[0], quad[2], quad[3]]);
            }
        }
        let sides = convex_sides(&corners, &faces);
        assert!(sides.front != sides.back, "{sides:?}");
        let centre = Vec3::new(10.0, -2.0, 5.0);
        let k = (rings / 2 * segments + 3) as usize;
        corners[k] = centre + (corners[k] - centre) * 0.99;
        assert_eq!(convex_sides(&corners, &faces), ConvexSides::default());
    }

    #[test]
    fn indices_out_of_range_and_huge_meshes_are_not_taken_as_convex() {
        let (corners, _) = octahedron();
        assert_eq!(convex_sides(&corners, &[[0, 2, 9]]), ConvexSides::default());
        let many = vec![Vec3::ZERO; 1 << 13];
        let faces = vec![[0, 1, 2]; 1 << 12];
        assert_eq!(convex_sides(&many, &faces), ConvexSides::default());
    }
}
