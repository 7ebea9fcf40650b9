//! Ray traversal: the 3D-DDA of Amanatides & Woo (1987), "A fast voxel traversal algorithm
//! for ray tracing", with two levels of empty-space skipping: an occupancy bit per cell
//! (so empty cells never touch the offset array) and one per macrocell of
//! `MACRO_CELLS`³ cells, which the walk crosses in a single step when it is empty.

use glam::{IVec3, Vec3};

use super::{Grid, GridHit, MACRO_SHIFT};
use crate::accel::Ray;

/// Counts the work a traversal does, for the benchmark's statistics. The unit type counts
/// nothing and compiles away.
pub trait TraversalStats {
    /// One cell (or one skipped macrocell) stepped through.
    fn visit_cell(&mut self) {}
    /// One ray–triangle test.
    fn test_triangle(&mut self) {}
}

impl TraversalStats for () {}

/// Cells visited and triangles tested, summed over rays.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct TraversalCounts {
    /// Cells and skipped macrocells stepped through.
    pub cells: u64,
    /// Ray–triangle tests.
    pub tests: u64,
}

impl TraversalStats for TraversalCounts {
    fn visit_cell(&mut self) {
        self.cells += 1;
    }
    fn test_triangle(&mut self) {
        self.tests += 1;
    }
}

/// The walk of one ray through the cells it crosses, front to back.
struct CellWalk {
    /// Current cell.
    cell: IVec3,
    /// −1, 0 or +1 per axis.
    step: IVec3,
    /// The ray crosses the plane of cell face `k` on axis `a` at `t = slope[a]·k + offset[a]`:
    /// face distances come from integer coordinates, so no error accumulates.
    slope: Vec3,
    offset: Vec3,
    /// Ray parameter at which the ray leaves the current cell, per axis.
    t_next: Vec3,
    /// Ray parameter at which the ray leaves the grid (or reaches `t_max`).
    t_end: f32,
}

impl CellWalk {
    /// Parameter of the current cell's far face on `axis` (∞ if the ray is parallel to it).
    #[inline]
    fn face_t(&self, axis: usize, face: i32) -> f32 {
        if self.step[axis] == 0 {
            f32::INFINITY
        } else {
            self.slope[axis] * face as f32 + self.offset[axis]
        }
    }

    #[inline]
    fn far_face(&self, axis: usize) -> i32 {
        self.cell[axis] + i32::from(self.step[axis] > 0)
    }

    #[inline]
    fn refresh(&mut self, axis: usize) {
        self.t_next[axis] = self.face_t(axis, self.far_face(axis));
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
            for k in range {
                let id = grid.cell_triangle_ids[k];
                stats.test_triangle();
                if let Some(hit) = grid.cell_triangle(k).intersect(ray, t_nearest) {
                    t_nearest = hit.t;
                    nearest = Some(GridHit {
                        t: hit.t,
                        u: hit.u,
                        v: hit.v,
                        triangle: id,
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
            blocked = range.into_iter().any(|k| {
                stats.test_triangle();
                grid.cell_triangle(k).intersect(ray, ray.t_max).is_some()
            });
            blocked
        });
        blocked
    }

    /// Walks the non-empty cells along `ray` in order, calling `visit` with where each cell's
    /// triangles lie in `cell_corners` and the largest hit parameter that belongs to the
    /// cell, until `visit` returns true or the ray leaves the grid.
    fn walk<S: TraversalStats>(
        &self,
        ray: &Ray,
        stats: &mut S,
        mut visit: impl FnMut(&Grid, std::ops::Range<usize>, f32, &mut S) -> bool,
    ) {
        let Some(mut walk) = self.start_walk(ray) else {
            return;
        };
        let res = self.resolution.as_ivec3();
        loop {
            stats.visit_cell();
            if !self.macro_occupied(walk.cell) {
                if !self.skip_macrocell(&mut walk, ray) {
                    return;
                }
                continue;
            }
            let axis = exit_axis(walk.t_next);
            let t_exit = walk.t_next[axis];
            let next = walk.cell[axis] + walk.step[axis];
            let last =
                walk.step[axis] == 0 || next < 0 || next >= res[axis] || t_exit >= walk.t_end;
            if let Some(range) = self.cell_range(self.cell_index(walk.cell.as_uvec3())) {
                // Only hits inside the cell count; the last cell takes all up to the grid's end.
                let limit = if last { walk.t_end } else { t_exit };
                if visit(self, range, limit, stats) {
                    return;
                }
            }
            if last {
                return;
            }
            walk.cell[axis] = next;
            walk.refresh(axis);
        }
    }

    /// Moves the walk past the empty macrocell holding its current cell, to the first cell of
    /// the next macrocell along the ray. False when the ray leaves the grid first.
    fn skip_macrocell(&self, walk: &mut CellWalk, ray: &Ray) -> bool {
        let res = self.resolution.as_ivec3();
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
                let c = ((p[a] - self.bounds.min[a]) * self.inv_cell_size[a]).floor() as i32;
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

    /// Clips the ray to the grid and finds the first cell; `None` when it misses the grid.
    fn start_walk(&self, ray: &Ray) -> Option<CellWalk> {
        if self.cell_corners.is_empty() || !(ray.origin.is_finite() && ray.direction.is_finite()) {
            return None;
        }
        let inv = ray.direction.recip();
        let t0 = (self.bounds.min - ray.origin) * inv;
        let t1 = (self.bounds.max - ray.origin) * inv;
        // f32::max/min skip NaN (0·∞ for an origin on a slab of a parallel axis).
        let near = t0.min(t1);
        // Widen each slab's exit by its rounding error, so a ray through the box is never
        // clipped away by rounding (pbrt-v4 §6.8.2: t_far·(1 + 2γ(3))).
        let far = t0.max(t1) * (1.0 + 2.0 * crate::accel::SLAB_ROUNDING);
        let t_start = ray.t_min.max(near.x).max(near.y).max(near.z);
        let t_end = ray.t_max.min(far.x).min(far.y).min(far.z);
        // Written so that a NaN bound also counts as a miss.
        if t_start > t_end || t_start.is_nan() || t_end.is_nan() {
            return None;
        }
        let cell = self.cell_of(ray.at(t_start)).as_ivec3();
        let step = IVec3::new(
            step_of(ray.direction.x),
            step_of(ray.direction.y),
            step_of(ray.direction.z),
        );
        let mut walk = CellWalk {
            cell,
            step,
            slope: self.cell_size * inv,
            offset: t0,
            t_next: Vec3::INFINITY,
            t_end,
        };
        for axis in 0..3 {
            walk.refresh(axis);
        }
        Some(walk)
    }
}

/// The axis whose cell face the ray crosses first.
#[inline]
fn exit_axis(t_next: Vec3) -> usize {
    if t_next.x <= t_next.y && t_next.x <= t_next.z {
        0
    } else if t_next.y <= t_next.z {
        1
    } else {
        2
    }
}

#[inline]
fn step_of(d: f32) -> i32 {
    if d > 0.0 {
        1
    } else if d < 0.0 {
        -1
    } else {
        0
    }
}
