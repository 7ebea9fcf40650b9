//! How far each empty cell of an occupied macrocell is from the nearest occupied cell
//! (Chebyshev distance, in cells): proximity clouds (Cohen & Sheffer 1994) at the level of
//! cells. Most of a walk's steps are through empty cells of macrocells that a surface
//! passes through; a cell that knows the cube around it is empty lets the walk leave that
//! whole cube in one step.
//!
//! Computed per macrocell from the occupancy bits of it and its 26 neighbours, by growing
//! the occupied cells one cell at a time (a dilation by the 3³ cube, done on rows of bits).

use super::cells::MACRO_CELLS;

/// Cells along a macrocell's edge.
const SIDE: usize = 8;
/// The window a macrocell's distances are found in: it and one macrocell on every side.
const WINDOW: usize = 3 * SIDE;
/// Distances are found up to this many dilations; a cell farther from every occupied
/// cell gets `MAX_RADIUS + 1` (all cells within `MAX_RADIUS` are known to be empty, and
/// the window holds no more).
pub(super) const MAX_RADIUS: u8 = SIDE as u8;

/// One gap per cell of a macrocell, two to a byte (cell `l` in byte `l / 2`, the low
/// nibble for even `l`): the Chebyshev distance `d` to the nearest occupied cell, so the
/// cube of cells within `d − 1` of the cell is empty (0 for an occupied cell).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) struct Gaps([u8; MACRO_CELLS / 2]);

impl Gaps {
    /// The gap of cell `l` (its index within the macrocell).
    #[inline(always)]
    pub fn get(&self, l: usize) -> u32 {
        u32::from(self.0[l >> 1] >> ((l & 1) * 4)) & 0xf
    }

    /// The gaps of a macrocell, from the occupancy of it and its neighbours:
    /// `neighbour(dx, dy, dz)` (each −1, 0 or 1) gives a neighbour's occupancy words (bit
    /// `x + 8y` of word `z` for its cell (x, y, z)), `None` where it is empty or outside.
    pub fn of(neighbour: impl Fn(i32, i32, i32) -> Option<[u64; SIDE]>) -> Gaps {
        // Occupancy of the 24³ window as rows along x: rows[z][y], bit x.
        let mut rows = [[0u32; WINDOW]; WINDOW];
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
                            rows[oz + z][oy + y] |= row << ox;
                        }
                    }
                }
            }
        }
        let mut gaps = [0u8; MACRO_CELLS / 2];
        let mut known = [[0u32; SIDE]; SIDE];
        for (z, plane) in known.iter_mut().enumerate() {
            for (y, row) in plane.iter_mut().enumerate() {
                *row = central(rows[SIDE + z][SIDE + y]);
            }
        }
        let mut set = |x: usize, y: usize, z: usize, d: u8| {
            let l = x + SIDE * (y + SIDE * z);
            gaps[l >> 1] |= d << ((l & 1) * 4);
        };
        let mut scratch = Scratch::default();
        for d in 1..=MAX_RADIUS {
            if known.iter().flatten().all(|&row| row == 0xff) {
                break;
            }
            dilate(&mut rows, d as usize, &mut scratch);
            for z in 0..SIDE {
                for y in 0..SIDE {
                    let reached = central(rows[SIDE + z][SIDE + y]);
                    let mut new = reached & !known[z][y];
                    known[z][y] |= new;
                    while new != 0 {
                        set(new.trailing_zeros() as usize, y, z, d);
                        new &= new - 1;
                    }
                }
            }
        }
        for (z, plane) in known.iter().enumerate() {
            for (y, &row) in plane.iter().enumerate() {
                let mut far = !row & 0xff;
                while far != 0 {
                    set(far.trailing_zeros() as usize, y, z, MAX_RADIUS + 1);
                    far &= far - 1;
                }
            }
        }
        Gaps(gaps)
    }
}

/// The central macrocell's 8 bits of a window row.
fn central(row: u32) -> u32 {
    (row >> SIDE) & 0xff
}

/// Work arrays of [`dilate`], kept between its calls.
struct Scratch {
    x: [[u32; WINDOW]; WINDOW],
    xy: [[u32; WINDOW]; WINDOW],
}

impl Default for Scratch {
    fn default() -> Scratch {
        Scratch {
            x: [[0; WINDOW]; WINDOW],
            xy: [[0; WINDOW]; WINDOW],
        }
    }
}

/// The window grown by one cell in every direction (26 neighbours), for the `d`-th time:
/// along x by shifting each row, then along y and z by or-ing neighbouring rows. Only the
/// rows `d..WINDOW − d` (in y and z) are brought up to date: the central macrocell's
/// distances up to `MAX_RADIUS` depend on no others in the dilations still to come, and
/// those rows' neighbours were up to date after the previous one.
// Rows are read beside the one written (y ± 1, z ± 1): index loops say that most plainly.
#[allow(clippy::needless_range_loop)]
fn dilate(rows: &mut [[u32; WINDOW]; WINDOW], d: usize, scratch: &mut Scratch) {
    let mask = (1u32 << WINDOW) - 1;
    let (lo, hi) = (d, WINDOW - d);
    let (outer_lo, outer_hi) = (lo - 1, hi + 1);
    for z in outer_lo..outer_hi {
        for y in outer_lo..outer_hi {
            let r = rows[z][y];
            scratch.x[z][y] = (r | (r << 1) | (r >> 1)) & mask;
        }
    }
    for z in outer_lo..outer_hi {
        for y in lo..hi {
            scratch.xy[z][y] = scratch.x[z][y - 1] | scratch.x[z][y] | scratch.x[z][y + 1];
        }
    }
    for z in lo..hi {
        for y in lo..hi {
            rows[z][y] = scratch.xy[z - 1][y] | scratch.xy[z][y] | scratch.xy[z + 1][y];
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Gaps found by brute force over the window: the distance to the nearest occupied cell.
    #[test]
    fn gaps_are_the_distance_to_the_nearest_occupied_cell() {
        let mut rng = crate::render::sampling::Rng::new(5, 5);
        let mut coordinate = || (rng.next_u32() % WINDOW as u32) as i32 - SIDE as i32;
        for round in 0..40 {
            // A few occupied cells scattered over the window, some neighbours empty.
            let mut occupied = std::collections::HashSet::new();
            for _ in 0..(1 + round % 6) {
                let c = [coordinate(), coordinate(), coordinate()];
                occupied.insert(c);
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
            let gaps = Gaps::of(words);
            for z in 0..8 {
                for y in 0..8 {
                    for x in 0..8 {
                        let nearest = occupied
                            .iter()
                            .map(|o| (o[0] - x).abs().max((o[1] - y).abs()).max((o[2] - z).abs()))
                            .min()
                            .unwrap();
                        let want = nearest.min(MAX_RADIUS as i32 + 1) as u32;
                        let l = (x + 8 * (y + 8 * z)) as usize;
                        assert_eq!(gaps.get(l), want, "cell ({x}, {y}, {z}), round {round}");
                    }
                }
            }
        }
    }
}
