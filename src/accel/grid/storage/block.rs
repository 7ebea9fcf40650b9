//! Eight triangles of one cell stored lane by lane (structure of arrays) and tested together.
//!
//! Each lane does exactly the arithmetic of [`Triangle::intersect`] (Möller & Trumbore 1997),
//! in the same order, so a block finds bit for bit what testing its triangles one at a time
//! finds; written branch-free over fixed arrays so the compiler turns each line into one
//! vector instruction (8 lanes with AVX, two halves of 4 with SSE).

use glam::Vec3;

use crate::accel::{Ray, Triangle};

/// Triangles per block.
pub(in crate::accel::grid) const LANES: usize = 8;

/// The id of an unused lane; its triangle (all zero) is never hit.
pub(in crate::accel::grid) const NO_TRIANGLE: u32 = u32::MAX;

/// Up to eight triangles as vertex and edges per axis, with their mesh indices. Aligned to
/// cache lines, so that a block (five lines) never straddles a sixth, which the walk's
/// request for its lines ([`crate::accel::grid::walk::prefetch::prefetch`]) would not ask for: the
/// allocator's placement of the block array does not decide it.
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(C, align(64))]
pub(in crate::accel::grid) struct Block {
    v0: [[f32; LANES]; 3],
    e1: [[f32; LANES]; 3],
    e2: [[f32; LANES]; 3],
    ids: [u32; LANES],
}

// Blocks fill whole cache lines, one after another.
const _: () = assert!(std::mem::size_of::<Block>().is_multiple_of(64));

/// The nearest hit in a block: lane, parameter and barycentrics.
#[derive(Clone, Copy, Debug)]
pub(in crate::accel::grid) struct LaneHit {
    pub t: f32,
    pub u: f32,
    pub v: f32,
    pub id: u32,
}

impl From<LaneHit> for crate::accel::grid::GridHit {
    fn from(hit: LaneHit) -> crate::accel::grid::GridHit {
        crate::accel::grid::GridHit {
            t: hit.t,
            u: hit.u,
            v: hit.v,
            triangle: hit.id,
        }
    }
}

impl Block {
    /// A block of unused lanes.
    pub const EMPTY: Block = Block {
        v0: [[0.0; LANES]; 3],
        e1: [[0.0; LANES]; 3],
        e2: [[0.0; LANES]; 3],
        ids: [NO_TRIANGLE; LANES],
    };

    /// Puts triangle `id` in `lane`.
    pub fn set(&mut self, lane: usize, triangle: &Triangle, id: u32) {
        for a in 0..3 {
            self.v0[a][lane] = triangle.v0[a];
            self.e1[a][lane] = triangle.e1[a];
            self.e2[a][lane] = triangle.e2[a];
        }
        self.ids[lane] = id;
    }

    /// The triangle in `lane` and its id; `None` for an unused lane.
    pub fn get(&self, lane: usize) -> Option<(Triangle, u32)> {
        let at = |m: &[[f32; LANES]; 3]| Vec3::new(m[0][lane], m[1][lane], m[2][lane]);
        (self.ids[lane] != NO_TRIANGLE).then(|| {
            (
                Triangle {
                    v0: at(&self.v0),
                    e1: at(&self.e1),
                    e2: at(&self.e2),
                },
                self.ids[lane],
            )
        })
    }

    /// The corners of the triangles ([`Triangle::vertices`]), corner by corner, axis by
    /// axis, lane by lane, and which lanes are in use.
    #[inline(always)]
    pub fn corners(&self) -> ([[[f32; LANES]; 3]; 3], [bool; LANES]) {
        let from_v0 = |e: &[[f32; LANES]; 3]| {
            std::array::from_fn(|a| std::array::from_fn(|l| self.v0[a][l] + e[a][l]))
        };
        let corners = [self.v0, from_v0(&self.e1), from_v0(&self.e2)];
        (corners, self.ids.map(|id| id != NO_TRIANGLE))
    }

    /// Triangles in use.
    pub fn len(&self) -> usize {
        self.ids.iter().filter(|&&id| id != NO_TRIANGLE).count()
    }

    /// Every lane's hit parameter and barycentrics, with a mask of the lanes hit within
    /// (`ray.t_min`, `t_max`): [`Triangle::intersect`] lane by lane. (The negated
    /// comparisons keep its answer where `v` is NaN.)
    #[inline(always)]
    #[allow(clippy::neg_cmp_op_on_partial_ord)]
    fn test(
        &self,
        ray: &Ray,
        t_max: f32,
    ) -> ([bool; LANES], [f32; LANES], [f32; LANES], [f32; LANES]) {
        let (o, d) = (ray.origin, ray.direction);
        let mut hit = [false; LANES];
        let mut ts = [0.0; LANES];
        let mut us = [0.0; LANES];
        let mut vs = [0.0; LANES];
        for l in 0..LANES {
            let (e1x, e1y, e1z) = (self.e1[0][l], self.e1[1][l], self.e1[2][l]);
            let (e2x, e2y, e2z) = (self.e2[0][l], self.e2[1][l], self.e2[2][l]);
            // p = d × e2, det = e1 · p
            let px = d.y * e2z - d.z * e2y;
            let py = d.z * e2x - d.x * e2z;
            let pz = d.x * e2y - d.y * e2x;
            let det = e1x * px + e1y * py + e1z * pz;
            let inv_det = 1.0 / det;
            // s = o − v0, u = s · p / det
            let sx = o.x - self.v0[0][l];
            let sy = o.y - self.v0[1][l];
            let sz = o.z - self.v0[2][l];
            let u = (sx * px + sy * py + sz * pz) * inv_det;
            // q = s × e1, v = d · q / det, t = e2 · q / det
            let qx = sy * e1z - sz * e1y;
            let qy = sz * e1x - sx * e1z;
            let qz = sx * e1y - sy * e1x;
            let v = (d.x * qx + d.y * qy + d.z * qz) * inv_det;
            let t = (e2x * qx + e2y * qy + e2z * qz) * inv_det;
            // The scalar test's conditions, NaN behaviour included.
            hit[l] = (det != 0.0)
                & (0.0..=1.0).contains(&u)
                & !(v < 0.0)
                & !(u + v > 1.0)
                & (t > ray.t_min)
                & (t < t_max);
            ts[l] = t;
            us[l] = u;
            vs[l] = v;
        }
        (hit, ts, us, vs)
    }

