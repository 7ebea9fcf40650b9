//! Ray traversal of the irregular grid (Pérard-Gayot, Kalojanov & Slusallek 2017): the
//! walk looks up the cell of its current voxel, tests the cell's blocks eight triangles at
//! a time, and leaves through the face of the cell's (expanded) box the ray reaches first,
//! into the voxel beyond it; face parameters come from integer voxel coordinates as in the
//! 3D-DDA of Amanatides & Woo (1987). A hit is accepted once it lies within a cell the walk
//! has reached. A grid of one cell is not walked: its blocks are tested at once.

use glam::{IVec3, UVec3};

use super::{Grid, GridHit};
use crate::accel::Ray;
use crate::accel::frame::CellWalk;

/// Counts the work a traversal does, for the benchmark's statistics. The unit type counts
/// nothing and compiles away.
pub trait TraversalStats {
    /// One cell (or one skipped stretch of empty macrocells) stepped through.
    fn visit_cell(&mut self) {}
    /// One occupied cell reached (its triangles are then tested).
    fn visit_occupied(&mut self) {}
    /// Ray–triangle tests (the triangles of one block, tested together).
    fn test_triangles(&mut self, _count: usize) {}
    /// One instance considered by the top level (its bounding box tested, and its grid
    /// walked if that is hit).
    fn test_instance(&mut self) {}
}

impl TraversalStats for () {}

/// Cells visited and triangles tested, summed over rays.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct TraversalCounts {
    /// Cells and skipped stretches of empty macrocells stepped through.
    pub cells: u64,
    /// Occupied cells reached.
    pub occupied: u64,
    /// Ray–triangle tests.
    pub tests: u64,
    /// Instances considered by the top level.
    pub instances: u64,
}

impl TraversalStats for TraversalCounts {
    fn visit_cell(&mut self) {
        self.cells += 1;
    }
    fn visit_occupied(&mut self) {
        self.occupied += 1;
    }
    fn test_triangles(&mut self, count: usize) {
        self.tests += count as u64;
    }
    fn test_instance(&mut self) {
        self.instances += 1;
    }
}

impl Grid {
    /// The closest hit along `ray`, if any.
    pub fn intersect(&self, ray: &Ray) -> Option<GridHit> {
        self.intersect_counting(ray, &mut ())
    }

    /// [`Grid::intersect`], reporting its work to `stats`.
    pub fn intersect_counting(
        &self,
        ray: &Ray,
        stats: &mut impl TraversalStats,
    ) -> Option<GridHit> {
        #[cfg(target_arch = "x86_64")]
        if std::is_x86_feature_detected!("avx2") {
            // SAFETY: the processor has AVX2, checked just above.
            return unsafe { self.intersect_avx2(ray, stats) };
        }
        self.intersect_portable(ray, stats)
    }

    /// [`Grid::intersect_portable`] compiled for AVX2, where a block's eight lanes are one
    /// vector (the arithmetic, and so the answer, is the same).
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    fn intersect_avx2(&self, ray: &Ray, stats: &mut impl TraversalStats) -> Option<GridHit> {
        self.intersect_portable(ray, stats)
    }

    #[inline(always)]
    fn intersect_portable(&self, ray: &Ray, stats: &mut impl TraversalStats) -> Option<GridHit> {
        // The nearest hit found so far, wherever it lies; it is the answer once it lies
        // within the cell being visited, since every later cell lies beyond that cell.
        let mut nearest: Option<GridHit> = None;
        let mut t_nearest = ray.t_max;
        let mut cells = self.occupied_cells(ray);
        while let Some((range, limit)) = cells.next(stats, t_nearest) {
            for block in &self.blocks[range] {
                stats.test_triangles(block.len());
                if let Some(hit) = block.nearest(ray, t_nearest) {
                    t_nearest = hit.t;
                    nearest = Some(hit.into());
                }
            }
            if t_nearest <= limit {
                break;
            }
        }
        nearest
    }

    /// True when anything blocks `ray` within (`t_min`, `t_max`): for shadow rays.
    pub fn occluded(&self, ray: &Ray) -> bool {
        self.occluded_counting(ray, &mut ())
    }

    /// [`Grid::occluded`], reporting its work to `stats`.
    pub fn occluded_counting(&self, ray: &Ray, stats: &mut impl TraversalStats) -> bool {
        #[cfg(target_arch = "x86_64")]
        if std::is_x86_feature_detected!("avx2") {
            // SAFETY: the processor has AVX2, checked just above.
            return unsafe { self.occluded_avx2(ray, stats) };
        }
        self.occluded_portable(ray, stats)
    }

