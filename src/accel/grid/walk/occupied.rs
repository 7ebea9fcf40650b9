//! The occupied cells along a ray, front to back: the walk of [`crate::accel::grid::walk`]'s
//! queries through the two-level cell index ([`crate::accel::grid::storage::cells`]), one occupied cell ahead of
//! the cell whose triangles are being tested.

use std::ops::Range;

use glam::{UVec3, Vec3A};

use super::stats::TraversalStats;
use crate::accel::Ray;
use crate::accel::grid::Grid;
use crate::accel::grid::frame::CellWalk;
use crate::accel::grid::storage::block::Block;
use crate::accel::grid::storage::cell_box::{self, MASKED_BLOCKS};
use crate::accel::grid::storage::cells::Lookup;
use crate::accel::grid::storage::macrocell::MACRO_SHIFT;
use crate::accel::grid::storage::reach;
use crate::accel::grid::walk::prefetch::prefetch;

impl Grid {
    /// The occupied cells along `ray`, front to back.
    #[inline(always)]
    pub(in crate::accel::grid) fn occupied_cells<
        'a,
        const READ_BLOCKS: bool,
        const FUSED: bool,
        const UNIT: u32,
        const BOXED: bool,
    >(
        &'a self,
        ray: &Ray,
    ) -> OccupiedCells<'a, READ_BLOCKS, FUSED, UNIT, BOXED> {
        let single_cell = self.frame.resolution == UVec3::ONE;
        let walk = if self.blocks.is_empty() || single_cell {
            None
        } else {
            self.frame.start_walk::<FUSED>(ray)
        };
        OccupiedCells {
            grid: self,
            octant: walk.map_or(0, |w| reach::octant(w.step())),
            walk,
            single_cell: single_cell && !self.blocks.is_empty(),
            ahead: None,
            last_record: usize::MAX,
            pause_ahead: walk.is_some_and(|w| w.from_outside),
            box_margin: self.cells.box_margin().unwrap_or(Vec3A::ZERO),
            masked: !self.block_boxes.is_empty(),
        }
    }

    /// The blocks of an occupied cell that its walk gives out ([`Found`]): for a grid that
    /// keeps boxes, those of `range` that `mask` holds, then any after the first 64.
    #[inline(always)]
    pub(in crate::accel::grid) fn cell_blocks<const BOXED: bool>(
        &self,
        range: &Range<usize>,
        mask: u64,
    ) -> CellBlocks<'_, BOXED> {
        CellBlocks {
            blocks: &self.blocks[range.clone()],
            mask,
            next: MASKED_BLOCKS,
        }
    }
}

/// The mask of every one of `count` blocks ([`Found`]).
#[inline(always)]
fn every_block(count: usize) -> u64 {
    u64::MAX >> (MASKED_BLOCKS - count.clamp(1, MASKED_BLOCKS))
}

/// The blocks of a cell to test ([`Grid::cell_blocks`]).
pub(in crate::accel::grid) struct CellBlocks<'a, const BOXED: bool> {
    blocks: &'a [Block],
    /// The blocks among the first 64 not yet given out.
    mask: u64,
    /// The next block after the first 64.
    next: usize,
}

impl<'a, const BOXED: bool> Iterator for CellBlocks<'a, BOXED> {
    type Item = &'a Block;

    #[inline(always)]
    fn next(&mut self) -> Option<&'a Block> {
        if !BOXED {
            let (first, rest) = self.blocks.split_first()?;
            self.blocks = rest;
            return Some(first);
        }
        if self.mask != 0 {
            let i = self.mask.trailing_zeros() as usize;
            self.mask &= self.mask - 1;
            return self.blocks.get(i);
        }
        let block = self.blocks.get(self.next)?;
        self.next += 1;
        Some(block)
    }
}

/// The occupied cells along a ray, front to back (a cursor rather than an iterator, so the
/// caller's statistics can ride along). Unless `READ_BLOCKS`, the cells' blocks are not
/// asked for ahead of time ([`Grid::walk`]). `FUSED` as in [`CellWalk`]; `UNIT` the grid's
/// [`crate::accel::grid::storage::cells::CellIndex::unit_shift`]; `BOXED` when the grid keeps a box per occupied
/// cell ([`cell_box`]).
pub(in crate::accel::grid) struct OccupiedCells<
    'a,
    const READ_BLOCKS: bool,
    const FUSED: bool,
    const UNIT: u32,
    const BOXED: bool,
