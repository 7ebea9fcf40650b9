//! How many cells per triangle (λ in Cleary & Wyvill 1988) a mesh's grid gets.
//!
//! Coarse cells are faster where a mesh's triangles are spread evenly over its surface
//! (fewer, cheaper steps; the eight-wide block test makes a few more triangles per cell
//! cheap), and much slower where most of them crowd into a small part of the box — a
//! detailed object on a large floor, the uniform grid's weak case — because each of the
//! few cells over the detail then holds a great many. How crowded the triangles are is
//! measured before the build, at the coarse density: the centroid count of the cell an
//! average triangle sits in (Σ n² / Σ n over cells, exact in integers, so the choice is
//! the same on any thread count). At or below [`EVEN_CROWDING`] the mesh gets
//! [`EVEN_DENSITY`]; above it, the density that brings that count back to it on a surface
//! (counts per cell scale as λ^(−2/3), so λ grows as the count's excess to the power 3/2),
//! at most [`UNEVEN_DENSITY`].

use std::sync::atomic::{AtomicU32, Ordering};

use rayon::prelude::*;

use crate::accel::grid::build::mesh_triangles::MeshTriangles;
use crate::accel::grid::frame::{GridFrame, resolution};
use crate::accel::huge_pages;
use crate::geometry::Aabb;

/// λ for evenly spread triangles (the Stanford dragons of 11k and 203k triangles: 1.02–1.10×
/// the speed of λ = 5 on outside and bounce rays, 28–32 % less memory; README, "How it
/// works").
pub const EVEN_DENSITY: f32 = 2.0;

/// λ for the most crowded meshes, the density every mesh had before (the 203k dragon on a
/// floor ten times its size runs at 0.67–0.71× the speed with λ = 2).
pub const UNEVEN_DENSITY: f32 = 5.0;

/// Centroids in the cell of an average triangle, at [`EVEN_DENSITY`], up to which a mesh
/// counts as evenly spread. The dragons have 4.6 (11k triangles), 6.7 (48k), 10.3 (203k)
/// and 20.5 (871k: it grows as N^⅓, a surface's cells being N^⅔ of N); λ = 2 loses to
/// λ = 5 on bounce rays from about 19 (the 11k dragon on a floor three times its size:
/// 0.96×; the 203k dragon on one twice its size, 25.4: 0.97×; the 11k dragon on one five
/// times its size, 42.6: 0.85×).
pub const EVEN_CROWDING: f64 = 16.0;

/// The density for the live triangles of `triangles` (numbered in `live`) in `bounds`.
pub(in crate::accel::grid) fn density_for(
    bounds: Aabb,
    triangles: MeshTriangles,
    live: &[u32],
) -> f32 {
    let crowding = crowding(bounds, triangles, live);
    if crowding <= EVEN_CROWDING {
        return EVEN_DENSITY;
    }
    let wanted = EVEN_DENSITY as f64 * (crowding / EVEN_CROWDING).powf(1.5);
    wanted.min(UNEVEN_DENSITY as f64) as f32
}

/// Σ n² / Σ n over the cells of a grid of [`EVEN_DENSITY`] over `bounds`, n the number of
/// triangle centroids in a cell: the centroid count of an average triangle's cell.
pub(in crate::accel::grid) fn crowding(
    bounds: Aabb,
    triangles: MeshTriangles,
    live: &[u32],
) -> f64 {
    if live.is_empty() {
        return 0.0;
    }
    let frame = GridFrame::new(
        bounds,
        resolution(bounds.extent(), live.len(), EVEN_DENSITY),
    );
    let mut counts: Vec<AtomicU32> = huge_pages::vec_with_capacity(frame.cell_count());
    counts.extend((0..frame.cell_count()).map(|_| AtomicU32::new(0)));
    live.par_iter().for_each(|&t| {
        let triangle = triangles.get(t);
        let centroid = triangle.v0 + (triangle.e1 + triangle.e2) / 3.0;
        let cell = frame.cell_index(frame.cell_of(centroid));
        counts[cell].fetch_add(1, Ordering::Relaxed);
    });
    let (squares, total) = counts
        .par_iter()
        .map(|c| {
            let n = u64::from(c.load(Ordering::Relaxed));
            (n * n, n)
        })
        .reduce(|| (0, 0), |a, b| (a.0 + b.0, a.1 + b.1));
    squares as f64 / total.max(1) as f64
}

