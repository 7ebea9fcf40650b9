//! Which cells of a grid hold triangles, and where their blocks lie: a two-level index.
//!
//! The cells are grouped in macrocells of 8³. One word per macrocell says where its record
//! is, or that it is empty; for an empty macrocell, a box per octant of directions says how
//! far empty space reaches from it ([`crate::accel::grid::storage::reach`]), so the walk can leap over a whole box
//! of empty cells. An occupied macrocell has a record of the 512 occupancy bits of its
//! cells and the ranks, and beside it, for each octant, how far empty space reaches from
//! each cell (or 2³ unit of cells, [`crate::accel::grid::storage::cell_reach`]); a ray entering the macrocell
//! asks for the occupancy, the ranks and its own octant's reaches at once. Occupied cells
//! are numbered macrocell by macrocell, so an occupied cell's number is its word's rank
//! plus a popcount within one 64-bit word, and the offsets
//! of the cells of one macrocell lie together. A ray stepping through a macrocell thus reads
//! one record instead of occupancy words scattered over whole rows of the grid.

use std::ops::Range;

use glam::{IVec3, UVec3, Vec3A};
use rayon::prelude::*;

use crate::accel::grid::build::box_counts::BoxCounts;
use crate::accel::grid::storage::cell_reach;
use crate::accel::grid::storage::reach;

use super::macrocell::{MACRO_CELLS, MACRO_SHIFT};

/// Set in a macrocell's word when it is occupied; the other bits are then its record's
/// index. (An empty macrocell's word is 0.)
const OCCUPIED: u32 = 1 << 31;

/// The record a macrocell's word names, or `None` for an empty macrocell.
#[inline(always)]
fn record_in(word: u32) -> Option<usize> {
    (word & OCCUPIED != 0).then_some((word & !OCCUPIED) as usize)
}

/// What the walk needs to know about one occupied macrocell besides its reaches, in one
/// place so that entering the macrocell can ask for it at once: the occupancy of its 512
/// cells (x fastest, then y, then z), and per word of those bits the number of the word's
/// first occupied cell (so an occupied cell's number is one popcount away, with no loop
/// over words). Two cache lines.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[repr(C, align(64))]
struct Record {
    bits: [u64; MACRO_CELLS / 64],
    ranks: [u32; MACRO_CELLS / 64],
}

/// What the index says about one cell.
pub(in crate::accel::grid) enum Lookup {
    /// The cell's macrocell is empty (how far empty space reaches from it is
    /// [`CellIndex::macrocell_of`]'s answer).
    EmptyMacrocell,
    /// The cell is empty (its macrocell is not), and so is the cube of `reach` cells a
    /// side that has the cell's unit ([`CellIndex::unit_shift`]) in its corner and extends
    /// towards the octant asked about ([`crate::accel::grid::storage::cell_reach`]); for units of 2³ cells,
    /// `reach` is 0 when not even the unit is.
    EmptyCell { reach: u32 },
    /// The cell's blocks, and the cell's number among the occupied cells.
    Blocks(Range<usize>, usize),
}

/// The two-level index of a grid's occupied cells.
#[derive(Clone, Debug, Default)]
pub(in crate::accel::grid) struct CellIndex {
    /// Macrocells per axis.
    macro_resolution: UVec3,
    /// Where a macrocell's y and z coordinates are shifted to in its index
    /// ([`CellIndex::macro_index`]).
    slot_shift_y: u32,
    slot_shift_z: u32,
    /// Per macrocell (at [`CellIndex::macro_index`]; words between the rows unused):
    /// `OCCUPIED |` its record's index, or 0 when it is empty. Sixteen to a cache line:
    /// a walk among occupied macrocells finds its neighbours' words in lines it has read.
    macro_words: Vec<u32>,
    /// Per macrocell (at `macro_index · 8`), one entry per octant of directions, the eight
    /// side by side: for an empty macrocell the sides of its empty box towards that octant
    /// ([`reach`], [`reach::pack`]), else 0. Read only for an empty macrocell (apart from
    /// the words: putting the boxes of all eight octants in the words' places cost rays
    /// among occupied macrocells up to 3 % of their time), at an address known with the
    /// word's, so the two loads overlap.
    macro_boxes: Vec<u32>,
    records: Vec<Record>,
    /// log2 of the side, in cells, of the units reaches are kept for
    /// ([`cell_reach::unit_shift_for`]).
    unit_shift: u32,
    /// Per record and octant ([`CellIndex::reach_bytes`]), the reaches of the macrocell's
    /// units, in cache lines: an octant's reaches are whole lines (per cell) or half of one
    /// (per 2³ unit).
    reaches: Vec<ReachLine>,
    /// Per record, the number of its first occupied cell (its first rank, kept apart so
    /// that its offsets can be asked for together with the record, before it arrives).
    first_cells: Vec<u32>,
    /// For the k-th occupied cell, `offsets[k]..offsets[k + 1]` indexes the blocks.
    offsets: Vec<u32>,
    /// For the k-th occupied cell, the word of its triangles' box within it
    /// ([`crate::accel::grid::storage::cell_box`]); empty for a grid that keeps no boxes.
    cell_boxes: Vec<u32>,
    /// How far the walk grows each box ([`crate::accel::grid::storage::cell_box::margin_for`]); `None` for a grid that
    /// keeps no boxes.
    box_margin: Option<Vec3A>,
}

