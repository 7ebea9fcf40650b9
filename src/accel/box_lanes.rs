//! The slab test (Kay & Kajiya 1986; pbrt-v4 §6.8.2) of one ray against a few boxes at
//! once: the boxes are stored axis by axis in fixed-size lanes, so the loops compile to
//! vector instructions, and each lane computes exactly what the scalar test computes, in
//! the same order, so the two agree on every ray.

use glam::Vec3;

use super::{Ray, SLAB_ROUNDING};
use crate::geometry::Aabb;

/// Boxes at most.
pub const LANES: usize = 16;

/// Boxes per group: the slabs are found group by group, only as many groups as there are
/// boxes (a scene of eight objects pays for eight lanes, not sixteen).
const GROUP: usize = 8;

/// Up to [`LANES`] boxes, axis by axis.
pub struct BoxLanes {
    min: [[f32; LANES]; 3],
    max: [[f32; LANES]; 3],
    /// Boxes held.
    count: usize,
}

/// Per box, where the ray enters it (from its `t_min` on) and the widened exit before any
/// `t_max`: the ray meets box `i` before `t_max` when `start[i] <= t_max.min(end[i])`.
pub struct Slabs {
    /// Entry distances.
    pub start: [f32; LANES],
    /// Exit distances, widened by their rounding error.
    pub end: [f32; LANES],
    /// The boxes the ray meets before its own `t_max`, as bits (box `i` in bit `i`).
    met: u32,
}

impl Slabs {
    /// True when the ray meets box `i` before `t_max`.
    #[inline]
    pub fn hits(&self, i: usize, t_max: f32) -> bool {
        self.start[i] <= t_max.min(self.end[i])
    }

    /// The boxes the ray meets before its `t_max`, as bits (box `i` in bit `i`), so that a
    /// query visits only those instead of asking each box in turn. (Found with the slabs,
    /// from the lanes still in registers, rather than by loading back the slabs just
    /// stored.)
    #[inline]
    pub fn met(&self) -> u32 {
        self.met
    }
}

/// The lesser of `a` and `b`, `b` when either is NaN: one `minss`/`minps`.
#[inline(always)]
fn lesser(a: f32, b: f32) -> f32 {
    if a < b { a } else { b }
}

/// One axis of the slab test: the entry and exit so far (`start`, `end`) narrowed by the
/// slab between `lo` and `hi` along that axis, for an origin coordinate `o` and reciprocal
/// direction `d`. The exit is widened by its rounding error, so a ray through the box is
/// never culled by rounding (pbrt-v4 §6.8.2: t_far·(1 + 2γ(3))). A NaN distance (0·∞: the
/// ray parallel to the slab and on one of its planes) is passed over by `f32::min` and
/// `max`. (Single `minps`/`maxps`, which pass on a NaN in one operand, were measured:
/// fewer instructions, yet the renders of the Principled test scenes took 1.06–1.16× as
/// long; measured at 66ea61e.) The lanes and [`hits_box`] share this, so
/// they agree on every ray.
#[inline(always)]
fn narrow(start: f32, end: f32, lo: f32, hi: f32, o: f32, d: f32) -> (f32, f32) {
    let t0 = (lo - o) * d;
    let t1 = (hi - o) * d;
    let far = t0.max(t1) * (1.0 + 2.0 * SLAB_ROUNDING);
    (start.max(t0.min(t1)), end.min(far))
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
            count: boxes.len(),
        };
        for (i, b) in boxes.enumerate() {
            for axis in 0..3 {
                lanes.min[axis][i] = b.min[axis];
                lanes.max[axis][i] = b.max[axis];
            }
        }
        Some(lanes)
    }

    /// The ray against every box (`inv` is its direction's reciprocal).
    /// Always inlined, so that it is compiled with the caller's instruction set (the top
    /// level's queries have versions compiled for AVX2, where a group is one vector) and
    /// its lanes stay in registers.
    #[inline(always)]
    pub fn slabs(&self, ray: &Ray, inv: Vec3) -> Slabs {
        let mut start = [ray.t_min; LANES];
        let mut end = [f32::INFINITY; LANES];
        let mut met = 0u32;
        for group in 0..self.count.div_ceil(GROUP) {
            let lanes = group * GROUP..(group + 1) * GROUP;
            let (start, end) = (&mut start[lanes.clone()], &mut end[lanes.clone()]);
            for axis in 0..3 {
                let (o, d) = (ray.origin[axis], inv[axis]);
                let (lo, hi) = (
                    &self.min[axis][lanes.clone()],
                    &self.max[axis][lanes.clone()],
                );
                for i in 0..GROUP {
                    (start[i], end[i]) = narrow(start[i], end[i], lo[i], hi[i], o, d);
                }
            }
            for i in 0..GROUP {
                // `Slabs::hits` for `ray.t_max` (`end` is never NaN, so `lesser` is `min`).
                met |= u32::from(start[i] <= lesser(end[i], ray.t_max)) << (group * GROUP + i);
            }
        }
        Slabs {
            start,
            end,
            met: met & ((1u32 << self.count) - 1),
        }
    }
}

/// The scalar test the lanes reproduce: does `ray` meet box `b` before `t_max`?
#[inline]
pub fn hits_box(b: &Aabb, ray: &Ray, inv: Vec3, t_max: f32) -> bool {
    let (mut start, mut end) = (ray.t_min, f32::INFINITY);
    for axis in 0..3 {
        (start, end) = narrow(
            start,
            end,
            b.min[axis],
            b.max[axis],
            ray.origin[axis],
            inv[axis],
        );
    }
    start <= t_max.min(end)
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
        // One group, two groups part-filled, two full.
        let lanes: Vec<BoxLanes> = [5, 11, LANES]
            .map(|k| BoxLanes::new(boxes[..k].iter().copied()).unwrap())
            .into();
        let mut checked = 0;
        for r in 0..20_000 {
            let mut d = Vec3::new(next(), next(), next());
            if r % 7 == 0 {
                d.x = 0.0;
            }
            if r % 11 == 0 {
                d.y = -0.0;
            }
            let mut origin = Vec3::new(next(), next(), next());
            if r % 13 == 0 {
                // Parallel to x and on the plane of a box's face: 0·∞ = NaN in the test.
                d.x = 0.0;
                origin.x = boxes[(r / 13) % LANES].min.x;
            }
            let mut ray = Ray::new(origin, d);
            ray.t_min = if r % 3 == 0 { 0.5 } else { 0.0 };
            let t_max = if r % 5 == 0 { 1.0 } else { f32::INFINITY };
            ray.t_max = t_max;
            let inv = ray.direction.recip();
            for lanes in &lanes {
                let slabs = lanes.slabs(&ray, inv);
                let mut met = 0;
                for (i, b) in boxes[..lanes.count].iter().enumerate() {
                    let scalar = hits_box(b, &ray, inv, t_max);
                    assert_eq!(slabs.hits(i, t_max), scalar, "ray {r} box {i}");
                    met |= u32::from(scalar) << i;
                }
                assert_eq!(slabs.met(), met, "ray {r}, {} boxes", lanes.count);
                if lanes.count == LANES {
                    checked += met.count_ones();
                }
            }
        }
        assert!(
            checked > 10_000,
            "only {checked} hits: the test sees too few"
        );
    }
}
