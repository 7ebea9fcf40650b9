//! How far empty space reaches ahead of a ray, per empty macrocell: for each of the eight
//! octants of directions, the side (in cells) of the largest cube of empty cells that has
//! this macrocell in its corner and extends in that octant's directions. A ray moving into
//! the octant from anywhere in the macrocell stays in that cube until it crosses one of the
//! cube's far faces, so the walk leaps there in one step.
//!
//! A distance to the nearest occupied macrocell (proximity clouds, Cohen & Sheffer 1994),
//! which this replaces, is bounded by geometry on every side, also behind and beside the
//! ray: a ray passing a surface, or leaving it, crept past it in short leaps. A cube with
//! its corner at the macrocell is bounded only by what lies ahead in the ray's octant (the
//! anisotropic, per-octant distances of sparse-voxel ray marchers). Its side is counted in
//! cells, not macrocells: the cube ends at the first occupied *cell* ahead, often well
//! inside the next occupied macrocell, so the leap lands past that macrocell's empty edge
//! (or passes its corner altogether) instead of stopping at its face.
//!
//! Sides are coded in 7 bits ([`side`]): exactly up to 64 cells, in steps of about 6 %
//! above, up to the largest grid. A code stands for the largest coded side not above the
//! true one, so a leap never passes an occupied cell. Found for each macrocell and octant
//! by bisection over the codes, each cube's occupied cells counted from a table of sums
//! ([`BoxCounts`]).

use glam::IVec3;
use rayon::prelude::*;

use super::box_counts::BoxCounts;
use super::cells::MACRO_SHIFT;
use crate::accel::frame::MAX_RESOLUTION;

/// The largest code of a side (7 bits each, so the eight fit in one word).
pub(super) const MAX_CODE: u32 = 127;

/// Bits per octant's code in a packed word.
const BITS: u32 = 7;

/// Cells along a macrocell's edge.
const MACRO_SIDE: i32 = 1 << MACRO_SHIFT;

/// Codes up to this stand for their own number of cells.
const EXACT_UP_TO: usize = 64;

/// The side in cells of each code: the code itself up to [`EXACT_UP_TO`], then 1/16 more
/// per code (at least one cell); never below a macrocell's edge, which an empty macrocell's
/// cube always has.
const SIDES: [f32; MAX_CODE as usize + 1] = {
    let mut sides = [0f32; MAX_CODE as usize + 1];
    let mut side = 0u32;
    let mut code = 0;
    while code <= MAX_CODE as usize {
        side = if code <= EXACT_UP_TO {
            code as u32
        } else {
            side + if side / 16 > 1 { side / 16 } else { 1 }
        };
        sides[code] = if side < MACRO_SIDE as u32 {
            MACRO_SIDE as f32
        } else {
            side as f32
        };
        code += 1;
    }
    sides
};

/// The side in cells of the cube `code` stands for ([`SIDES`]).
#[inline(always)]
pub(super) fn side(code: u32) -> f32 {
    SIDES[(code & MAX_CODE) as usize]
}

/// The octant of a walk's direction: bit `a` set when it moves down axis `a` (a ray
/// parallel to an axis counts as moving up it: it never leaves its slab of that axis).
#[inline(always)]
pub(super) fn octant(step: IVec3) -> u32 {
    u32::from(step.x < 0) | u32::from(step.y < 0) << 1 | u32::from(step.z < 0) << 2
}

/// The code for `octant` in a word packed by [`reaches`].
#[inline(always)]
pub(super) fn unpack(word: u64, octant: u32) -> u32 {
    (word >> (BITS * octant)) as u32 & MAX_CODE
}

/// True when a walk moving into `octant` moves up (or along) `axis` ([`octant`]).
#[inline(always)]
pub(super) fn moves_up(octant: u32, axis: usize) -> bool {
    octant >> axis & 1 == 0
}

/// The cells `(lo, hi)` (inclusive) of the cube of `side` cells a side that has the unit of
/// `unit` cells a side starting at cell `corner` in its corner and extends towards
/// `octant`: the box a reach promises empty (of a cell: `unit` 1; of a macrocell: its
/// edge).
pub(super) fn cube_box(corner: IVec3, unit: i32, octant: u32, side: i32) -> (IVec3, IVec3) {
    let up = IVec3::from_array([0, 1, 2].map(|a| i32::from(moves_up(octant, a))));
    let lo = corner + (IVec3::ONE - up) * (unit - side);
    (lo, lo + IVec3::splat(side - 1))
}

