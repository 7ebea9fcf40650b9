//! How far empty space reaches ahead of a ray from each empty cell of an occupied
//! macrocell: for each of the eight octants of directions, the side (in cells, up to
//! [`MAX_REACH`]) of the largest cube of empty cells that has the cell's *unit* in its
//! corner and extends in that octant's directions — the octant reaches of
//! [`crate::accel::grid::storage::reach`], one level down. Most of a walk's steps are through empty cells of
//! macrocells a surface passes through; a ray moving into the octant stays in the cube
//! until it crosses one of its far faces, so the walk leaves the whole cube in one step.
//! Unlike a distance to the nearest occupied cell (proximity clouds, Cohen & Sheffer 1994,
//! which this replaces), the cube is bounded only by what lies ahead, not by the surface
//! the ray has just left or passes.
//!
//! The unit is the cell itself, or for a grid whose blocks are many times the caches a
//! 2³ unit of cells ([`unit_shift_for`]): an octant's reaches then take 32 bytes (half a
//! cache line) instead of 256 (four lines), so a ray entering a macrocell asks for one line
//! of reaches instead of four, and the full dragon's reaches take 0.4 MB instead of 3.0,
//! which stay in the caches beside the blocks. Its cubes are coarser (a cell in a unit
//! that holds an occupied cell is left by a plain step): on the full dragon 0.94–0.95 the
//! time of outside, bounce and shadow rays, 1.04 of camera rays (whose reaches are in
//! cache), and on the 11k dragon, which is all in cache, 1.03–1.06 (measured at
//! ed4cc45; docs/design/grid.md).
//!
//! Computed per macrocell and octant on rows of bits over the macrocell and its neighbours
//! towards the octant: the cells whose cube of side k + 1 is empty are those whose cubes of
//! side k at the cell and at its seven neighbours towards the octant are all empty — three
//! `and`s per row (along x, then y, then z) per side. A 2³ unit's reach is then that of
//! its cell nearest the octant's origin, whose cubes of two or more cells cover the unit.

use super::macrocell::MACRO_CELLS;
use crate::accel::grid::storage::reach::moves_up;

/// Cells along a macrocell's edge.
const SIDE: usize = 8;
/// The window a macrocell's reaches are found in: it and one macrocell on every side.
const WINDOW: usize = 3 * SIDE;
/// Reaches are found up to this side; a cube of side `MAX_REACH` from any cell of the
/// macrocell stays within the macrocell and its neighbours towards the octant.
pub(in crate::accel::grid) const MAX_REACH: u32 = SIDE as u32;

/// Grids whose blocks take more bytes than this keep reaches per 2³ unit of cells, the
/// others per cell ([`unit_shift_for`]). Between the 203k dragon's 23 MB of blocks (2³
/// units: 0.97–1.07 the time of per-cell reaches, mixed) and the full dragon's 88 MB
/// (0.94–0.95 on outside, bounce and shadow rays, 1.04 on camera rays): about where the
/// blocks outgrow a large last-level cache.
pub(in crate::accel::grid) const LARGE_BLOCKS: usize = 48 << 20;

/// log2 of a unit's side for a grid whose blocks take `block_bytes`: 0 (a unit is a cell)
/// or 1 (2³ cells).
pub(in crate::accel::grid) fn unit_shift_for(block_bytes: usize) -> u32 {
    u32::from(block_bytes > LARGE_BLOCKS)
}

/// Bytes of one octant's reaches of a macrocell's units of 2^`unit_shift` cells a side,
/// two to a byte.
#[inline(always)]
pub(in crate::accel::grid) fn octant_bytes(unit_shift: u32) -> usize {
    (MACRO_CELLS >> (3 * unit_shift)) / 2
}

/// The nibble of cell `l` (its index within the macrocell, x + 8y + 64z) among its
/// macrocell's units of 2^`unit_shift` cells a side (numbered x fastest).
#[inline(always)]
pub(in crate::accel::grid) fn unit_of(l: usize, unit_shift: u32) -> usize {
    match unit_shift {
        0 => l,
        _ => (l & 7) >> 1 | (l >> 4 & 3) << 2 | (l >> 7 & 3) << 4,
    }
}

/// The reach (0 or 2 to [`MAX_REACH`] for units of 2³; 0 to [`MAX_REACH`] for cells) in
/// nibble `u` of an octant's reaches `bytes`.
#[inline(always)]
pub(in crate::accel::grid) fn nibble(bytes: &[u8], u: usize) -> u32 {
    u32::from(bytes[u >> 1] >> ((u & 1) * 4)) & 0xf
}

/// One octant's reach per cell of a macrocell, two to a byte (cell `l` in byte `l / 2`,
/// the low nibble for even `l`); 0 for an occupied cell.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct CellReaches([u8; MACRO_CELLS / 2]);

