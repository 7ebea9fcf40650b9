//! Writing the blocks, cell by cell: each occupied cell's triangles are made from the mesh
//! once, put in Morton order when the grid orders its crowded cells ([`block_order`]), and
//! written eight at a time straight into the cell's place in the block array, with each
//! block's box word when the grid keeps boxes ([`cell_box`]). Groups of cells are written
//! in parallel, each into its own part of the array.
//!
//! Ordering the cells in a pass of their own made every triangle of a crowded cell twice
//! (once for its key, once for its block); on the full dragon, whose references lie 94 % in
//! crowded cells, that pass took a sixth of the build (the triangles' corners are scattered
//! reads of the mesh).
//!
//! [`cell_box`]: crate::accel::grid::storage::cell_box

use std::mem::MaybeUninit;

use glam::IVec3;
use rayon::prelude::*;

use super::block_order;
use super::mesh_triangles::MeshTriangles;
use crate::accel::Triangle;
use crate::accel::grid::frame::GridFrame;
use crate::accel::grid::storage::block::{Block, LANES};
use crate::accel::grid::storage::cell_box;
use crate::accel::huge_pages;
use crate::accel::isa::{Kernel, X86Level, dispatch};

/// An occupied cell: the start and length of its run of the cell-sorted triangle numbers,
/// and its coordinates.
#[derive(Clone, Copy, Debug)]
pub(in crate::accel::grid) struct CellRun {
    pub start: u32,
    pub count: u32,
    pub cell: IVec3,
}

impl CellRun {
    /// Blocks the cell's triangles fill.
    pub fn blocks(&self) -> usize {
        self.count.div_ceil(LANES as u32) as usize
    }
}

/// Cells written by one task.
const GROUP: usize = 64;

/// What the blocks are written with.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(in crate::accel::grid) enum BlockBoxes {
    /// Triangles in mesh order, no box words.
    None,
    /// Triangles in mesh order and each block's box word.
    Words,
    /// The triangles of cells of more than one block in Morton order, and each block's box
    /// word.
    OrderedWords,
}

impl BlockBoxes {
    /// Box words written for `blocks` blocks: one per block, or none.
    fn words_for(self, blocks: usize) -> usize {
        if self == BlockBoxes::None { 0 } else { blocks }
    }
}

/// The blocks of the cells `runs` (in the order the index numbers them) from the triangles
/// `sorted` lists cell by cell, and the blocks' box words (empty for [`BlockBoxes::None`]).
pub(in crate::accel::grid) fn write(
    frame: &GridFrame,
    runs: &[CellRun],
    sorted: &[u32],
    triangles: MeshTriangles,
    boxes: BlockBoxes,
) -> (Vec<Block>, Vec<u32>) {
    let count: usize = runs.iter().map(CellRun::blocks).sum();
    let words_count = boxes.words_for(count);
    let mut blocks: Vec<Block> = huge_pages::vec_with_capacity(count);
    let mut words: Vec<u32> = Vec::with_capacity(words_count);
    // Each group of cells' own slots of both arrays, in order: together, the first `count`
    // (and `words_count`) slots, each in exactly one group's part. Groups of cells, not
    // single cells, so that the list of parts stays small.
    let mut jobs = Vec::with_capacity(runs.len().div_ceil(GROUP));
    let mut block_slots = &mut blocks.spare_capacity_mut()[..count];
    let mut word_slots = &mut words.spare_capacity_mut()[..words_count];
    for group in runs.chunks(GROUP) {
        let n: usize = group.iter().map(CellRun::blocks).sum();
        let (own, rest) = std::mem::take(&mut block_slots).split_at_mut(n);
        block_slots = rest;
        let (own_words, rest) = std::mem::take(&mut word_slots).split_at_mut(boxes.words_for(n));
        word_slots = rest;
        jobs.push((group, own, own_words));
    }
    jobs.into_par_iter().for_each_init(
        Scratch::default,
        |scratch, (group, mut own, mut own_words)| {
            for &run in group {
                let n = run.blocks();
                let (blocks, rest) = std::mem::take(&mut own).split_at_mut(n);
                own = rest;
                let (words, rest) = std::mem::take(&mut own_words).split_at_mut(boxes.words_for(n));
                own_words = rest;
                let cell = FillCell {
                    frame,
                    run,
                    sorted,
                    triangles,
                    boxes,
                    scratch,
                    blocks,
                    words,
                };
                dispatch(X86Level::Avx2, cell)
            }
        },
    );
    // SAFETY: the groups' parts, and within them the cells' parts, cover the first `count`
    // slots of `blocks` and the first `words_count` of `words` (with box words, a cell's
    // part of `words` is as long as its part of `blocks`), and `FillCell` writes every slot
    // of its cell's parts. (Written in place: collecting each cell's blocks and then copying
    // them into the array would write the array, 90 MB for the full dragon, twice.)
    unsafe {
        blocks.set_len(count);
        words.set_len(words_count);
    }
    (blocks, words)
}