impl CellIndex {
    /// Macrocells per axis for a grid of `resolution` cells.
    pub fn macro_resolution_for(resolution: UVec3) -> UVec3 {
        (resolution + UVec3::splat((1 << MACRO_SHIFT) - 1)) >> MACRO_SHIFT as u32
    }

    /// Where cell `c` is counted in storage order (macrocell by macrocell), for a grid of
    /// `macro_resolution` macrocells.
    #[inline]
    pub fn storage_key(macro_resolution: UVec3, c: UVec3) -> usize {
        let m = c >> MACRO_SHIFT as u32;
        let l = c & UVec3::splat((1 << MACRO_SHIFT) - 1);
        let macro_index = (m.x + macro_resolution.x * (m.y + macro_resolution.y * m.z)) as usize;
        macro_index * MACRO_CELLS + local_index(l.as_ivec3())
    }

    /// The index of a grid whose cell with storage key `k` holds `triangles[k]` triangles,
    /// in blocks of `lanes` of `block_bytes` each, laid out in key order.
    pub fn build(
        resolution: UVec3,
        triangles: &[u32],
        lanes: u32,
        block_bytes: usize,
    ) -> CellIndex {
        let macro_resolution = CellIndex::macro_resolution_for(resolution);
        let m = macro_resolution;
        let macro_count = (m.x * m.y * m.z) as usize;
        debug_assert_eq!(triangles.len(), macro_count * MACRO_CELLS);
        let bits = |n: u32| u32::BITS - (n - 1).leading_zeros();
        let (slot_shift_y, slot_shift_z) = (bits(m.x), bits(m.x) + bits(m.y));
        let mut index = CellIndex {
            macro_resolution,
            slot_shift_y,
            slot_shift_z,
            macro_words: vec![0; (m.z as usize) << slot_shift_z],
            macro_boxes: vec![0; ((m.z as usize) << slot_shift_z) * 8],
            ..CellIndex::default()
        };
        // Per macrocell (x fastest): its record, if occupied.
        let mut record_of = vec![None; macro_count];
        let mut total = 0u32;
        let mut occupancy = Vec::new();
        let mut ranks = Vec::new();
        for (mi, cells) in triangles.chunks(MACRO_CELLS).enumerate() {
            if cells.iter().all(|&n| n == 0) {
                continue;
            }
            record_of[mi] = Some(occupancy.len() as u32);
            let mut bits = [0u64; MACRO_CELLS / 64];
            let mut first = [0u32; MACRO_CELLS / 64];
            for (l, &n) in cells.iter().enumerate() {
                if l & 63 == 0 {
                    first[l >> 6] = index.offsets.len() as u32;
                }
                if n > 0 {
                    bits[l >> 6] |= 1 << (l & 63);
                    index.offsets.push(total);
                    total += n.div_ceil(lanes);
                }
            }
            occupancy.push(bits);
            ranks.push(first);
        }
        index.offsets.push(total);
        // A row's cells lie in runs of eight in storage, one run per macrocell it crosses.
        let cells = BoxCounts::from_rows(resolution.as_ivec3(), |y, z, row| {
            for (mx, run) in row.chunks_mut(1 << MACRO_SHIFT).enumerate() {
                let first = UVec3::new((mx as u32) << MACRO_SHIFT, y as u32, z as u32);
                let key = CellIndex::storage_key(macro_resolution, first);
                for (cell, &n) in run.iter_mut().zip(&triangles[key..]) {
                    *cell = n > 0;
                }
            }
        });
        index.fill_entries(&cells, &record_of);
        index.first_cells = ranks.iter().map(|r| r[0]).collect();
        index.records = occupancy
            .into_iter()
            .zip(ranks)
            .map(|(bits, ranks)| Record { bits, ranks })
            .collect();
        index.fill_reaches(cell_reach::unit_shift_for(total as usize * block_bytes));
        index
    }