/// The reaches of a macrocell's units of 2^`unit_shift` cells a side, octant by octant
/// (as [`crate::accel::grid::storage::reach::octant`] numbers them; [`octant_bytes`] each), from the occupancy
/// of it and its neighbours: `neighbour(dx, dy, dz)` (each −1, 0 or 1) gives a neighbour's
/// occupancy words (bit `x + 8y` of word `z` for its cell (x, y, z)), `None` where it is
/// empty or outside the grid (outside counts as empty: a ray there has left the grid).
pub(in crate::accel::grid) fn reaches(
    neighbour: impl Fn(i32, i32, i32) -> Option<[u64; SIDE]>,
    unit_shift: u32,
) -> Vec<u8> {
    let cells = CellReaches::of(neighbour);
    let mut bytes = Vec::with_capacity(8 * octant_bytes(unit_shift));
    for (octant, cells) in cells.iter().enumerate() {
        match unit_shift {
            0 => bytes.extend_from_slice(&cells.0),
            _ => bytes.extend_from_slice(&cells.units(octant as u32)),
        }
    }
    bytes
}

impl CellReaches {
    /// The reach of cell `l` (its index within the macrocell).
    fn get(&self, l: usize) -> u32 {
        nibble(&self.0, l)
    }

    /// Each 2³ unit's reach towards `octant`: the reach of its cell nearest the octant's
    /// origin (the cube of two or more cells with that cell in its corner covers the
    /// unit), if at least 2, else 0.
    fn units(&self, octant: u32) -> [u8; MACRO_CELLS / 16] {
        let mut units = [0u8; MACRO_CELLS / 16];
        let back = |axis: usize| usize::from(!moves_up(octant, axis));
        for u in 0..MACRO_CELLS / 8 {
            let (x, y, z) = (
                2 * (u & 3) + back(0),
                2 * (u >> 2 & 3) + back(1),
                2 * (u >> 4) + back(2),
            );
            let reach = self.get(x + SIDE * (y + SIDE * z));
            let reach = if reach >= 2 { reach as u8 } else { 0 };
            units[u >> 1] |= reach << ((u & 1) * 4);
        }
        units
    }

    /// The reaches of a macrocell's cells in every octant ([`reaches`]).
    fn of(neighbour: impl Fn(i32, i32, i32) -> Option<[u64; SIDE]>) -> [CellReaches; 8] {
        // Empty cells of the 24³ window as rows along x: empty[z][y], bit x.
        let mut empty = [[(1u32 << WINDOW) - 1; WINDOW]; WINDOW];
        for dz in -1..=1 {
            for dy in -1..=1 {
                for dx in -1..=1 {
                    let Some(words) = neighbour(dx, dy, dz) else {
                        continue;
                    };
                    let (ox, oy, oz) = (
                        (dx + 1) as usize * SIDE,
                        (dy + 1) as usize * SIDE,
                        (dz + 1) as usize * SIDE,
                    );
                    for (z, word) in words.iter().enumerate() {
                        for y in 0..SIDE {
                            let row = ((word >> (8 * y)) & 0xff) as u32;
                            empty[oz + z][oy + y] &= !(row << ox);
                        }
                    }
                }
            }
        }
        std::array::from_fn(|octant| reaches_towards(&empty, octant as u32))
    }
}

/// The reaches towards `octant` of the central macrocell's cells, given the window's empty
/// cells.
fn reaches_towards(empty: &[[u32; WINDOW]; WINDOW], octant: u32) -> CellReaches {
    let up = [0, 1, 2].map(|a| moves_up(octant, a));
    // Only the central macrocell and the macrocells beside it towards the octant matter:
    // rows and planes `lo..lo + 2·SIDE` in y and z.
    let lo = |a: usize| if up[a] { SIDE } else { 0 };
    let (y0, z0) = (lo(1), lo(2));
    let mut cubes = [[0u32; 2 * SIDE]; 2 * SIDE];
    for (z, plane) in cubes.iter_mut().enumerate() {
        for (y, row) in plane.iter_mut().enumerate() {
            *row = empty[z0 + z][y0 + y];
        }
    }
    // Nibble counters, one per cell of a central row: the number of sides k whose cube
    // is empty (the cubes are nested, so that number is the reach).
    let mut counts = [[0u32; SIDE]; SIDE];
    let (cy, cz) = (SIDE - y0, SIDE - z0);
    let mut add = |cubes: &[[u32; 2 * SIDE]; 2 * SIDE]| {
        for (z, plane) in counts.iter_mut().enumerate() {
            for (y, count) in plane.iter_mut().enumerate() {
                *count += spread((cubes[cz + z][cy + y] >> SIDE) & 0xff);
            }
        }
    };
    add(&cubes);
    for _ in 1..MAX_REACH {
        grow(&mut cubes, up);
        add(&cubes);
    }
    let mut reaches = [0u8; MACRO_CELLS / 2];
    for (z, plane) in counts.iter().enumerate() {
        for (y, count) in plane.iter().enumerate() {
            let at = (SIDE * (y + SIDE * z)) / 2;
            reaches[at..at + 4].copy_from_slice(&count.to_le_bytes());
        }
    }
    CellReaches(reaches)
}