/// The blocks and box words of one cell whose triangles, in lane order, are `ids`, written
/// by the version compiled for this processor or, if `portable`, by the portable one (for
/// tests: the two must agree).
#[cfg(test)]
pub(in crate::accel::grid) fn write_cell(
    frame: &GridFrame,
    run: CellRun,
    ids: &[u32],
    triangles: MeshTriangles,
    portable: bool,
) -> (Vec<Block>, Vec<u32>) {
    let n = run.blocks();
    let mut blocks = vec![MaybeUninit::uninit(); n];
    let mut words = vec![MaybeUninit::uninit(); n];
    let cell = FillCell {
        frame,
        run,
        sorted: ids,
        triangles,
        boxes: BlockBoxes::Words,
        scratch: &mut Scratch::default(),
        blocks: &mut blocks,
        words: &mut words,
    };
    if portable {
        cell.run::<false>();
    } else {
        dispatch(X86Level::Avx2, cell);
    }
    // SAFETY: `FillCell` writes every one of the run's blocks and, with box words, words.
    unsafe {
        (
            blocks.iter().map(|b| b.assume_init_read()).collect(),
            words.iter().map(|w| w.assume_init_read()).collect(),
        )
    }
}

/// A worker's buffers for a cell's triangles and their keys, kept from cell to cell.
#[derive(Default)]
struct Scratch {
    triangles: Vec<Triangle>,
    keyed: Vec<u64>,
}

/// One cell's blocks, as a [`Kernel`]: compiled for AVX2 like the overlap tests (the
/// arithmetic, and so the grid, is the same).
struct FillCell<'a> {
    frame: &'a GridFrame,
    run: CellRun,
    sorted: &'a [u32],
    triangles: MeshTriangles<'a>,
    boxes: BlockBoxes,
    scratch: &'a mut Scratch,
    blocks: &'a mut [MaybeUninit<Block>],
    words: &'a mut [MaybeUninit<u32>],
}

impl Kernel for FillCell<'_> {
    type Output = ();
    #[inline(always)]
    fn run<const FUSED: bool>(self) {
        let CellRun { start, count, cell } = self.run;
        let ids = &self.sorted[start as usize..(start + count) as usize];
        let Scratch { triangles, keyed } = self.scratch;
        triangles.clear();
        triangles.extend(ids.iter().map(|&t| self.triangles.get(t)));
        // Lane order: the triangles' places in the run, by Morton key in a crowded cell of
        // an ordering grid (ties by place, which is mesh order).
        keyed.clear();
        if self.boxes == BlockBoxes::OrderedWords && count as usize > LANES {
            keyed.extend(triangles.iter().enumerate().map(|(i, t)| {
                u64::from(block_order::key(self.frame, cell, t.bounds())) << 32 | i as u64
            }));
            keyed.sort_unstable();
        } else {
            keyed.extend(0..u64::from(count));
        }
        for (b, lanes) in keyed.chunks(LANES).enumerate() {
            let mut block = Block::EMPTY;
            for (lane, &k) in lanes.iter().enumerate() {
                let i = k as u32 as usize;
                block.set(lane, &triangles[i], ids[i]);
            }
            if let Some(word) = self.words.get_mut(b) {
                word.write(cell_box::block_word(self.frame, cell, &block));
            }
            self.blocks[b].write(block);
        }
    }
}
