//! Ray traversal: Amanatides & Woo (1987), "A fast voxel traversal algorithm for ray tracing".

use glam::{IVec3, Vec3};

use super::{Grid, GridHit};
use crate::accel::Ray;

/// The walk of one ray through the cells it crosses, front to back.
struct CellWalk {
    /// Current cell.
    cell: IVec3,
    /// −1, 0 or +1 per axis.
    step: IVec3,
    /// Ray parameter at which the ray leaves the current cell, per axis.
    t_next: Vec3,
    /// Ray parameter at which the ray leaves the grid (or reaches `t_max`).
    t_end: f32,
}

impl Grid {
    /// The closest hit along `ray`, if any.
    pub fn intersect(&self, ray: &Ray) -> Option<GridHit> {
        let mut walk = self.start_walk(ray)?;
        let mut best: Option<GridHit> = None;
        loop {
            let (t_exit, last) = self.cell_exit(&walk);
            // A hit beyond this cell may be beaten by one in a later cell, so only hits
            // inside the cell count; the last cell takes everything up to the grid's end.
            let limit = if last {
                walk.t_end
            } else {
                t_exit.min(walk.t_end)
            };
            let mut t_best = best.map_or(ray.t_max, |h| h.t);
            for &index in self.cell(walk.cell.as_uvec3()) {
                if let Some(hit) = self.triangles[index as usize].intersect(ray, t_best)
                    && hit.t <= limit
                {
                    t_best = hit.t;
                    best = Some(GridHit {
                        t: hit.t,
                        u: hit.u,
                        v: hit.v,
                        triangle: index,
                    });
                }
            }
            if best.is_some() || last || t_exit >= walk.t_end {
                return best;
            }
            self.advance(&mut walk, ray);
        }
    }

    /// True when anything blocks `ray` within (`t_min`, `t_max`): for shadow rays.
    pub fn occluded(&self, ray: &Ray) -> bool {
        let Some(mut walk) = self.start_walk(ray) else {
            return false;
        };
        loop {
            if self.cell(walk.cell.as_uvec3()).iter().any(|&i| {
                self.triangles[i as usize]
                    .intersect(ray, ray.t_max)
                    .is_some()
            }) {
                return true;
            }
            let (t_exit, last) = self.cell_exit(&walk);
            if last || t_exit >= walk.t_end {
                return false;
            }
            self.advance(&mut walk, ray);
        }
    }

    /// Clips the ray to the grid and finds the first cell; `None` when it misses the grid.
    fn start_walk(&self, ray: &Ray) -> Option<CellWalk> {
        if self.references.is_empty() || !(ray.origin.is_finite() && ray.direction.is_finite()) {
            return None;
        }
        let inv = ray.direction.recip();
        let t0 = (self.bounds.min - ray.origin) * inv;
        let t1 = (self.bounds.max - ray.origin) * inv;
        // f32::max/min skip NaN (0·∞ for an origin on a slab of a parallel axis).
        let near = t0.min(t1);
        let far = t0.max(t1);
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
            t_next: Vec3::INFINITY,
            t_end,
        };
        for axis in 0..3 {
            walk.t_next[axis] = self.boundary_t(&walk, ray, axis);
        }
        Some(walk)
    }

    /// Ray parameter where the ray crosses the current cell's far face along `axis`,
    /// computed from integer coordinates so that error does not accumulate.
    #[inline]
    fn boundary_t(&self, walk: &CellWalk, ray: &Ray, axis: usize) -> f32 {
        let step = walk.step[axis];
        if step == 0 {
            return f32::INFINITY;
        }
        let face = walk.cell[axis] + i32::from(step > 0);
        let plane = self.bounds.min[axis] + face as f32 * self.cell_size[axis];
        (plane - ray.origin[axis]) / ray.direction[axis]
    }

    /// Where the ray leaves the current cell, and whether the next cell is outside the grid.
    #[inline]
    fn cell_exit(&self, walk: &CellWalk) -> (f32, bool) {
        let axis = exit_axis(walk.t_next);
        let next = walk.cell[axis] + walk.step[axis];
        let last = walk.step[axis] == 0 || next < 0 || next >= self.resolution[axis] as i32;
        (walk.t_next[axis], last)
    }

    /// Steps into the next cell.
    #[inline]
    fn advance(&self, walk: &mut CellWalk, ray: &Ray) {
        let axis = exit_axis(walk.t_next);
        walk.cell[axis] += walk.step[axis];
        walk.t_next[axis] = self.boundary_t(walk, ray, axis);
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
