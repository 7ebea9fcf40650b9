//! How far empty space reaches ahead of a ray, per empty macrocell: for each of the eight
//! octants of directions, the sides (in cells) of a box of empty cells that has this
//! macrocell in its corner and extends in that octant's directions. A ray moving into the
//! octant from anywhere in the macrocell stays in that box until it crosses one of the
//! box's far faces, so the walk leaps there in one step.
//!
//! A distance to the nearest occupied macrocell (proximity clouds, Cohen & Sheffer 1994),
//! which this replaces, is bounded by geometry on every side, also behind and beside the
//! ray: a ray passing a surface, or leaving it, crept past it in short leaps. A box with
//! its corner at the macrocell is bounded only by what lies ahead in the ray's octant (the
//! anisotropic, per-octant distances of sparse-voxel ray marchers). Its sides are counted
//! in cells, not macrocells: the box ends at the first occupied *cell* ahead, often well
//! inside the next occupied macrocell, so the leap lands past that macrocell's empty edge
//! (or passes its corner altogether) instead of stopping at its face.
//!
//! The box is the largest empty cube, then grown along x, y and z in turn as far as it
//! stays empty: where a cube stops at the first occupied cell in any direction ahead, the
//! box goes on along the axes that are still clear, so a ray leaving it by those axes' far
//! faces leaps further (outside rays that miss the full dragon take 2.8 leaps over empty
//! macrocells instead of 3.9; measured at 624bb22). Each side is at most
//! [`MAX_SIDE`] cells, so the three fit in a byte each ([`CellIndex`]); found by bisection,
//! each box's occupied cells counted from a table of sums ([`BoxCounts`]).
//!
//! [`CellIndex`]: crate::accel::grid::storage::cells::CellIndex

use glam::IVec3;
use rayon::prelude::*;

use super::macrocell::MACRO_SHIFT;
use crate::accel::grid::build::box_counts::BoxCounts;

/// The longest side of a box, in cells: a side fits in a byte. (A ray through a grid of
/// the largest resolution, 2048 cells a side, thus leaps at least nine times over empty
/// space along it.)
pub(in crate::accel::grid) const MAX_SIDE: i32 = 255;

/// Cells along a macrocell's edge.
const MACRO_SIDE: i32 = 1 << MACRO_SHIFT;

/// The octant of a walk's direction: bit `a` set when it moves down axis `a` (a ray
/// parallel to an axis counts as moving up it: it never leaves its slab of that axis).
#[inline(always)]
pub(in crate::accel::grid) fn octant(step: IVec3) -> u32 {
    u32::from(step.x < 0) | u32::from(step.y < 0) << 1 | u32::from(step.z < 0) << 2
}

/// True when a walk moving into `octant` moves up (or along) `axis` ([`octant`]).
#[inline(always)]
pub(in crate::accel::grid) fn moves_up(octant: u32, axis: usize) -> bool {
    octant >> axis & 1 == 0
}

/// The cells `(lo, hi)` (inclusive) of the box of `sides` cells that has the unit of `unit`
/// cells a side starting at cell `corner` in its corner and extends towards `octant`: the
/// box a reach promises empty (of a cell: `unit` 1; of a macrocell: its edge).
pub(in crate::accel::grid) fn box_cells(
    corner: IVec3,
    unit: i32,
    octant: u32,
    sides: IVec3,
) -> (IVec3, IVec3) {
    let up = IVec3::from_array([0, 1, 2].map(|a| i32::from(moves_up(octant, a))));
    let lo = corner + (IVec3::ONE - up) * (IVec3::splat(unit) - sides);
    (lo, lo + sides - 1)
}

/// [`box_cells`] of a cube of `side` cells a side.
pub(in crate::accel::grid) fn cube_box(
    corner: IVec3,
    unit: i32,
    octant: u32,
    side: i32,
) -> (IVec3, IVec3) {
    box_cells(corner, unit, octant, IVec3::splat(side))
}

/// Per macrocell of a grid of `resolution` macrocells (x fastest) whose occupied cells
/// `cells` counts, and per octant: the sides of its box (above), packed a byte each, x
/// lowest; 0 for an occupied macrocell.
pub(in crate::accel::grid) fn boxes(resolution: IVec3, cells: &BoxCounts) -> Vec<[u32; 8]> {
    let r = resolution;
    let count = (r.x * r.y * r.z) as usize;
    (0..count)
        .into_par_iter()
        .map(|i| {
            let i = i as i32;
            let m = IVec3::new(i % r.x, i / r.x % r.y, i / (r.x * r.y));
            let corner = m * MACRO_SIDE;
            let empty = |octant: u32, sides: IVec3| {
                let (lo, hi) = box_cells(corner, MACRO_SIDE, octant, sides);
                cells.count(lo, hi) == 0
            };
            let mut packed = [0u32; 8];
            if !empty(0, IVec3::splat(MACRO_SIDE)) {
                return packed;
            }
            for (octant, entry) in (0..8).zip(&mut packed) {
                let edge = edge_sides(cells.resolution(), corner, octant);
                let cube = |s| empty(octant, IVec3::splat(s));
                let side = largest(MACRO_SIDE, edge.max_element(), cube);
                let x = largest(side, edge.x, |s| empty(octant, IVec3::new(s, side, side)));
                let y = largest(side, edge.y, |s| empty(octant, IVec3::new(x, s, side)));
                let z = largest(side, edge.z, |s| empty(octant, IVec3::new(x, y, s)));
                *entry = pack(IVec3::new(x, y, z));
            }
            packed
        })
        .collect()
}