/// From the cells whose cube of side k towards the octant (`up` per axis) is empty, those
/// whose cube of side k + 1 is: the cell's cube and its neighbours' towards the octant
/// along x, then y, then z. Rows and planes at the far edge keep stale values, which no
/// central cell's reach up to `MAX_REACH` depends on.
fn grow(cubes: &mut [[u32; 2 * SIDE]; 2 * SIDE], up: [bool; 3]) {
    for plane in cubes.iter_mut() {
        for row in plane.iter_mut() {
            *row &= if up[0] { *row >> 1 } else { *row << 1 };
        }
    }
    let n = 2 * SIDE;
    for plane in cubes.iter_mut() {
        if up[1] {
            for y in 0..n - 1 {
                plane[y] &= plane[y + 1];
            }
        } else {
            for y in (1..n).rev() {
                plane[y] &= plane[y - 1];
            }
        }
    }
    if up[2] {
        for z in 0..n - 1 {
            let next = cubes[z + 1];
            for (row, above) in cubes[z].iter_mut().zip(next) {
                *row &= above;
            }
        }
    } else {
        for z in (1..n).rev() {
            let next = cubes[z - 1];
            for (row, below) in cubes[z].iter_mut().zip(next) {
                *row &= below;
            }
        }
    }
}

/// The eight bits of `bits` as the eight nibbles of a word, bit `i` to nibble `i`.
#[inline]
fn spread(bits: u32) -> u32 {
    SPREAD[bits as usize]
}

/// [`spread`] of every byte.
static SPREAD: [u32; 256] = {
    let mut table = [0u32; 256];
    let mut bits = 0;
    while bits < 256 {
        let mut i = 0;
        while i < SIDE {
            table[bits] |= ((bits as u32 >> i) & 1) << (4 * i);
            i += 1;
        }
        bits += 1;
    }
    table
};

#[cfg(test)]
mod tests {
    use super::*;

    /// Reaches found by trying every side: the largest cube of empty cells with the cell (or
    /// the unit) as its corner, towards the octant, within the window (outside it counts as
    /// empty).
    #[test]
    fn reaches_are_the_largest_empty_cube_towards_each_octant_of_cells_and_units() {
        let mut rng = crate::render::sampling::Rng::new(5, 5);
        let mut coordinate = || (rng.next_u32() % WINDOW as u32) as i32 - SIDE as i32;
        for round in 0..40 {
            // A few occupied cells scattered over the window, some neighbours empty.
            let mut occupied = std::collections::HashSet::new();
            for _ in 0..(1 + round % 12) {
                occupied.insert([coordinate(), coordinate(), coordinate()]);
            }
            let words = |dx: i32, dy: i32, dz: i32| {
                let mut w = [0u64; SIDE];
                for &[x, y, z] in &occupied {
                    let (mx, my, mz) = (x.div_euclid(8), y.div_euclid(8), z.div_euclid(8));
                    if (mx, my, mz) == (dx, dy, dz) {
                        let (lx, ly, lz) = (x.rem_euclid(8), y.rem_euclid(8), z.rem_euclid(8));
                        w[lz as usize] |= 1 << (lx + 8 * ly);
                    }
                }
                w.iter().any(|&b| b != 0).then_some(w)
            };
            let reaches = CellReaches::of(words);
            let (cells, units) = (super::reaches(words, 0), super::reaches(words, 1));
            for (octant, reaches) in reaches.iter().enumerate() {
                let cells = &cells[octant * octant_bytes(0)..][..octant_bytes(0)];
                let units = &units[octant * octant_bytes(1)..][..octant_bytes(1)];
                let s = [0, 1, 2].map(|a| if moves_up(octant as u32, a) { 1 } else { -1 });
                let cube_is_empty = |c: [i32; 3], k: i32| {
                    !occupied.iter().any(|o| {
                        (0..3).all(|a| {
                            let d = (o[a] - c[a]) * s[a];
                            (0..k).contains(&d)
                        })
                    })
                };
                for l in 0..MACRO_CELLS {
                    let c = [(l & 7) as i32, (l >> 3 & 7) as i32, (l >> 6) as i32];
                    let want = (1..=MAX_REACH as i32)
                        .take_while(|&k| cube_is_empty(c, k))
                        .count() as u32;
                    assert_eq!(
                        reaches.get(l),
                        want,
                        "cell {c:?}, octant {octant}, round {round}"
                    );
                    assert_eq!(nibble(cells, unit_of(l, 0)), want);
                    // The unit's reach: its cell nearest the octant's origin's, from 2.
                    let back = c.map(|x| x & !1);
                    let back = [0, 1, 2].map(|a| back[a] + i32::from(s[a] < 0));
                    let unit = (1..=MAX_REACH as i32)
                        .take_while(|&k| cube_is_empty(back, k))
                        .count() as u32;
                    assert_eq!(
                        nibble(units, unit_of(l, 1)),
                        if unit >= 2 { unit } else { 0 },
                        "cell {c:?}'s unit, octant {octant}, round {round}"
                    );
                }
            }
        }
    }
}