/// Every macrocell's codes in the eight octants, packed `BITS` bits each (octant `o` at bit
/// `BITS·o`), for a grid of `resolution` macrocells (x fastest) whose occupied cells
/// `cells` counts; an occupied macrocell's are 0.
pub(super) fn reaches(resolution: IVec3, cells: &BoxCounts) -> Vec<u64> {
    let r = resolution;
    let count = (r.x * r.y * r.z) as usize;
    (0..count)
        .into_par_iter()
        .map(|i| {
            let i = i as i32;
            let m = IVec3::new(i % r.x, i / r.x % r.y, i / (r.x * r.y));
            let corner = m * MACRO_SIDE;
            let empty = |octant: u32, code: u32| {
                let (lo, hi) = cube_box(corner, MACRO_SIDE, octant, side(code) as i32);
                cells.count(lo, hi) == 0
            };
            if !empty(0, 0) {
                return 0;
            }
            (0..8).fold(0u64, |word, octant| {
                // The largest code whose cube is empty: the macrocell's own (code 0)
                // is, and cubes grow with the code.
                let (mut low, mut high) = (0, MAX_CODE + 1);
                while high - low > 1 {
                    let mid = (low + high) / 2;
                    if empty(octant, mid) {
                        low = mid;
                    } else {
                        high = mid;
                    }
                }
                word | u64::from(low) << (BITS * octant)
            })
        })
        .collect()
}

/// The largest code spans any grid, so a cube that reaches past the grid's end on every
/// axis ahead is coded as such.
const _: () = assert!(SIDES[MAX_CODE as usize] >= MAX_RESOLUTION as f32);

#[cfg(test)]
mod tests {
    use super::*;

    /// Each code stands for the largest coded side of an empty cube of cells in the
    /// macrocell's corner, found by counting the cells of every cube in turn.
    #[test]
    fn reaches_are_the_largest_empty_cubes_ahead() {
        // Macrocells of a grid whose last ones are partly outside it.
        let (macros, cells) = (IVec3::new(5, 3, 4), IVec3::new(37, 20, 30));
        let full = [
            IVec3::new(20, 11, 17),
            IVec3::new(3, 18, 9),
            IVec3::new(33, 0, 26),
            IVec3::new(9, 9, 9),
        ];
        let counts = BoxCounts::new(cells, |c| full.contains(&c));
        let packed = reaches(macros, &counts);
        let index = |m: IVec3| (m.x + macros.x * (m.y + macros.y * m.z)) as usize;
        let mut checked = 0;
        for z in 0..macros.z {
            for y in 0..macros.y {
                for x in 0..macros.x {
                    let m = IVec3::new(x, y, z);
                    let corner = m * MACRO_SIDE;
                    let empty = |o: u32, side: f32| {
                        let (lo, hi) = cube_box(corner, MACRO_SIDE, o, side as i32);
                        !full.iter().any(|f| f.cmpge(lo).all() && f.cmple(hi).all())
                    };
                    if !empty(0, 8.0) {
                        assert_eq!(packed[index(m)], 0, "{m}");
                        continue;
                    }
                    for o in 0..8 {
                        let code = unpack(packed[index(m)], o);
                        assert!(empty(o, side(code)), "{m} octant {o}: code {code}");
                        if code < MAX_CODE {
                            assert!(!empty(o, side(code + 1)), "{m} octant {o}: code {code}");
                        }
                        checked += 1;
                    }
                }
            }
        }
        assert!(checked > 300, "{checked}");
        assert_eq!(octant(IVec3::new(1, -1, 0)), 2);
        assert_eq!(octant(IVec3::new(-1, 1, -1)), 5);
    }

    /// Codes stand for their own side up to 64 cells, grow from there, and never stand for
    /// less than a macrocell.
    #[test]
    fn sides_grow_with_their_codes() {
        assert_eq!(side(0), 8.0);
        assert_eq!(side(13), 13.0);
        assert_eq!(side(64), 64.0);
        for code in 8..MAX_CODE {
            assert!(side(code + 1) > side(code), "{code}");
        }
    }
}