#[cfg(test)]
mod tests {
    use glam::Vec3;

    use super::*;
    use crate::accel::Triangle;
    use crate::accel::grid::build::soup;

    /// `f` of the triangles' bounds, the triangles as an indexed mesh, and their numbers
    /// (every one live).
    fn on_mesh<T>(triangles: &[Triangle], f: impl FnOnce(Aabb, MeshTriangles, &[u32]) -> T) -> T {
        let (vertices, indices) = soup(triangles);
        let live: Vec<u32> = (0..triangles.len() as u32).collect();
        let bounds = triangles
            .iter()
            .fold(Aabb::EMPTY, |b, t| b.union(t.bounds()));
        f(bounds, MeshTriangles::new(&vertices, &indices), &live)
    }

    /// The surface of the cube [−1, 1]³, each face cut into `n` × `n` squares split in two:
    /// triangles of one size, evenly spread.
    fn cube_surface(n: usize) -> Vec<Triangle> {
        let mut triangles = Vec::new();
        for axis in 0..3 {
            for side in [-1.0f32, 1.0] {
                let at = |i: usize, j: usize| {
                    let (u, v) = (
                        2.0 * i as f32 / n as f32 - 1.0,
                        2.0 * j as f32 / n as f32 - 1.0,
                    );
                    let mut p = Vec3::ZERO;
                    p[axis] = side;
                    p[(axis + 1) % 3] = u;
                    p[(axis + 2) % 3] = v;
                    p
                };
                for i in 0..n {
                    for j in 0..n {
                        let (a, b, c, d) = (at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1));
                        triangles.push(Triangle::new(a, b, c));
                        triangles.push(Triangle::new(a, c, d));
                    }
                }
            }
        }
        triangles
    }

    /// An evenly tessellated surface gets the coarse density; the same surface on a floor
    /// a hundred times its size (two triangles) gets the fine one.
    #[test]
    fn crowded_meshes_get_finer_cells() {
        let surface = cube_surface(60);
        assert_eq!(on_mesh(&surface, density_for), EVEN_DENSITY);
        let mut on_floor = surface.clone();
        let corner = |x: f32, z: f32| Vec3::new(x, -1.0, z);
        on_floor.push(Triangle::new(
            corner(-100.0, -100.0),
            corner(100.0, -100.0),
            corner(100.0, 100.0),
        ));
        on_floor.push(Triangle::new(
            corner(-100.0, -100.0),
            corner(100.0, 100.0),
            corner(-100.0, 100.0),
        ));
        let crowded = on_mesh(&on_floor, crowding);
        assert!(crowded > 4.0 * EVEN_CROWDING, "{crowded}");
        assert_eq!(on_mesh(&on_floor, density_for), UNEVEN_DENSITY);
    }

    /// Between the two, the density never falls as the floor grows, and ends above the
    /// coarse one.
    #[test]
    fn the_density_grows_with_the_crowding() {
        let mut previous = 0.0;
        for floor in [1.0f32, 2.0, 3.0, 4.0, 6.0, 10.0] {
            let mut mesh = cube_surface(40);
            let corner = |x: f32, z: f32| Vec3::new(x * floor, -1.0, z * floor);
            mesh.push(Triangle::new(
                corner(-1.0, -1.0),
                corner(1.0, -1.0),
                corner(1.0, 1.0),
            ));
            let density = on_mesh(&mesh, density_for);
            assert!(
                (EVEN_DENSITY..=UNEVEN_DENSITY).contains(&density),
                "{density}"
            );
            assert!(density >= previous, "floor {floor}: {density} < {previous}");
            previous = density;
        }
        assert!(previous > EVEN_DENSITY, "{previous}");
    }
}
