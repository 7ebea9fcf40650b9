//! Traversal macrocell by macrocell: a 3D-DDA (Amanatides & Woo 1987) over the 8³
//! macrocells, leaping over the empty cube around an empty macrocell in one step
//! (proximity clouds, Cohen & Sheffer 1994), and inside an occupied macrocell no walk at
//! all: the cells the ray can touch there are found as a mask in the layout of the
//! macrocell's occupancy record ([`super::segment_mask`]), the occupied ones among them
//! are the candidates, and their blocks are tested in the order the ray enters them.
//!
//! A hit is accepted anywhere along the ray; the walk stops once the nearest hit so far
//! lies at or before the entry of the next candidate cell, or the exit of the macrocell:
//! every later cell lies beyond that point, so nothing nearer can follow.

use std::ops::Range;

use glam::{IVec3, UVec3};

use super::block::LaneHit;
use super::cells::MACRO_SHIFT;
use super::segment_mask::CellRay;
use super::traverse::TraversalStats;
use super::{Grid, GridHit};
use crate::accel::Ray;
use crate::accel::frame::CellWalk;

/// Candidate cells of one macrocell kept in ray order; a ray that meets more (a thick
/// rounding margin, far from the grid) has all of that macrocell's candidates tested.
const ORDERED: usize = 32;
const PREFETCH: bool = true;
/// Candidates are scanned in groups of this many (one vector).
const GROUP: usize = 8;

/// The occupied cells of one macrocell that the ray may meet: where it enters each (the
/// cell grown by the rounding margin) and the cell's index within the macrocell.
struct Candidates {
    t: [f32; ORDERED],
    /// Each one's index within the macrocell.
    local: [u16; ORDERED],
    /// Each one's blocks.
    first: [u32; ORDERED],
    end: [u32; ORDERED],
    /// Each one's coordinates within the macrocell, axis by axis (scratch of `collect`).
    at: [[f32; ORDERED]; 3],
    len: usize,
}

impl Candidates {
    fn new() -> Candidates {
        Candidates {
            t: [0.0; ORDERED],
            local: [0; ORDERED],
            first: [0; ORDERED],
            end: [0; ORDERED],
            at: [[0.0; ORDERED]; 3],
            len: 0,
        }
    }
}

impl Grid {
    /// The closest hit along `ray`.
    #[inline(always)]
    pub(super) fn nearest_by_macrocells(
        &self,
        ray: &Ray,
        stats: &mut impl TraversalStats,
    ) -> Option<GridHit> {
        let mut nearest: Option<LaneHit> = None;
        let mut t_nearest = ray.t_max;
        if self.blocks.is_empty() {
            return None;
        }
        if self.frame.resolution == UVec3::ONE {
            // One cell: its few triangles are tested at once, not found by a walk.
            stats.visit_occupied();
            self.nearest_in(
                0..self.blocks.len(),
                ray,
                &mut t_nearest,
                &mut nearest,
                stats,
            );
            return nearest.map(Into::into);
        }
        let mut walk = self.macro_frame.start_walk(ray)?;
        let cell_ray = CellRay::new(
            ray,
            self.frame.bounds.min,
            self.frame.inv_cell_size,
            walk.t_end,
        );
        let mut candidates = Candidates::new();
        loop {
            stats.visit_cell();
            match self.cells.record_at(walk.cell) {
                Err(distance) => {
                    if !self.leave_empty_macrocells(&mut walk, ray, distance) {
                        break;
                    }
                    continue;
                }
                Ok(record) => {
                    stats.skip_macrocell();
                    let t_end = t_nearest.min(walk.t_end);
                    if self.collect(
                        record,
                        walk.cell,
                        &cell_ray,
                        ray.t_min,
                        t_end,
                        &mut candidates,
                    ) {
                        // Nearest entry first; done once the nearest hit lies before the
                        // next entry.
                        if PREFETCH {
                            for &first in &candidates.first[..candidates.len] {
                                self.blocks[first as usize].prefetch();
                            }
                        }
                        let mut next = self.take_nearest(&mut candidates, t_nearest);
                        while let Some((_, blocks)) = next {
                            next = self.take_nearest(&mut candidates, t_nearest);
                            stats.visit_occupied();
                            self.nearest_in(blocks, ray, &mut t_nearest, &mut nearest, stats);
                            if next.as_ref().is_some_and(|(t, _)| t_nearest <= *t) {
                                return nearest.map(Into::into);
                            }
                        }
                    } else {
                        // Too many to order: all of them, in any order.
                        self.for_each_candidate(
                            record,
                            walk.cell,
                            &cell_ray,
                            ray.t_min,
                            t_end,
                            |_, blocks| {
                                stats.visit_occupied();
                                self.nearest_in(blocks, ray, &mut t_nearest, &mut nearest, stats);
                                false
                            },
                        );
                    }
                }
            }
            let (t_exit, more) = walk.advance();
            if !more || t_nearest <= t_exit {
                break;
            }
        }
        nearest.map(Into::into)
    }