    /// The nearest hit before `t_max`; of equal hits, the first lane's.
    #[inline(always)]
    pub fn nearest(&self, ray: &Ray, t_max: f32) -> Option<LaneHit> {
        let (hit, ts, us, vs) = self.test(ray, t_max);
        self.first_nearest(&hit, &ts, &us, &vs, t_max)
    }

    /// [`Block::nearest`], and whether a lane of another triangle is hit at exactly its
    /// distance.
    #[inline(always)]
    pub fn nearest_and_tie(&self, ray: &Ray, t_max: f32) -> Option<(LaneHit, bool)> {
        let (hit, ts, us, vs) = self.test(ray, t_max);
        let best = self.first_nearest(&hit, &ts, &us, &vs, t_max)?;
        let tie = (0..LANES).any(|l| hit[l] && ts[l] == best.t && self.ids[l] != best.id);
        Some((best, tie))
    }

    /// The first of the nearest lanes hit, from [`Block::test`]'s answers.
    #[inline(always)]
    fn first_nearest(
        &self,
        hit: &[bool; LANES],
        ts: &[f32; LANES],
        us: &[f32; LANES],
        vs: &[f32; LANES],
        t_max: f32,
    ) -> Option<LaneHit> {
        // Most blocks tested hold no hit: one test of all lanes then, not one per lane.
        if !hit.iter().any(|&h| h) {
            return None;
        }
        let mut best: Option<LaneHit> = None;
        let mut t_best = t_max;
        for l in 0..LANES {
            if hit[l] && ts[l] < t_best {
                t_best = ts[l];
                best = Some(LaneHit {
                    t: ts[l],
                    u: us[l],
                    v: vs[l],
                    id: self.ids[l],
                });
            }
        }
        best
    }

    /// True when some triangle is hit before `t_max`.
    #[inline(always)]
    pub fn any(&self, ray: &Ray, t_max: f32) -> bool {
        self.test(ray, t_max).0.iter().any(|&h| h)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::render::sampling::Rng;

    fn random_vec(rng: &mut Rng) -> Vec3 {
        Vec3::new(rng.uniform(), rng.uniform(), rng.uniform()) * 2.0 - 1.0
    }

    /// Every lane finds bit for bit what the scalar test finds, and the block reports the
    /// first of the nearest.
    #[test]
    fn a_block_finds_what_testing_its_triangles_in_turn_finds() {
        let mut rng = Rng::new(3, 3);
        let mut hits = 0;
        for round in 0..20_000 {
            let filled = 1 + round % LANES;
            let mut block = Block::EMPTY;
            let mut triangles = Vec::new();
            for lane in 0..filled {
                let a = random_vec(&mut rng);
                // Some share an edge or repeat, so ties and edge hits occur.
                let tri = match lane % 4 {
                    3 => triangles
                        .last()
                        .map_or(Triangle::new(a, Vec3::X, Vec3::Y), |t: &Triangle| *t),
                    _ => Triangle::new(a, a + random_vec(&mut rng), a + random_vec(&mut rng)),
                };
                block.set(lane, &tri, lane as u32 * 10);
                triangles.push(tri);
            }
            let origin = random_vec(&mut rng) * 2.0;
            let ray = Ray::new(origin, random_vec(&mut rng) - origin);
            let t_max = if round % 3 == 0 { 1.0 } else { f32::INFINITY };
            let mut expected: Option<(f32, f32, f32, u32)> = None;
            for (lane, tri) in triangles.iter().enumerate() {
                let limit = expected.map_or(t_max, |e| e.0);
                if let Some(h) = tri.intersect(&ray, limit) {
                    expected = Some((h.t, h.u, h.v, lane as u32 * 10));
                }
            }
            let got = block.nearest(&ray, t_max).map(|h| (h.t, h.u, h.v, h.id));
            assert_eq!(
                got.map(|g| (g.0.to_bits(), g.1.to_bits(), g.2.to_bits(), g.3)),
                expected.map(|e| (e.0.to_bits(), e.1.to_bits(), e.2.to_bits(), e.3)),
                "round {round}"
            );
            assert_eq!(block.any(&ray, t_max), expected.is_some());
            hits += usize::from(expected.is_some());
            assert_eq!(block.len(), filled);
            assert_eq!(block.get(0).unwrap().0, triangles[0]);
            assert!(filled == LANES || block.get(filled).is_none());
        }
        assert!(hits > 2_000, "{hits}");
    }
}