> {
    grid: &'a Grid,
    /// `None` once the ray has left the grid.
    walk: Option<CellWalk<FUSED>>,
    /// The octant of the ray's direction ([`reach::octant`]).
    octant: u32,
    /// True until the one cell of a single-cell grid has been given out: such a grid is not
    /// walked (a few triangles are tested faster all at once than found by a walk).
    single_cell: bool,
    /// The walk ahead of the cell given out last; `None` before the first is given out.
    ahead: Option<Ahead>,
    /// The record of the macrocell of the cell given out last.
    last_record: usize,
    /// True when the walk ahead of a cell stops at the next occupied macrocell: for a ray
    /// that starts outside the grid's box ([`OccupiedCells::next`]).
    pause_ahead: bool,
    /// How far each cell's box is grown, if `BOXED` ([`cell_box::margin_for`]).
    box_margin: Vec3A,
    /// True when the grid keeps a box per block as well ([`cell_box::block_mask`]).
    masked: bool,
}

/// How far the walk ahead of the cell being tested went.
enum Ahead {
    /// To the next occupied cell (`None`: the ray leaves the grid without one).
    Found(Option<Found>),
    /// To an occupied macrocell other than the tested cell's, whose record it has asked
    /// for; the walk goes on from there when the cell being tested holds no hit.
    Paused,
}

impl Ahead {
    /// The cell found, for a walk that may not pause (which finds one or leaves the grid).
    fn into_found(self) -> Option<Found> {
        match self {
            Ahead::Found(found) => found,
            Ahead::Paused => unreachable!("a walk that may not pause paused"),
        }
    }
}

/// An occupied cell: where its blocks lie in `blocks`, which of them the ray may meet (for
/// a grid that keeps boxes, [`cell_box::block_mask`]; bit `i` for the `i`-th block of the
/// first 64, every block after them), and the largest hit parameter that belongs to it (the
/// last cell takes all up to the grid's end).
pub(in crate::accel::grid) type Found = (Range<usize>, u64, f32);

