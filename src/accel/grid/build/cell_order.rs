//! The build's counting sort: (cell, triangle) pairs, made in triangle order, laid out in
//! cell order, in parallel.
//!
//! The cells' storage keys are cut into parts of whole macrocells, and each chunk of
//! triangles puts its pairs into one bucket per part as it makes them. Every part is then
//! counted, prefix-summed and scattered on its own (a radix sort's first pass, then a
//! counting sort within each part): a part's counts fit in the second-level cache, and no
//! part waits for another. Within a cell, triangles keep the order of the chunks and of the
//! pairs within each, so the result is the same on any number of threads.

use rayon::prelude::*;

use crate::accel::grid::storage::macrocell::MACRO_CELLS;
use crate::accel::huge_pages;

/// Parts the keys are cut into, at most (at least half as many in a large grid): enough
/// for two threads to share the work evenly however the occupied macrocells cluster, few
/// enough that a chunk's buckets stay small.
const MAX_PARTS: usize = 64;

/// How the storage keys are cut into parts of whole macrocells.
#[derive(Clone, Copy, Debug)]
pub(in crate::accel::grid) struct KeyParts {
    /// Keys per part (the last may have fewer): a power of two, so that a key's part is a
    /// shift away (a division by it was the overlap tests' costliest instruction).
    part_keys: usize,
    /// log2 of `part_keys`.
    part_shift: u32,
    /// Number of parts.
    parts: usize,
}

/// The pairs of one chunk of triangles, one bucket per part, each in the order made.
pub(in crate::accel::grid) type Buckets = Vec<Vec<(u32, u32)>>;

/// Triangle numbers in cell order, and how they divide among the cells.
pub(in crate::accel::grid) struct CellOrder {
    /// Per storage key, the cell's number of triangles.
    pub counts: Vec<u32>,
    /// Per storage key in order, the cell's triangles in mesh order, all cells after one
    /// another.
    pub sorted: Vec<u32>,
}

impl KeyParts {
    /// The parts of `keys` storage keys (a whole number of macrocells).
    pub fn new(keys: usize) -> KeyParts {
        let macrocells = keys.div_ceil(MACRO_CELLS).max(1);
        let part_keys = macrocells.div_ceil(MAX_PARTS).next_power_of_two() * MACRO_CELLS;
        KeyParts {
            part_keys,
            part_shift: part_keys.trailing_zeros(),
            parts: keys.div_ceil(part_keys).max(1),
        }
    }

    /// One empty bucket per part.
    pub fn buckets(&self) -> Buckets {
        vec![Vec::new(); self.parts]
    }

    /// Puts the pair (`key`, `triangle`) into its part's bucket.
    #[inline]
    pub fn push(&self, buckets: &mut Buckets, key: usize, triangle: u32) {
        buckets[key >> self.part_shift].push((key as u32, triangle));
    }

    /// Sorts the pairs of `chunks` (in triangle order) into cell order over `keys` keys.
    pub fn sort(&self, chunks: &[Buckets], keys: usize) -> CellOrder {
        let pairs_of = |part: usize| chunks.iter().flat_map(move |c| &c[part]);
        let mut counts = huge_pages::filled(keys, 0u32);
        let in_part: Vec<usize> = counts
            .par_chunks_mut(self.part_keys)
            .enumerate()
            .map(|(part, counts)| {
                let first = part * self.part_keys;
                let mut n = 0;
                for &(key, _) in pairs_of(part) {
                    counts[key as usize - first] += 1;
                    n += 1;
                }
                n
            })
            .collect();
        let mut sorted = huge_pages::filled(in_part.iter().sum(), 0u32);
        let mut slices = Vec::with_capacity(in_part.len());
        let mut rest = sorted.as_mut_slice();
        for &n in &in_part {
            let (slice, tail) = rest.split_at_mut(n);
            slices.push(slice);
            rest = tail;
        }
        // Each part's cells' first places in its slice (the counts stay as they are).
        slices
            .into_par_iter()
            .zip(counts.par_chunks(self.part_keys))
            .enumerate()
            .for_each_init(Vec::new, |next, (part, (slice, counts))| {
                let first = part * self.part_keys;
                next.clear();
                let mut start = 0u32;
                for &n in counts {
                    next.push(start);
                    start += n;
                }
                for &(key, triangle) in pairs_of(part) {
                    let place = &mut next[key as usize - first];
                    slice[*place as usize] = triangle;
                    *place += 1;
                }
            });
        CellOrder { counts, sorted }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Pairs made in chunks, in triangle order, come out in cell order with each cell's
    /// triangles in triangle order, however many keys the parts hold.
    #[test]
    fn pairs_come_out_in_cell_order_and_triangle_order_within_a_cell() {
        for macrocells in [1, 3, 64, 65, 200] {
            let keys = macrocells * MACRO_CELLS;
            let parts = KeyParts::new(keys);
            let mut expected: Vec<(u32, u32)> = Vec::new();
            let chunks: Vec<Buckets> = (0..7u32)
                .map(|c| {
                    let mut buckets = parts.buckets();
                    for i in 0..300u32 {
                        let triangle = c * 300 + i;
                        // Keys spread over the whole range, some cells met several times.
                        let key = (triangle as usize * 7919 + (i % 5) as usize) % keys;
                        parts.push(&mut buckets, key, triangle);
                        expected.push((key as u32, triangle));
                    }
                    buckets
                })
                .collect();
            expected.sort_by_key(|&(key, triangle)| (key, triangle));
            let order = parts.sort(&chunks, keys);
            assert_eq!(
                order.sorted,
                expected.iter().map(|p| p.1).collect::<Vec<_>>(),
                "{macrocells} macrocells"
            );
            let mut counts = vec![0u32; keys];
            for &(key, _) in &expected {
                counts[key as usize] += 1;
            }
            assert_eq!(order.counts, counts, "{macrocells} macrocells");
        }
    }
}