    /// True when anything blocks `ray`.
    #[inline(always)]
    pub(super) fn any_by_macrocells(&self, ray: &Ray, stats: &mut impl TraversalStats) -> bool {
        if self.blocks.is_empty() {
            return false;
        }
        if self.frame.resolution == UVec3::ONE {
            stats.visit_occupied();
            return self.any_in(0..self.blocks.len(), ray, stats);
        }
        let Some(mut walk) = self.macro_frame.start_walk(ray) else {
            return false;
        };
        let cell_ray = CellRay::new(
            ray,
            self.frame.bounds.min,
            self.frame.inv_cell_size,
            walk.t_end,
        );
        let mut candidates = Candidates::new();
        loop {
            stats.visit_cell();
            match self.cells.record_at(walk.cell) {
                Err(distance) => {
                    if !self.leave_empty_macrocells(&mut walk, ray, distance) {
                        return false;
                    }
                    continue;
                }
                Ok(record) => {
                    let (m, t_end) = (walk.cell, walk.t_end);
                    let blocked =
                        if self.collect(record, m, &cell_ray, ray.t_min, t_end, &mut candidates) {
                            // Nearest first: an occluder near the start ends the search soonest.
                            let mut blocked = false;
                            let mut next = self.take_nearest(&mut candidates, f32::INFINITY);
                            while let Some((_, blocks)) = next {
                                next = self.take_nearest(&mut candidates, f32::INFINITY);
                                if let Some((_, ahead)) = &next {
                                    if PREFETCH {
                                        self.blocks[ahead.start].prefetch();
                                    }
                                }
                                stats.visit_occupied();
                                if self.any_in(blocks, ray, stats) {
                                    blocked = true;
                                    break;
                                }
                            }
                            blocked
                        } else {
                            self.for_each_candidate(
                                record,
                                m,
                                &cell_ray,
                                ray.t_min,
                                t_end,
                                |_, blocks| {
                                    stats.visit_occupied();
                                    self.any_in(blocks, ray, stats)
                                },
                            )
                        };
                    if blocked {
                        return true;
                    }
                }
            }
            if !walk.advance().1 {
                return false;
            }
        }
    }

    /// Takes the candidate the ray enters first, if it enters it before `limit`: its entry
    /// and blocks.
    #[inline(always)]
    fn take_nearest(&self, candidates: &mut Candidates, limit: f32) -> Option<(f32, Range<usize>)> {
        // A branch-free scan of whole groups of eight (unused places hold ∞): no sort and
        // no loop of data-dependent length, whose branches mispredict.
        let mut best = limit;
        let mut at = ORDERED;
        for group in 0..candidates.len.div_ceil(GROUP) {
            let ts = &candidates.t[group * GROUP..(group + 1) * GROUP];
            for (i, &t) in ts.iter().enumerate() {
                let nearer = t < best;
                best = if nearer { t } else { best };
                at = if nearer { group * GROUP + i } else { at };
            }
        }
        if at == ORDERED {
            return None;
        }
        candidates.t[at] = f32::INFINITY;
        Some((
            best,
            candidates.first[at] as usize..candidates.end[at] as usize,
        ))
    }

    /// Tests `blocks`, keeping the nearest hit before `t_nearest`.
    #[inline(always)]
    fn nearest_in(
        &self,
        blocks: Range<usize>,
        ray: &Ray,
        t_nearest: &mut f32,
        nearest: &mut Option<LaneHit>,
        stats: &mut impl TraversalStats,
    ) {
        for block in &self.blocks[blocks] {
            stats.test_triangles(block.len());
            if let Some(hit) = block.nearest(ray, *t_nearest) {
                *t_nearest = hit.t;
                *nearest = Some(hit);
            }
        }
    }

    /// Tests `blocks` for any hit.
    #[inline(always)]
    fn any_in(&self, blocks: Range<usize>, ray: &Ray, stats: &mut impl TraversalStats) -> bool {
        for block in &self.blocks[blocks] {
            stats.test_triangles(block.len());
            if block.any(ray, ray.t_max) {
                return true;
            }
        }
        false
    }