impl<const READ_BLOCKS: bool, const FUSED: bool, const UNIT: u32, const BOXED: bool>
    OccupiedCells<'_, READ_BLOCKS, FUSED, UNIT, BOXED>
{
    /// The next occupied cell along the ray.
    ///
    /// The walk runs one occupied cell ahead of the cell given out. Reading a cell's
    /// blocks from memory (about 170 ns on a mesh the size of the full dragon) is the
    /// largest single cost of a query, and the walk asks for all of a cell's blocks as soon
    /// as it finds the cell ([`OccupiedCells::find_next`]), so those reads overlap the
    /// tests of the cell before. Two cells ahead gained 1.00–1.03× on the full dragon's
    /// bounce rays but lost 0.89× on its outside rays: cells found beyond the hit are
    /// wasted work.
    ///
    /// For the same reason, a ray that starts outside the grid's box — which meets the
    /// outside of the surface first, and most often hits it in the first occupied cells it
    /// finds — stops its walk ahead at the next occupied macrocell other than the tested
    /// cell's, having asked for that macrocell's record: the walk does not wait for a
    /// record from memory that the tested cell's hit may make useless, and goes on from
    /// there, the record on its way, if the cell holds none. A ray that starts inside
    /// (bounce and shadow rays, leaving the surface they start on) walks on as before:
    /// stopping cost its bounce rays 0.93× the speed.
    #[inline(always)]
    pub(in crate::accel::grid) fn next(
        &mut self,
        stats: &mut impl TraversalStats,
    ) -> Option<Found> {
        let grid = self.grid;
        if self.single_cell {
            self.single_cell = false;
            stats.visit_occupied();
            // Every hit belongs to the one cell.
            let all = grid.blocks.len();
            return Some((0..all, every_block(all), f32::INFINITY));
        }
        let current = match self.ahead.take() {
            Some(Ahead::Found(found)) => found,
            // Before the first cell, or on from where the walk ahead stopped.
            Some(Ahead::Paused) | None => self.find_next(stats, false).into_found(),
        }?;
        self.ahead = Some(self.find_next(stats, self.pause_ahead));
        stats.visit_occupied();
        Some(current)
    }

    /// The walk on to the next occupied cell: its blocks and hit limit; if `pause`, it stops
    /// instead at an occupied macrocell other than that of the cell given out last.
    #[inline(always)]
    fn find_next(&mut self, stats: &mut impl TraversalStats, pause: bool) -> Ahead {
        let grid = self.grid;
        let Some(walk) = self.walk.as_mut() else {
            return Ahead::Found(None);
        };
        loop {
            let word = grid.cells.macrocell_of(walk.cell(), self.octant);
            if let (true, Ok(record)) = (pause, word)
                && record != self.last_record
            {
                grid.cells
                    .prefetch_record::<UNIT, BOXED>(record, self.octant);
                stats.pause_ahead();
                return Ahead::Paused;
            }
            stats.visit_cell();
            let record = match word {
                Ok(record) => {
                    stats.enter_macrocell();
                    grid.cells
                        .prefetch_record::<UNIT, BOXED>(record, self.octant);
                    record
                }
                Err(sides) => {
                    stats.leap_macrocells();
                    // Past the empty box of cells ahead in this macrocell's corner
                    // ([`reach`]).
                    if !walk.leave_box(sides, MACRO_SHIFT as u32) {
                        self.walk = None;
                        return Ahead::Found(None);
                    }
                    continue;
                }
            };
            // Within one occupied macrocell, its record serves every step until the walk
            // leaves it: no macrocell lookup per cell.
            let macrocell = walk.cell() >> MACRO_SHIFT;
            loop {
                match grid
                    .cells
                    .lookup_in::<UNIT>(record, walk.cell(), self.octant)
                {
                    // A cell whose reach is 1 is left by an ordinary step, cheaper than
                    // leaving a cube of one cell; so is one whose 2³ unit has no empty
                    // cube ahead (reach 0).
                    Lookup::EmptyCell { reach } if reach >= 2 => {
                        stats.leap_cells();
                        // Past the empty cube of `reach` cells ahead
                        // ([`crate::accel::grid::storage::cell_reach`]).
                        if !walk.leave_cube(reach as f32, UNIT) {
                            self.walk = None;
                            return Ahead::Found(None);
                        }
                    }
                    Lookup::Blocks(range, k) => {
                        // A cell whose triangles' box the ray passes is given out with no
                        // blocks ([`cell_box`]; without a branch on it, whose outcome is
                        // as good as random); of a cell of several blocks, only those
                        // whose boxes the ray meets.
                        let (range, mask) = if BOXED {
                            let word = grid.cells.cell_box(k);
                            let meets = cell_box::meets(walk, word, self.box_margin);
                            let keep = usize::from(meets).wrapping_neg();
                            let range = range.start..range.start + (range.len() & keep);
                            let mask = if range.len() > 1 && self.masked {
                                let words = &grid.block_boxes;
                                cell_box::block_mask(walk, words, range.clone(), self.box_margin)
                            } else {
                                every_block(range.len())
                            };
                            (range, mask)
                        } else {
                            (range, u64::MAX)
                        };
                        // All its blocks to be tested: ask for them now, while the walk
                        // goes on to the next occupied cell.
                        if READ_BLOCKS {
                            for block in grid.cell_blocks::<BOXED>(&range, mask) {
                                prefetch(block);
                            }
                        }
                        let (limit, more) = walk.advance();
                        if !more {
                            self.walk = None;
                        }
                        self.last_record = record;
                        return Ahead::Found(Some((range, mask, limit)));
                    }
                    // (`lookup_in` never answers `EmptyMacrocell`.)
                    Lookup::EmptyCell { .. } | Lookup::EmptyMacrocell => {
                        stats.step_cell();
                        if !walk.advance().1 {
                            self.walk = None;
                            return Ahead::Found(None);
                        }
                    }
                }
                if walk.cell() >> MACRO_SHIFT != macrocell {
                    break;
                }
                stats.visit_cell();
            }
        }
    }
}
