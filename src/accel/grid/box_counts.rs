//! Counting the occupied cells of any box of a 3D grid in constant time, from a table of
//! sums (a summed-area table in three dimensions, Crow 1984): for checking that the
//! distances the walk leaps by never pass over an occupied cell.

use glam::IVec3;

/// Occupied cells per box of a grid of `resolution` cells.
pub(super) struct BoxCounts {
    resolution: IVec3,
    /// `sums[(x, y, z)]`: occupied cells with all coordinates below (x, y, z); one more
    /// entry than cells along each axis.
    sums: Vec<u32>,
}

impl BoxCounts {
    /// The table for a grid whose cell `c` is occupied when `occupied(c)`.
    pub fn new(resolution: IVec3, occupied: impl Fn(IVec3) -> bool) -> BoxCounts {
        let mut counts = BoxCounts {
            resolution,
            sums: vec![0; ((resolution + 1).as_uvec3().element_product()) as usize],
        };
        for z in 0..resolution.z {
            for y in 0..resolution.y {
                for x in 0..resolution.x {
                    let own = u32::from(occupied(IVec3::new(x, y, z)));
                    let at = |dx: i32, dy: i32, dz: i32| counts.sum(x + dx, y + dy, z + dz);
                    let value = own
                        .wrapping_add(at(0, 1, 1))
                        .wrapping_add(at(1, 0, 1))
                        .wrapping_add(at(1, 1, 0))
                        .wrapping_sub(at(0, 0, 1))
                        .wrapping_sub(at(0, 1, 0))
                        .wrapping_sub(at(1, 0, 0))
                        .wrapping_add(at(0, 0, 0));
                    let i = counts.index(x + 1, y + 1, z + 1);
                    counts.sums[i] = value;
                }
            }
        }
        counts
    }

    fn index(&self, x: i32, y: i32, z: i32) -> usize {
        let (sx, sy) = (
            self.resolution.x as usize + 1,
            self.resolution.y as usize + 1,
        );
        x as usize + sx * (y as usize + sy * z as usize)
    }

    fn sum(&self, x: i32, y: i32, z: i32) -> u32 {
        self.sums[self.index(x, y, z)]
    }

    /// Occupied cells in the box `lo..=hi`, clipped to the grid.
    pub fn count(&self, lo: IVec3, hi: IVec3) -> u32 {
        let lo = lo.max(IVec3::ZERO);
        let hi = (hi + 1).min(self.resolution);
        if lo.cmpge(hi).any() {
            return 0;
        }
        self.sum(hi.x, hi.y, hi.z)
            .wrapping_sub(self.sum(lo.x, hi.y, hi.z))
            .wrapping_sub(self.sum(hi.x, lo.y, hi.z))
            .wrapping_sub(self.sum(hi.x, hi.y, lo.z))
            .wrapping_add(self.sum(lo.x, lo.y, hi.z))
            .wrapping_add(self.sum(lo.x, hi.y, lo.z))
            .wrapping_add(self.sum(hi.x, lo.y, lo.z))
            .wrapping_sub(self.sum(lo.x, lo.y, lo.z))
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
