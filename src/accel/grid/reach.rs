//! How far empty space reaches ahead of a ray, per empty macrocell: for each of the eight
//! octants of directions, the side (in macrocells) of the largest cube of empty macrocells
//! that has this macrocell as a corner and extends in that octant's directions. A ray
//! moving into the octant from anywhere in the macrocell stays in that cube until it
//! crosses one of the cube's far faces, so the walk leaps there in one step.
//!
//! A distance to the nearest occupied macrocell (proximity clouds, Cohen & Sheffer 1994),
//! which this replaces, is bounded by geometry on every side, also behind and beside the
//! ray: a ray passing a surface, or leaving it, crept past it in short leaps. A cube with
//! its corner at the macrocell is bounded only by what lies ahead in the ray's octant (the
//! anisotropic, per-octant distances of sparse-voxel ray marchers).
//!
//! Found for each octant by the recurrence for the largest empty cube with a given corner:
//! the cube of side k at `m` is `m` and the seven cubes of side k − 1 at the neighbours of
//! `m` towards the octant, so reach(m) = 1 + the least reach of those neighbours (0 for an
//! occupied macrocell; outside the grid counts as the cap).

use glam::IVec3;

/// Reaches are counted up to this (7 bits each, so the eight fit in one word).
pub(super) const MAX_REACH: u32 = 127;

/// Bits per octant's reach in a packed word.
const BITS: u32 = 7;

/// The octant of a walk's direction: bit `a` set when it moves down axis `a` (a ray
/// parallel to an axis counts as moving up it: it never leaves its slab of that axis).
#[inline(always)]
pub(super) fn octant(step: IVec3) -> u32 {
    u32::from(step.x < 0) | u32::from(step.y < 0) << 1 | u32::from(step.z < 0) << 2
}

/// The reach for `octant` in a word packed by [`reaches`].
#[inline(always)]
pub(super) fn unpack(word: u64, octant: u32) -> u32 {
    (word >> (BITS * octant)) as u32 & MAX_REACH
}

/// True when a walk moving into `octant` moves up (or along) `axis` ([`octant`]).
#[inline(always)]
pub(super) fn moves_up(octant: u32, axis: usize) -> bool {
    octant >> axis & 1 == 0
}

/// The direction of `octant` per axis: +1 or −1.
fn signs(octant: u32) -> IVec3 {
    IVec3::from_array([0, 1, 2].map(|a| if moves_up(octant, a) { 1 } else { -1 }))
}

/// The empty box `(lo, hi)` (inclusive) that `reach` promises from `m`, its corner, for a
/// walk moving into `octant`: of macrocells here, of cells for [`super::cell_reach`].
pub(super) fn reach_box(m: IVec3, octant: u32, reach: u32) -> (IVec3, IVec3) {
    let far = m + signs(octant) * (reach as i32 - 1);
    (m.min(far), m.max(far))
}

/// Every macrocell's reaches in the eight octants, packed `BITS` bits each (octant `o` at
/// bit `BITS·o`), for a grid of `resolution` macrocells (x fastest) of which those with
/// `occupied(index)` hold cells; an occupied macrocell's are 0.
pub(super) fn reaches(resolution: IVec3, occupied: impl Fn(usize) -> bool) -> Vec<u64> {
    let r = resolution;
    let index = |c: IVec3| (c.x + r.x * (c.y + r.y * c.z)) as usize;
    let count = index(r - 1) + 1;
    let mut packed = vec![0u64; count];
    let mut reach = vec![0u8; count];
    // Along each axis, cells in the order that visits a cell's neighbours towards the
    // octant before the cell.
    let order = |n: i32, up: bool| (0..n).map(move |i| if up { n - 1 - i } else { i });
    for o in 0..8 {
        let s = signs(o);
        for z in order(r.z, s.z > 0) {
            for y in order(r.y, s.y > 0) {
                for x in order(r.x, s.x > 0) {
                    let c = IVec3::new(x, y, z);
                    let i = index(c);
                    if occupied(i) {
                        reach[i] = 0;
                        continue;
                    }
                    let mut least = MAX_REACH;
                    for e in 1..8 {
                        let n = c + s * IVec3::new(e & 1, (e >> 1) & 1, e >> 2);
                        if n.cmpge(IVec3::ZERO).all() && n.cmplt(r).all() {
                            least = least.min(u32::from(reach[index(n)]));
                        }
                    }
                    reach[i] = (least + 1).min(MAX_REACH) as u8;
                }
            }
        }
        for (word, &k) in packed.iter_mut().zip(&reach) {
            *word |= u64::from(k) << (BITS * o);
        }
    }
    packed
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Each reach is the side of the largest empty cube at its corner, found by trying
    /// every side in turn.
    #[test]
    fn reaches_are_the_largest_empty_cubes_ahead() {
        let r = IVec3::new(9, 7, 8);
        let index = |c: IVec3| (c.x + r.x * (c.y + r.y * c.z)) as usize;
        let full = [
            IVec3::new(4, 3, 4),
            IVec3::new(1, 5, 2),
            IVec3::new(7, 0, 6),
        ];
        let occupied = |i: usize| full.iter().any(|&c| index(c) == i);
        let packed = reaches(r, occupied);
        for z in 0..r.z {
            for y in 0..r.y {
                for x in 0..r.x {
                    let m = IVec3::new(x, y, z);
                    for o in 0..8 {
                        let got = unpack(packed[index(m)], o);
                        let empty = |k: u32| {
                            let (lo, hi) = reach_box(m, o, k);
                            !full.iter().any(|f| f.cmpge(lo).all() && f.cmple(hi).all())
                        };
                        let expected = (0..=MAX_REACH).take_while(|&k| k == 0 || empty(k));
                        assert_eq!(got, expected.last().unwrap(), "{m} octant {o}");
                    }
                }
            }
        }
        assert_eq!(octant(IVec3::new(1, -1, 0)), 2);
        assert_eq!(octant(IVec3::new(-1, 1, -1)), 5);
    }
}
