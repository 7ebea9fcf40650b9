//! The slab test (Kay & Kajiya 1986; pbrt-v4 §6.8.2) of one ray against a few boxes at
//! once: the boxes are stored axis by axis in fixed-size lanes, so the loops compile to
//! vector instructions, and each lane computes exactly what the scalar test computes, in
//! the same order, so the two agree on every ray.

use glam::Vec3;

use super::{Ray, SLAB_ROUNDING};
use crate::scene::Aabb;

/// Boxes per group.
pub const LANES: usize = 16;

/// Up to [`LANES`] boxes, axis by axis.
pub struct BoxLanes {
    min: [[f32; LANES]; 3],
    max: [[f32; LANES]; 3],
}

/// Per box, where the ray enters it (from its `t_min` on) and the widened exit before any
/// `t_max`: the ray meets box `i` before `t_max` when `start[i] <= t_max.min(end[i])`.
pub struct Slabs {
    /// Entry distances.
    pub start: [f32; LANES],
    /// Exit distances, widened by their rounding error.
    pub end: [f32; LANES],
}

impl Slabs {
    /// True when the ray meets box `i` before `t_max`.
    #[inline]
    pub fn hits(&self, i: usize, t_max: f32) -> bool {
        self.start[i] <= t_max.min(self.end[i])
    }
}

impl BoxLanes {
    /// The boxes, or `None` when there are more than [`LANES`].
    pub fn new(boxes: impl ExactSizeIterator<Item = Aabb>) -> Option<BoxLanes> {
        if boxes.len() > LANES {
            return None;
        }
        let mut lanes = BoxLanes {
            min: [[0.0; LANES]; 3],
            max: [[0.0; LANES]; 3],
        };
        for (i, b) in boxes.enumerate() {
            for axis in 0..3 {
                lanes.min[axis][i] = b.min[axis];
                lanes.max[axis][i] = b.max[axis];
            }
        }
        Some(lanes)
    }

    /// The ray against every box (`inv` is its direction's reciprocal). Lanes past
    /// the boxes given hold nothing meaningful.
    #[inline]
    pub fn slabs(&self, ray: &Ray, inv: Vec3) -> Slabs {
        let mut start = [ray.t_min; LANES];
        let mut end = [f32::INFINITY; LANES];
        for axis in 0..3 {
            let (o, d) = (ray.origin[axis], inv[axis]);
            for i in 0..LANES {
                let t0 = (self.min[axis][i] - o) * d;
                let t1 = (self.max[axis][i] - o) * d;
                start[i] = start[i].max(t0.min(t1));
                end[i] = end[i].min(t0.max(t1) * (1.0 + 2.0 * SLAB_ROUNDING));
            }
        }
        Slabs { start, end }
    }
}

/// The scalar test the lanes reproduce: does `ray` meet box `b` before `t_max`?
#[inline]
pub fn hits_box(b: &Aabb, ray: &Ray, inv: Vec3, t_max: f32) -> bool {
    let t0 = (b.min - ray.origin) * inv;
    let t1 = (b.max - ray.origin) * inv;
    let near = t0.min(t1);
    // Widen each slab's exit by its rounding error, so a ray through the box is never
    // culled by rounding (pbrt-v4 §6.8.2: t_far·(1 + 2γ(3))).
    let far = t0.max(t1) * (1.0 + 2.0 * SLAB_ROUNDING);
    let t_start = ray.t_min.max(near.x).max(near.y).max(near.z);
    let t_end = t_max.min(far.x).min(far.y).min(far.z);
    t_start <= t_end
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lanes_agree_with_the_scalar_test() {
        // Boxes and rays from a fixed hash: grazing, axis-parallel (zero direction
        // components), inside, behind, empty boxes.
        let mut state = 0x9e37_79b9_7f4a_7c15u64;
        let mut next = || {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((state >> 40) as f32 / (1u64 << 24) as f32) * 4.0 - 2.0
        };
        let mut boxes = Vec::new();
        for i in 0..LANES {
            let a = Vec3::new(next(), next(), next());
            let b = Vec3::new(next(), next(), next());
            boxes.push(if i == 5 {
                Aabb::EMPTY
            } else if i == 7 {
                Aabb { min: a, max: a }
            } else {
                Aabb {
                    min: a.min(b),
                    max: a.max(b),
                }
            });
        }
        let lanes = BoxLanes::new(boxes.iter().copied()).unwrap();
        let mut checked = 0;
        for r in 0..20_000 {
            let mut d = Vec3::new(next(), next(), next());
            if r % 7 == 0 {
                d.x = 0.0;
            }
            if r % 11 == 0 {
                d.y = -0.0;
            }
            let mut ray = Ray::new(Vec3::new(next(), next(), next()), d);
            ray.t_min = if r % 3 == 0 { 0.5 } else { 0.0 };
            let t_max = if r % 5 == 0 { 1.0 } else { f32::INFINITY };
            let inv = ray.direction.recip();
            let slabs = lanes.slabs(&ray, inv);
            for (i, b) in boxes.iter().enumerate() {
                assert_eq!(
                    slabs.hits(i, t_max),
                    hits_box(b, &ray, inv, t_max),
                    "ray {r} box {i}"
                );
                checked += usize::from(slabs.hits(i, t_max));
            }
        }
        assert!(
            checked > 10_000,
            "only {checked} hits: the test sees too few"
        );
    }
}
