//! Counting the occupied cells of any box of a 3D grid in constant time, from a table of
//! sums (a summed-area table in three dimensions, Crow 1984): for finding how far the
//! walk may leap from an empty macrocell ([`crate::accel::grid::storage::reach`]), and for checking that no
//! leap passes over an occupied cell.

use glam::IVec3;
use rayon::prelude::*;

use crate::accel::huge_pages;

/// Occupied cells per box of a grid of `resolution` cells.
pub(in crate::accel::grid) struct BoxCounts {
    resolution: IVec3,
    /// `sums[(x, y, z)]`: occupied cells with all coordinates below (x, y, z); one more
    /// entry than cells along each axis.
    sums: Vec<u32>,
}

impl BoxCounts {
    /// The table for a grid whose cell `c` is occupied when `occupied(c)`.
    pub fn new(resolution: IVec3, occupied: impl Fn(IVec3) -> bool + Sync) -> BoxCounts {
        BoxCounts::from_rows(resolution, |y, z, row| {
            for (x, cell) in row.iter_mut().enumerate() {
                *cell = occupied(IVec3::new(x as i32, y, z));
            }
        })
    }

    /// The table for a grid whose row of cells along x at `(y, z)` is occupied where
    /// `row(y, z, occupied)` sets `occupied` (as long as the row, cleared) true: the
    /// occupancy summed along x, then y, then z, one axis at a time (each pass over rows or
    /// planes that are independent, in parallel where they are). A row at a time lets the
    /// caller read its storage in runs instead of finding each cell's place.
    pub fn from_rows(resolution: IVec3, row: impl Fn(i32, i32, &mut [bool]) + Sync) -> BoxCounts {
        let (sx, sy) = (resolution.x as usize + 1, resolution.y as usize + 1);
        let plane = sx * sy;
        let mut sums = huge_pages::filled(plane * (resolution.z as usize + 1), 0u32);
        // Along x, then y, within each plane of constant z (the first plane stays 0).
        sums.par_chunks_mut(plane)
            .skip(1)
            .enumerate()
            .for_each_init(
                || vec![false; resolution.x as usize],
                |occupied, (z, plane)| {
                    for y in 0..resolution.y {
                        occupied.fill(false);
                        row(y, z as i32, occupied);
                        let sums = &mut plane[sx * (y as usize + 1)..][..sx];
                        let mut sum = 0;
                        for (x, &cell) in occupied.iter().enumerate() {
                            sum += u32::from(cell);
                            sums[x + 1] = sum;
                        }
                    }
                    for y in 1..sy {
                        let (before, rest) = plane.split_at_mut(sx * y);
                        for (sum, below) in rest[..sx].iter_mut().zip(&before[sx * (y - 1)..]) {
                            *sum = sum.wrapping_add(*below);
                        }
                    }
                },
            );
        // Along z, in parallel over runs of each plane (a run's column of planes is summed
        // apart from the others).
        const RUN: usize = 4096;
        let mut columns: Vec<Vec<&mut [u32]>> =
            (0..plane.div_ceil(RUN)).map(|_| Vec::new()).collect();
        for plane_sums in sums.chunks_mut(plane) {
            for (column, run) in columns.iter_mut().zip(plane_sums.chunks_mut(RUN)) {
                column.push(run);
            }
        }
        columns.into_par_iter().for_each(|mut column| {
            for z in 1..column.len() {
                let (below, rest) = column.split_at_mut(z);
                for (sum, below) in rest[0].iter_mut().zip(below[z - 1].iter()) {
                    *sum = sum.wrapping_add(*below);
                }
            }
        });
        BoxCounts { resolution, sums }
    }

    /// Cells along each axis of the grid.
    pub fn resolution(&self) -> IVec3 {
        self.resolution
    }

    /// Occupied cells in the box `lo..=hi`, clipped to the grid (inlined: a leap's box
    /// takes a dozen of them).
    #[inline(always)]
    pub fn count(&self, lo: IVec3, hi: IVec3) -> u32 {
        let lo = lo.max(IVec3::ZERO);
        let hi = (hi + 1).min(self.resolution);
        if lo.cmpge(hi).any() {
            return 0;
        }
        // Offsets of the box's two x, y and z planes in the table.
        let (sx, sy) = (
            self.resolution.x as usize + 1,
            self.resolution.y as usize + 1,
        );
        let (x0, x1) = (lo.x as usize, hi.x as usize);
        let (y0, y1) = (sx * lo.y as usize, sx * hi.y as usize);
        let (z0, z1) = (sx * sy * lo.z as usize, sx * sy * hi.z as usize);
        let sum = |x: usize, y: usize, z: usize| self.sums[x + y + z];
        sum(x1, y1, z1)
            .wrapping_sub(sum(x0, y1, z1))
            .wrapping_sub(sum(x1, y0, z1))
            .wrapping_sub(sum(x1, y1, z0))
            .wrapping_add(sum(x0, y0, z1))
            .wrapping_add(sum(x0, y1, z0))
            .wrapping_add(sum(x1, y0, z0))
            .wrapping_sub(sum(x0, y0, z0))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn box_counts_match_counting_cell_by_cell() {
        let r = IVec3::new(7, 5, 6);
        let occupied = |c: IVec3| (c.x * 7 + c.y * 3 + c.z * 5) % 4 == 0;
        let counts = BoxCounts::new(r, occupied);
        for (lo, hi) in [
            (IVec3::ZERO, r - 1),
            (IVec3::new(1, 2, 0), IVec3::new(4, 2, 5)),
            (IVec3::new(-3, -1, 2), IVec3::new(2, 9, 3)),
            (IVec3::new(3, 3, 3), IVec3::new(2, 4, 4)),
        ] {
            let mut expected = 0;
            for z in lo.z.max(0)..=hi.z.min(r.z - 1) {
                for y in lo.y.max(0)..=hi.y.min(r.y - 1) {
                    for x in lo.x.max(0)..=hi.x.min(r.x - 1) {
                        expected += u32::from(occupied(IVec3::new(x, y, z)));
                    }
                }
            }
            assert_eq!(counts.count(lo, hi), expected, "{lo} {hi}");
        }
    }
}