    /// The macrocells' entries: the occupied ones' records (`record_of`, per macrocell x
    /// fastest), and the empty ones' boxes ([`reach`]) from the counts of occupied cells.
    fn fill_entries(&mut self, cells: &BoxCounts, record_of: &[Option<u32>]) {
        let boxes = reach::boxes(self.macro_resolution.as_ivec3(), cells);
        for (mi, (boxes, record)) in boxes.into_iter().zip(record_of).enumerate() {
            let slot = self.macro_index(dense_coordinates(self.macro_resolution, mi));
            match record {
                Some(record) => self.macro_words[slot] = OCCUPIED | record,
                None => self.macro_boxes[slot * 8..slot * 8 + 8].copy_from_slice(&boxes),
            }
        }
    }

    /// Every macrocell's coordinates, record (`None` when empty) and boxes, x fastest.
    fn macrocells(&self) -> impl Iterator<Item = (IVec3, Option<usize>, &[u32])> + '_ {
        let m = self.macro_resolution;
        (0..(m.x * m.y * m.z) as usize).map(move |mi| {
            let c = dense_coordinates(m, mi);
            let slot = self.macro_index(c);
            (
                c,
                record_in(self.macro_words[slot]),
                &self.macro_boxes[slot * 8..slot * 8 + 8],
            )
        })
    }

    /// Finds the reaches ([`crate::accel::grid::storage::cell_reach`]) of every occupied macrocell's units of
    /// 2^`unit_shift` cells a side, in parallel over the macrocells, from their occupancy.
    pub fn fill_reaches(&mut self, unit_shift: u32) {
        let m = self.macro_resolution.as_ivec3();
        let mut at = vec![IVec3::ZERO; self.records.len()];
        for (c, record, _) in self.macrocells() {
            if let Some(record) = record {
                at[record] = c;
            }
        }
        let index = &*self;
        let bytes: Vec<Vec<u8>> = at
            .par_iter()
            .map(|&c| {
                cell_reach::reaches(
                    |dx, dy, dz| {
                        let n = c + IVec3::new(dx, dy, dz);
                        if n.cmplt(IVec3::ZERO).any() || n.cmpge(m).any() {
                            return None;
                        }
                        let record = index.macrocell_of(n << MACRO_SHIFT, 0).ok();
                        record.map(|record| index.records[record].bits)
                    },
                    unit_shift,
                )
            })
            .collect();
        self.unit_shift = unit_shift;
        self.reaches = bytes
            .concat()
            .chunks(64)
            .map(|line| ReachLine(line.try_into().expect("whole lines")))
            .collect();
    }

    /// log2 of the side, in cells, of the units whose reaches the index keeps: the unit
    /// shift [`crate::accel::grid::frame::CellWalk::leave_cube`] takes.
    #[inline(always)]
    pub fn unit_shift(&self) -> u32 {
        self.unit_shift
    }

    /// Where record `record`'s reaches towards `octant` begin, in bytes from the start of
    /// `reaches`, for units of 2^`UNIT` cells (the index's [`CellIndex::unit_shift`]).
    #[inline(always)]
    fn reach_bytes<const UNIT: u32>(&self, record: usize, octant: u32) -> usize {
        debug_assert_eq!(UNIT, self.unit_shift);
        (record * 8 + octant as usize) * cell_reach::octant_bytes(UNIT)
    }

    /// Where macrocell `m`'s word lies: its coordinates' bits side by side, each axis given
    /// as many bits as its largest coordinate needs, so the index is two shifts and two ors
    /// (the walk's chain from one leap to the next goes through it) instead of two
    /// multiply-adds.
    #[inline(always)]
    fn macro_index(&self, m: IVec3) -> usize {
        (m.x as u32 | (m.y as u32) << self.slot_shift_y | (m.z as u32) << self.slot_shift_z)
            as usize
    }

    /// What the index says about cell `c` (inside the grid) to a ray moving into `octant`.
    #[inline(always)]
    pub fn lookup(&self, c: IVec3, octant: u32) -> Lookup {
        match self.macrocell_of(c, octant) {
            Err(_) => Lookup::EmptyMacrocell,
            Ok(record) => match self.unit_shift {
                0 => self.lookup_in::<0>(record, c, octant),
                _ => self.lookup_in::<1>(record, c, octant),
            },
        }
    }

    /// The record of cell `c`'s macrocell, or (`Err`) when it is empty the sides in cells
    /// of its empty box towards `octant` ([`reach`]).
    #[inline(always)]
    pub fn macrocell_of(&self, c: IVec3, octant: u32) -> Result<usize, Vec3A> {
        let slot = self.macro_index(c >> MACRO_SHIFT);
        match record_in(self.macro_words[slot]) {
            Some(record) => Ok(record),
            None => Err(byte_lanes(self.macro_boxes[slot << 3 | octant as usize])),
        }
    }

    /// Starts loading what a ray moving into `octant` reads of record `record` (its
    /// occupancy, ranks and that octant's reaches) and the first two cache lines of its
    /// cells' offsets at once: the walk has just entered its macrocell and will read
    /// several parts of them, one after another.
    #[inline(always)]
    pub fn prefetch_record<const UNIT: u32, const BOXED: bool>(&self, record: usize, octant: u32) {
        use crate::accel::grid::walk::prefetch::prefetch;
        let r = &self.records[record];
        let start = self.reach_bytes::<UNIT>(record, octant);
        let lines = cell_reach::octant_bytes(UNIT).div_ceil(64);
        for line in &self.reaches[start / 64..][..lines] {
            prefetch(line);
        }
        prefetch(&r.bits);
        prefetch(&r.ranks);
        let first = self.first_cells[record] as usize;
        prefetch(&self.offsets[first]);
        prefetch(&self.offsets[(first + 16).min(self.offsets.len() - 1)]);
        if BOXED {
            prefetch(&self.cell_boxes[first]);
            prefetch(&self.cell_boxes[(first + 16).min(self.cell_boxes.len() - 1)]);
        }
    }

    /// What record `record` says about its cell `c` to a ray moving into `octant`:
    /// `EmptyCell` or `Blocks`.
    #[inline(always)]
    pub fn lookup_in<const UNIT: u32>(&self, record: usize, c: IVec3, octant: u32) -> Lookup {
        let l = local_index(c & IVec3::splat((1 << MACRO_SHIFT) - 1));
        let at = self.reach_bytes::<UNIT>(record, octant);
        let record = &self.records[record];
        let bits = record.bits[l >> 6];
        let bit = 1u64 << (l & 63);
        if bits & bit == 0 {
            let u = cell_reach::unit_of(l, UNIT);
            let at = at + (u >> 1);
            let byte = self.reaches[at / 64].0[at % 64];
            return Lookup::EmptyCell {
                reach: cell_reach::nibble(&[byte], u & 1),
            };
        }
        let k = (record.ranks[l >> 6] + (bits & (bit - 1)).count_ones()) as usize;
        Lookup::Blocks(self.offsets[k] as usize..self.offsets[k + 1] as usize, k)
    }

    /// The cell `l` (x + 8y + 64z within its macrocell) of macrocell `mi` (x fastest) of a
    /// grid of `macro_resolution` macrocells.
    pub fn cell_at(macro_resolution: UVec3, mi: usize, l: usize) -> IVec3 {
        (dense_coordinates(macro_resolution, mi) << MACRO_SHIFT) + local_coordinates(l)
    }

    /// The occupied cells' coordinates, in the order they are numbered.
    #[cfg(test)]
    pub fn occupied_cells(&self) -> Vec<IVec3> {
        let mut cells = Vec::with_capacity(self.occupied());
        for (m, record, _) in self.macrocells() {
            if let Some(record) = record {
                let bits = self.records[record].bits;
                for l in 0..MACRO_CELLS {
                    if bits[l >> 6] >> (l & 63) & 1 != 0 {
                        cells.push((m << MACRO_SHIFT) + local_coordinates(l));
                    }
                }
            }
        }
        cells
    }

    /// How far the walk grows each cell's box, for a grid that keeps boxes.
    #[inline(always)]
    pub fn box_margin(&self) -> Option<Vec3A> {
        self.box_margin
    }

    /// The box word of the `k`-th occupied cell, in a grid that keeps boxes.
    #[inline(always)]
    pub fn cell_box(&self, k: usize) -> u32 {
        self.cell_boxes[k]
    }

    /// The blocks of the `k`-th occupied cell.
    pub fn blocks_of(&self, k: usize) -> Range<usize> {
        self.offsets[k] as usize..self.offsets[k + 1] as usize
    }

    /// Sets the occupied cells' box words ([`crate::accel::grid::storage::cell_box`]), in the order the cells are
    /// numbered, and the margin the walk grows them by.
    pub fn set_cell_boxes(&mut self, boxes: Vec<u32>, margin: Vec3A) {
        assert_eq!(boxes.len(), self.occupied());
        self.box_margin = Some(margin);
        self.cell_boxes = boxes;
    }

    /// Occupied cells.
    pub fn occupied(&self) -> usize {
        self.offsets.len() - 1
    }

    /// Blocks over all cells.
    pub fn block_count(&self) -> usize {
        *self.offsets.last().unwrap_or(&0) as usize
    }

    /// Bytes held.
    pub fn bytes(&self) -> usize {
        std::mem::size_of_val(self.macro_words.as_slice())
            + std::mem::size_of_val(self.macro_boxes.as_slice())
            + std::mem::size_of_val(self.records.as_slice())
            + std::mem::size_of_val(self.reaches.as_slice())
            + std::mem::size_of_val(self.first_cells.as_slice())
            + std::mem::size_of_val(self.offsets.as_slice())
            + std::mem::size_of_val(self.cell_boxes.as_slice())
    }

    /// Checks the index's invariants for a grid of `resolution` cells; returns a description
    /// of the first broken one.
    pub fn validate(&self, resolution: UVec3) -> Result<(), String> {
        if self.macro_resolution != CellIndex::macro_resolution_for(resolution) {
            return Err("macrocell resolution does not match the grid".into());
        }
        if self.offsets.windows(2).any(|w| w[0] >= w[1]) {
            return Err("an occupied cell is empty or offsets decrease".into());
        }
        let counted: u32 = self
            .records
            .iter()
            .flat_map(|r| r.bits)
            .map(u64::count_ones)
            .sum();
        if counted as usize != self.occupied() {
            return Err("records and offsets disagree".into());
        }
        let boxes = if self.box_margin.is_some() {
            self.occupied()
        } else {
            0
        };
        if self.cell_boxes.len() != boxes {
            return Err(format!("{} cell boxes for {boxes}", self.cell_boxes.len()));
        }
        if self.first_cells.len() != self.records.len()
            || self
                .first_cells
                .iter()
                .zip(&self.records)
                .any(|(&f, r)| f != r.ranks[0])
        {
            return Err("a record's first cell is not its first rank".into());
        }
        let r = resolution.as_ivec3();
        let counts = BoxCounts::new(r, |c| matches!(self.lookup(c, 0), Lookup::Blocks(..)));
        for (c, record, entries) in self.macrocells() {
            if let Some(record) = record {
                if self.records[record].bits.iter().all(|&b| b == 0) {
                    return Err(format!("macrocell {c} has a record but no cell"));
                }
                continue;
            }
            for (octant, &entry) in (0..8).zip(entries) {
                let sides = reach::unpack(entry);
                let empty = |sides: IVec3| {
                    let (lo, hi) =
                        reach::box_cells(c << MACRO_SHIFT, 1 << MACRO_SHIFT, octant, sides);
                    counts.count(lo, hi) == 0
                };
                if sides.min_element() < 1 << MACRO_SHIFT || !empty(sides) {
                    return Err(format!(
                        "empty macrocell {c}'s box towards octant {octant} ({sides}) is \
                         smaller than the macrocell or not empty"
                    ));
                }
                for axis in 0..3 {
                    let mut larger = sides;
                    larger[axis] += 1;
                    if sides[axis] < reach::MAX_SIDE && empty(larger) {
                        return Err(format!(
                            "empty macrocell {c}'s box towards octant {octant} ({sides}) \
                             could grow along axis {axis}"
                        ));
                    }
                }
            }
        }
        self.validate_cell_reaches(r, &counts)
    }
}