    /// Gathers the candidates of macrocell `m` (record `record`) into `into`; false when
    /// there are more than it holds.
    #[inline(always)]
    fn collect(
        &self,
        record: usize,
        m: IVec3,
        cell_ray: &CellRay,
        t_start: f32,
        t_end: f32,
        into: &mut Candidates,
    ) -> bool {
        let base = m << MACRO_SHIFT;
        let mask = cell_ray.macrocell_mask(base, t_start, t_end);
        let bits = self.cells.bits(record);
        let mut words = [0u64; 8];
        let mut total = 0;
        for z in 0..8 {
            words[z] = mask[z] & bits[z];
            total += words[z].count_ones() as usize;
        }
        if total > ORDERED {
            return false;
        }
        // The cells in storage order, one pass each with no branch on what is found (a
        // cell's word is the first non-zero one left), their coordinates into lanes.
        let mut nonzero = 0u32;
        for (z, word) in words.iter().enumerate() {
            nonzero |= u32::from(*word != 0) << z;
        }
        let (at, local) = (&mut into.at, &mut into.local);
        for i in 0..total {
            let z = nonzero.trailing_zeros() as usize;
            let word = words[z];
            let bit = word.trailing_zeros() as usize;
            words[z] = word & (word - 1);
            nonzero &= !(u32::from(words[z] == 0) << z);
            at[0][i] = (bit & 7) as f32;
            at[1][i] = (bit >> 3) as f32;
            at[2][i] = z as f32;
            local[i] = (64 * z + bit) as u16;
        }
        // Where the ray enters each, eight at a time (∞ for a cell it misses).
        let groups = total.div_ceil(GROUP);
        for g in 0..groups {
            let lanes = g * GROUP..(g + 1) * GROUP;
            cell_ray.cell_entries(
                base,
                [
                    &at[0][lanes.clone()],
                    &at[1][lanes.clone()],
                    &at[2][lanes.clone()],
                ],
                t_start,
                t_end,
                &mut into.t[lanes],
            );
        }
        into.len = total;
        for i in 0..total {
            let blocks = self.cells.blocks_at(record, usize::from(into.local[i]));
            into.first[i] = blocks.start as u32;
            into.end[i] = blocks.end as u32;
        }
        // Whole groups for the scan in `take_nearest`: unused places were never met.
        into.t[total..groups * GROUP].fill(f32::INFINITY);
        true
    }

    /// Calls `f` with the entry parameter and blocks of every occupied cell of macrocell
    /// `m` (record `record`) that the ray meets within `[t_start, t_end]`, in storage
    /// order, until `f` answers true; true when it did.
    #[inline(always)]
    fn for_each_candidate(
        &self,
        record: usize,
        m: IVec3,
        cell_ray: &CellRay,
        t_start: f32,
        t_end: f32,
        mut f: impl FnMut(f32, Range<usize>) -> bool,
    ) -> bool {
        self.for_each_cell(m, cell_ray, t_start, t_end, record, |t, cell| {
            f(t, self.cells.blocks_at(record, cell))
        })
    }

    /// [`Grid::for_each_candidate`], giving each cell's index within the macrocell instead
    /// of its blocks.
    #[inline(always)]
    fn for_each_cell(
        &self,
        m: IVec3,
        cell_ray: &CellRay,
        t_start: f32,
        t_end: f32,
        record: usize,
        mut f: impl FnMut(f32, usize) -> bool,
    ) -> bool {
        let base = m << MACRO_SHIFT;
        let mask = cell_ray.macrocell_mask(base, t_start, t_end);
        let bits = self.cells.bits(record);
        for z in 0..mask.len() {
            let mut word = mask[z] & bits[z];
            while word != 0 {
                let bit = word.trailing_zeros() as usize;
                word &= word - 1;
                let c = base + IVec3::new((bit & 7) as i32, (bit >> 3) as i32, z as i32);
                if let Some((t, _)) = cell_ray.cell_span(c, t_start, t_end) {
                    if f(t, 64 * z + bit) {
                        return true;
                    }
                }
            }
        }
        false
    }

    /// Moves the macrocell walk past the empty cube of macrocells around its current one
    /// (of Chebyshev radius `distance − 1`). False when the ray leaves the grid first.
    #[inline(always)]
    fn leave_empty_macrocells(&self, walk: &mut CellWalk, ray: &Ray, distance: u32) -> bool {
        let res = self.macro_frame.resolution.as_ivec3();
        let reach = distance.max(1) as i32 - 1;
        let lo = (walk.cell - reach).max(IVec3::ZERO);
        let hi = (walk.cell + reach).min(res - 1);
        self.macro_frame.leave_box(walk, ray, lo, hi)
    }
}