    /// [`Grid::occluded_portable`] compiled for AVX2.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    fn occluded_avx2(&self, ray: &Ray, stats: &mut impl TraversalStats) -> bool {
        self.occluded_portable(ray, stats)
    }

    #[inline(always)]
    fn occluded_portable(&self, ray: &Ray, stats: &mut impl TraversalStats) -> bool {
        let mut cells = self.occupied_cells(ray);
        while let Some((range, _)) = cells.next(stats, ray.t_max) {
            for block in &self.blocks[range] {
                stats.test_triangles(block.len());
                if block.any(ray, ray.t_max) {
                    return true;
                }
            }
        }
        false
    }

    /// The occupied cells along `ray`, front to back.
    #[inline(always)]
    fn occupied_cells<'a>(&'a self, ray: &'a Ray) -> OccupiedCells<'a> {
        let single_cell = self.frame.resolution == UVec3::ONE;
        let walk = if self.blocks.is_empty() || single_cell {
            None
        } else {
            self.frame.start_walk(ray)
        };
        OccupiedCells {
            grid: self,
            ray,
            walk,
            single_cell: single_cell && !self.blocks.is_empty(),
        }
    }
}

/// The occupied cells along a ray, front to back (a cursor rather than an iterator, so the
/// caller's statistics can ride along).
struct OccupiedCells<'a> {
    grid: &'a Grid,
    ray: &'a Ray,
    /// `None` once the ray has left the grid.
    walk: Option<CellWalk>,
    /// True until the one cell of a single-cell grid has been given out: such a grid is not
    /// walked (a few triangles are tested faster all at once than found by a walk).
    single_cell: bool,
}

impl OccupiedCells<'_> {
    /// Where the next occupied cell's blocks lie in `blocks`, and the largest hit parameter
    /// that belongs to the cell (the last cell takes all up to the grid's end); `None` when
    /// the ray leaves the grid, or when a hit at `t_nearest` already found is the nearest
    /// (it lies within a cell the walk has reached).
    #[inline(always)]
    fn next(
        &mut self,
        stats: &mut impl TraversalStats,
        t_nearest: f32,
    ) -> Option<(std::ops::Range<usize>, f32)> {
        let grid = self.grid;
        if self.single_cell {
            self.single_cell = false;
            // Every hit belongs to the one cell.
            return Some((0..grid.blocks.len(), f32::INFINITY));
        }
        let walk = self.walk.as_mut()?;
        let frame = &grid.frame;
        let resolution = frame.resolution.as_ivec3();
        loop {
            stats.visit_cell();
            let cell = grid.cells.cell_at(walk.cell);
            let (lo, hi) = (
                IVec3::from_array(cell.lo.map(i32::from)),
                IVec3::from_array(cell.hi.map(i32::from)),
            );
            // The ray leaves the cell's box by the face it reaches first.
            let mut axis = 0;
            let mut t_exit = f32::INFINITY;
            for a in 0..3 {
                let face = if walk.step[a] > 0 { hi[a] + 1 } else { lo[a] };
                let t = walk.face_t(a, face);
                if t < t_exit {
                    t_exit = t;
                    axis = a;
                }
            }
            let next = if walk.step[axis] > 0 {
                hi[axis] + 1
            } else {
                lo[axis] - 1
            };
            let last = t_exit >= walk.t_end || next < 0 || next >= resolution[axis];
            let limit = if last { walk.t_end } else { t_exit };
            let blocks = cell.blocks();
            let occupied = !blocks.is_empty();
            if occupied {
                stats.visit_occupied();
            }
            if last {
                self.walk = None;
                return occupied.then_some((blocks, limit));
            }
            // The voxel beyond the exit face: on the other axes, the one under the exit
            // point, kept within the box and never behind the current voxel, so rounding
            // cannot move the walk backwards or sideways (each step leaves the box).
            let p = self.ray.at(t_exit);
            for a in 0..3 {
                if a == axis {
                    walk.cell[a] = next;
                } else if walk.step[a] != 0 {
                    let c = ((p[a] - frame.bounds.min[a]) * frame.inv_cell_size[a]).floor() as i32;
                    walk.cell[a] = if walk.step[a] > 0 {
                        c.clamp(walk.cell[a], hi[a])
                    } else {
                        c.clamp(lo[a], walk.cell[a])
                    };
                }
            }
            if occupied {
                return Some((blocks, limit));
            }
            if t_nearest <= limit {
                self.walk = None;
                return None;
            }
        }
    }
}