impl CellIndex {
    /// Checks every stored unit reach against a count of occupied cells in boxes
    /// ([`BoxCounts`]): the cube it promises holds none, and (below the cap) the cube one
    /// cell larger holds one; a reach of 0, that the unit's cube of 2 holds one.
    fn validate_cell_reaches(&self, r: IVec3, counts: &BoxCounts) -> Result<(), String> {
        for z in 0..r.z {
            for y in 0..r.y {
                for x in 0..r.x {
                    let c = IVec3::new(x, y, z);
                    for octant in 0..8 {
                        let Lookup::EmptyCell { reach: k } = self.lookup(c, octant) else {
                            continue;
                        };
                        let shift = self.unit_shift;
                        let (unit, side) = (c >> shift << shift, 1 << shift);
                        // A unit of 2³ may reach 0: its own cube holds an occupied cell.
                        if k == 0 && shift != 0 {
                            let (lo, hi) = reach::cube_box(unit, side, octant, side);
                            if counts.count(lo, hi) == 0 {
                                return Err(format!(
                                    "cell {c}'s unit reaches 0 towards octant {octant}, but \
                                     its cube of {side} is empty"
                                ));
                            }
                            continue;
                        }
                        check_reach(counts, unit, side, octant, k, cell_reach::MAX_REACH)
                            .map_err(|e| format!("the unit at cell {e}"))?;
                    }
                }
            }
        }
        Ok(())
    }
}