/// Per axis, the side from which a box with the macrocell at `corner` in its corner,
/// extending towards `octant`, reaches the far edge of a grid of `resolution` cells: the
/// boxes of that side and larger hold the same cells of the grid.
fn edge_sides(resolution: IVec3, corner: IVec3, octant: u32) -> IVec3 {
    IVec3::from_array([0, 1, 2].map(|a| match moves_up(octant, a) {
        true => resolution[a] - corner[a],
        false => corner[a] + MACRO_SIDE,
    }))
}

/// The largest side in `low..=MAX_SIDE` for which `fits` holds: `fits(low)` holds, a side
/// for which it fails fails for every larger one (boxes nest), and the sides from `edge` on
/// hold the same cells (the box has reached the grid's edge). Two answers are tried first —
/// the box reaches the edge, or does not grow (two fifths of the full dragon's searches) —
/// then the rest by bisection between them: the full dragon's boxes in about half the
/// time of a bisection over `low..=MAX_SIDE`.
fn largest(low: i32, edge: i32, fits: impl Fn(i32) -> bool) -> i32 {
    let edge = edge.min(MAX_SIDE);
    if edge <= low || fits(edge) {
        return MAX_SIDE;
    }
    if !fits(low + 1) {
        return low;
    }
    // `fits(low)` holds and `fits(high)` fails.
    let (mut low, mut high) = (low + 1, edge);
    while high - low > 1 {
        let mid = (low + high) / 2;
        if fits(mid) {
            low = mid;
        } else {
            high = mid;
        }
    }
    low
}

/// A box's sides (each in `1..=MAX_SIDE`), a byte each, x lowest.
pub(in crate::accel::grid) fn pack(sides: IVec3) -> u32 {
    sides.x as u32 | (sides.y as u32) << 8 | (sides.z as u32) << 16
}

/// The sides [`pack`] packed.
pub(in crate::accel::grid) fn unpack(packed: u32) -> IVec3 {
    IVec3::new(
        (packed & 0xff) as i32,
        (packed >> 8 & 0xff) as i32,
        (packed >> 16 & 0xff) as i32,
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Each macrocell's box is empty, holds the largest empty cube, and cannot grow by a
    /// cell along any axis without taking in an occupied cell (or passing `MAX_SIDE`), as
    /// counting the cells of every box in turn finds.
    #[test]
    fn boxes_are_empty_and_grown_as_far_as_they_stay_empty() {
        // Macrocells of a grid whose last ones are partly outside it.
        let (macros, cells) = (IVec3::new(5, 3, 4), IVec3::new(37, 20, 30));
        let full = [
            IVec3::new(20, 11, 17),
            IVec3::new(3, 18, 9),
            IVec3::new(33, 0, 26),
            IVec3::new(9, 9, 9),
        ];
        let counts = BoxCounts::new(cells, |c| full.contains(&c));
        let packed = boxes(macros, &counts);
        let index = |m: IVec3| (m.x + macros.x * (m.y + macros.y * m.z)) as usize;
        let (mut checked, mut grown) = (0, 0);
        for z in 0..macros.z {
            for y in 0..macros.y {
                for x in 0..macros.x {
                    let m = IVec3::new(x, y, z);
                    let corner = m * MACRO_SIDE;
                    let empty = |o: u32, sides: IVec3| {
                        let (lo, hi) = box_cells(corner, MACRO_SIDE, o, sides);
                        !full.iter().any(|f| f.cmpge(lo).all() && f.cmple(hi).all())
                    };
                    if !empty(0, IVec3::splat(MACRO_SIDE)) {
                        assert_eq!(packed[index(m)], [0; 8], "{m}");
                        continue;
                    }
                    for o in 0..8 {
                        let sides = unpack(packed[index(m)][o as usize]);
                        assert!(empty(o, sides), "{m} octant {o}: {sides}");
                        let cube = (MACRO_SIDE..=MAX_SIDE)
                            .take_while(|&s| empty(o, IVec3::splat(s)))
                            .last();
                        assert_eq!(Some(sides.min_element()), cube, "{m} octant {o}");
                        for axis in 0..3 {
                            let mut larger = sides;
                            larger[axis] += 1;
                            assert!(
                                sides[axis] == MAX_SIDE || !empty(o, larger),
                                "{m} octant {o}: {sides} grows along {axis}"
                            );
                        }
                        grown += usize::from(sides.max_element() > sides.min_element());
                        checked += 1;
                    }
                }
            }
        }
        assert!(
            checked > 300 && grown > 100,
            "{checked} boxes, {grown} grown"
        );
        assert_eq!(octant(IVec3::new(1, -1, 0)), 2);
        assert_eq!(octant(IVec3::new(-1, 1, -1)), 5);
    }
}
