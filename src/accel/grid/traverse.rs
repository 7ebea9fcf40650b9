//! Ray traversal: the 3D-DDA of Amanatides & Woo (1987), "A fast voxel traversal algorithm
//! for ray tracing", with two levels of empty-space skipping: an occupancy bit per cell
//! (so empty cells never touch the offset array) and one per macrocell of
//! `MACRO_CELLS`³ cells, which the walk crosses in a single step when it is empty.

use glam::IVec3;

use super::{Grid, GridHit, MACRO_SHIFT};
use crate::accel::Ray;
use crate::accel::frame::CellWalk;

/// Counts the work a traversal does, for the benchmark's statistics. The unit type counts
/// nothing and compiles away.
pub trait TraversalStats {
    /// One cell (or one skipped macrocell) stepped through.
    fn visit_cell(&mut self) {}
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
    /// Cells and skipped macrocells stepped through.
    pub cells: u64,
    /// Ray–triangle tests.
    pub tests: u64,
    /// Instances considered by the top level.
    pub instances: u64,
}

impl TraversalStats for TraversalCounts {
    fn visit_cell(&mut self) {
        self.cells += 1;
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
        // The nearest hit found so far, wherever it lies; it is the answer once it lies
        // within the cell being visited, since every later cell lies beyond that cell.
        let mut nearest: Option<GridHit> = None;
        let mut t_nearest = ray.t_max;
        self.walk(ray, stats, |grid, range, limit, stats| {
            for block in &grid.blocks[range] {
                stats.test_triangles(block.len());
                if let Some(hit) = block.nearest(ray, t_nearest) {
                    t_nearest = hit.t;
                    nearest = Some(GridHit {
                        t: hit.t,
                        u: hit.u,
                        v: hit.v,
                        triangle: hit.id,
                    });
                }
            }
            t_nearest <= limit
        });
        nearest
    }

    /// True when anything blocks `ray` within (`t_min`, `t_max`): for shadow rays.
    pub fn occluded(&self, ray: &Ray) -> bool {
        self.occluded_counting(ray, &mut ())
    }

    /// [`Grid::occluded`], reporting its work to `stats`.
    pub fn occluded_counting(&self, ray: &Ray, stats: &mut impl TraversalStats) -> bool {
        let mut blocked = false;
        self.walk(ray, stats, |grid, range, _limit, stats| {
            blocked = grid.blocks[range].iter().any(|block| {
                stats.test_triangles(block.len());
                block.any(ray, ray.t_max)
            });
            blocked
        });
        blocked
    }

    /// Walks the non-empty cells along `ray` in order, calling `visit` with where each cell's
    /// blocks lie in `blocks` and the largest hit parameter that belongs to the
    /// cell, until `visit` returns true or the ray leaves the grid.
    fn walk<S: TraversalStats>(
        &self,
        ray: &Ray,
        stats: &mut S,
        mut visit: impl FnMut(&Grid, std::ops::Range<usize>, f32, &mut S) -> bool,
    ) {
        if self.blocks.is_empty() {
            return;
        }
        let Some(mut walk) = self.frame.start_walk(ray) else {
            return;
        };
        loop {
            stats.visit_cell();
            if !self.macro_occupied(walk.cell) {
                if !self.skip_macrocell(&mut walk, ray) {
                    return;
                }
                continue;
            }
            let exit = walk.exit();
            if let Some(range) = self.cell_range(self.cell_index(walk.cell.as_uvec3())) {
                // Only hits inside the cell count; the last cell takes all up to the grid's end.
                if visit(self, range, exit.t, stats) {
                    return;
                }
            }
            if exit.last {
                return;
            }
            walk.advance(exit);
        }
    }

    /// Moves the walk past the empty macrocell holding its current cell, to the first cell of
    /// the next macrocell along the ray. False when the ray leaves the grid first.
    fn skip_macrocell(&self, walk: &mut CellWalk, ray: &Ray) -> bool {
        let res = self.frame.resolution.as_ivec3();
        let macro_lo = (walk.cell >> MACRO_SHIFT) << MACRO_SHIFT;
        let macro_hi = (macro_lo + IVec3::splat((1 << MACRO_SHIFT) - 1)).min(res - 1);
        let mut axis = 0;
        let mut t_exit = f32::INFINITY;
        for a in 0..3 {
            let face = if walk.step[a] > 0 {
                macro_hi[a] + 1
            } else {
                macro_lo[a]
            };
            let t = walk.face_t(a, face);
            if t < t_exit {
                t_exit = t;
                axis = a;
            }
        }
        if t_exit >= walk.t_end {
            return false;
        }
        let next = if walk.step[axis] > 0 {
            macro_hi[axis] + 1
        } else {
            macro_lo[axis] - 1
        };
        if next < 0 || next >= res[axis] {
            return false;
        }
        // The other axes: the cell under the exit point, kept within the macrocell and never
        // behind the current cell, so rounding cannot move the walk backwards or sideways.
        let p = ray.at(t_exit);
        for a in 0..3 {
            if a == axis {
                walk.cell[a] = next;
            } else if walk.step[a] != 0 {
                let c = ((p[a] - self.frame.bounds.min[a]) * self.frame.inv_cell_size[a]).floor()
                    as i32;
                walk.cell[a] = if walk.step[a] > 0 {
                    c.clamp(walk.cell[a], macro_hi[a])
                } else {
                    c.clamp(macro_lo[a], walk.cell[a])
                };
            }
            walk.refresh(a);
        }
        true
    }
}
