//! Grid construction: resolution, then count → prefix sum → fill into compact cell storage.

use glam::{UVec3, Vec3};

use super::overlap::triangle_overlaps_box;
use super::{DEFAULT_DENSITY, Grid};
use crate::accel::Triangle;
use crate::scene::Aabb;

/// Most cells along one axis.
const MAX_RESOLUTION: u32 = 1024;
/// Most cells in one grid (512 MiB of offsets would be absurd for any mesh we render).
const MAX_CELLS: u64 = 1 << 27;

impl Grid {
    /// Builds a grid over `triangles` with the default density.
    pub fn build(triangles: Vec<Triangle>) -> Grid {
        Grid::build_with_density(triangles, DEFAULT_DENSITY)
    }

    /// Builds a grid with about `density` cells per triangle.
    ///
    /// Degenerate triangles (no area, or non-finite corners) are kept in the triangle list,
    /// so indices still match the mesh, but go into no cell and so are never hit.
    pub fn build_with_density(triangles: Vec<Triangle>, density: f32) -> Grid {
        let live: Vec<u32> = (0..triangles.len() as u32)
            .filter(|&i| !triangles[i as usize].is_degenerate())
            .collect();
        let tight = live
            .iter()
            .fold(Aabb::EMPTY, |b, &i| b.union(triangles[i as usize].bounds()));
        if tight.is_empty() {
            return Grid::empty(triangles);
        }
        let bounds = padded(tight);
        let resolution = resolution(bounds.extent(), live.len(), density);
        let cell_size = bounds.extent() / resolution.as_vec3();
        let mut grid = Grid {
            bounds,
            resolution,
            cell_size,
            inv_cell_size: cell_size.recip(),
            cell_start: Vec::new(),
            references: Vec::new(),
            triangles,
        };
        grid.insert(&live);
        grid
    }

    fn empty(triangles: Vec<Triangle>) -> Grid {
        Grid {
            bounds: Aabb {
                min: Vec3::ZERO,
                max: Vec3::ONE,
            },
            resolution: UVec3::ONE,
            cell_size: Vec3::ONE,
            inv_cell_size: Vec3::ONE,
            cell_start: vec![0, 0],
            references: Vec::new(),
            triangles,
        }
    }

    /// Fills the compact cell storage in two passes over the triangles (count, then place).
    fn insert(&mut self, live: &[u32]) {
        let cells = (self.resolution.x * self.resolution.y * self.resolution.z) as usize;
        let mut counts = vec![0u32; cells + 1];
        for &t in live {
            self.for_each_overlapped_cell(t, |cell| counts[cell] += 1);
        }
        // Exclusive prefix sum: counts becomes the start offset of each cell.
        let mut total = 0u32;
        for c in counts.iter_mut() {
            let n = *c;
            *c = total;
            total += n;
        }
        let mut next = counts.clone();
        let mut references = vec![0u32; total as usize];
        for &t in live {
            self.for_each_overlapped_cell(t, |cell| {
                references[next[cell] as usize] = t;
                next[cell] += 1;
            });
        }
        self.cell_start = counts;
        self.references = references;
    }

    /// Calls `f` with the index of every cell the triangle overlaps.
    fn for_each_overlapped_cell(&self, t: u32, mut f: impl FnMut(usize)) {
        // Pad cells a little so rounding never drops a cell the triangle touches: a triangle
        // lying on a cell face belongs to the cells on both sides.
        let magnitude = self
            .bounds
            .min
            .abs()
            .max(self.bounds.max.abs())
            .max_element();
        let pad = self.cell_size * 1e-4 + Vec3::splat(magnitude * 1e-6);
        let tri = self.triangles[t as usize];
        let b = tri.bounds();
        let lo = self.cell_of(b.min - pad);
        let hi = self.cell_of(b.max + pad);
        if lo == hi {
            f(self.cell_index(lo));
            return;
        }
        let half = 0.5 * self.cell_size + pad;
        let vertices = tri.vertices();
        for z in lo.z..=hi.z {
            for y in lo.y..=hi.y {
                for x in lo.x..=hi.x {
                    let c = UVec3::new(x, y, z);
                    let center = self.bounds.min + (c.as_vec3() + 0.5) * self.cell_size;
                    if triangle_overlaps_box(vertices, center, half) {
                        f(self.cell_index(c));
                    }
                }
            }
        }
    }

    /// The cell holding point `p`, clamped into the grid.
    pub(super) fn cell_of(&self, p: Vec3) -> UVec3 {
        let c = ((p - self.bounds.min) * self.inv_cell_size).floor();
        c.max(Vec3::ZERO).as_uvec3().min(self.resolution - 1)
    }
}

/// The box grown by a small fraction of its size, so flat meshes get a volume and no
/// triangle lies exactly on the boundary.
fn padded(b: Aabb) -> Aabb {
    let e = b.extent();
    let pad = Vec3::splat(
        e.max_element() * 1e-5
            + 1e-7 * b.min.abs().max(b.max.abs()).max_element()
            + f32::MIN_POSITIVE,
    );
    Aabb {
        min: b.min - pad,
        max: b.max + pad,
    }
}

/// Cells per axis after Cleary & Wyvill (1988): R_a = d_a · ∛(λN / V), which makes cells
/// near-cubic. In V, thin axes count as at least the cube-root cell size of the longest
/// axis, so that a flat mesh (a wall, a floor) gets about λN cells in its plane and one
/// across it, instead of a vast number of slivers.
fn resolution(extent: Vec3, triangles: usize, density: f32) -> UVec3 {
    let target = (density * triangles as f32).max(1.0);
    let floor = extent.max_element() / target.cbrt();
    let e = extent.max(Vec3::splat(floor));
    let k = (target / (e.x * e.y * e.z)).cbrt();
    let mut r = (extent * k)
        .floor()
        .max(Vec3::ONE)
        .min(Vec3::splat(MAX_RESOLUTION as f32))
        .as_uvec3();
    while r.x as u64 * r.y as u64 * r.z as u64 > MAX_CELLS {
        r = (r.as_vec3() * 0.9).max(Vec3::ONE).as_uvec3();
    }
    r
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn resolution_follows_density_and_aspect() {
        let r = resolution(Vec3::new(2.0, 1.0, 1.0), 1000, 5.0);
        let cells = r.x * r.y * r.z;
        assert!((2500..=5000).contains(&cells), "{r}");
        assert!(r.x >= 2 * r.y - 1, "{r}");
    }

    #[test]
    fn flat_meshes_get_few_cells() {
        let r = resolution(Vec3::new(2.0, 1e-5, 2.0), 2, 5.0);
        assert_eq!(r.y, 1);
        assert!(r.x * r.z <= 16, "{r}");
        let r = resolution(Vec3::new(2.0, 4e-5, 2.0), 800, 5.0);
        assert_eq!(r.y, 1, "{r}");
        assert!((1000..=4000).contains(&(r.x * r.z)), "{r}");
    }
}