/// Checks a reach `k` towards `octant` of the unit of `unit` cells a side at cell `c`
/// ([`cell_reach`]): the cube it promises holds no occupied cell of `counts`, and — below
/// `cap` — the cube one larger does.
fn check_reach(
    counts: &BoxCounts,
    c: IVec3,
    unit: i32,
    octant: u32,
    k: u32,
    cap: u32,
) -> Result<(), String> {
    let (lo, hi) = reach::cube_box(c, unit, octant, k as i32);
    if k < 1 || counts.count(lo, hi) != 0 {
        return Err(format!(
            "{c} reaches {k} towards octant {octant}, past an occupied one"
        ));
    }
    let (lo, hi) = reach::cube_box(c, unit, octant, k as i32 + 1);
    if k < cap && counts.count(lo, hi) == 0 {
        return Err(format!("{c} reaches only {k} towards octant {octant}"));
    }
    Ok(())
}

/// The low three bytes of `v` as the lanes of a vector (a box's sides, [`reach::pack`]):
/// two unpacks and a conversion, SSE2.
#[inline(always)]
fn byte_lanes(v: u32) -> Vec3A {
    #[cfg(target_arch = "x86_64")]
    {
        use std::arch::x86_64::{
            _mm_cvtepi32_ps, _mm_cvtsi32_si128, _mm_setzero_si128, _mm_unpacklo_epi8,
            _mm_unpacklo_epi16,
        };
        // SAFETY: SSE2, which these intrinsics need, is part of x86_64.
        unsafe {
            let zero = _mm_setzero_si128();
            let bytes = _mm_cvtsi32_si128(v as i32);
            let lanes = _mm_unpacklo_epi16(_mm_unpacklo_epi8(bytes, zero), zero);
            Vec3A::from(_mm_cvtepi32_ps(lanes))
        }
    }
    #[cfg(not(target_arch = "x86_64"))]
    reach::unpack(v).as_vec3a()
}

/// The coordinates of the macrocell numbered `mi` in a grid of `r` macrocells, x fastest.
fn dense_coordinates(r: UVec3, mi: usize) -> IVec3 {
    let mi = mi as u32;
    UVec3::new(mi % r.x, mi / r.x % r.y, mi / (r.x * r.y)).as_ivec3()
}

/// A cell's coordinates within its macrocell, from its index there ([`local_index`]).
fn local_coordinates(l: usize) -> IVec3 {
    let l = l as i32;
    IVec3::new(l & 7, l >> 3 & 7, l >> 6)
}

/// Index of a cell within its macrocell, from its coordinates there.
#[inline(always)]
fn local_index(l: IVec3) -> usize {
    (l.x + (l.y << MACRO_SHIFT) + (l.z << (2 * MACRO_SHIFT))) as usize
}

/// A cache line of reaches ([`CellIndex::reaches`]), aligned so that one octant's reaches
/// never straddle more lines than they fill.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[repr(C, align(64))]
struct ReachLine([u8; 64]);
