//! The cells of an irregular grid as the walk reads them: one word per voxel naming its
//! cell, and per cell the box it answers for (in voxels) and where its blocks lie.
//!
//! Cells are boxes of voxels made by merging ([`super::merge`]); a cell's box is grown over
//! neighbours whose triangles it holds too, so a ray leaves it at the grown box's face. A
//! step of the walk is thus one word, one cell record and the cell's blocks, whatever the
//! size of the cell (Pérard-Gayot, Kalojanov & Slusallek 2017).

use std::ops::Range;

use glam::{IVec3, UVec3};

use super::merge::Merged;

/// One cell: the voxels it answers for (inclusive corners) and its blocks.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[repr(C)]
pub(super) struct Cell {
    pub lo: [u16; 3],
    pub hi: [u16; 3],
    /// `first..end` indexes the blocks.
    pub first: u32,
    pub end: u32,
}

impl Cell {
    /// Where the cell's blocks lie.
    #[inline(always)]
    pub fn blocks(&self) -> Range<usize> {
        self.first as usize..self.end as usize
    }
}

/// The cells of a grid and the voxel-to-cell map.
#[derive(Clone, Debug, Default)]
pub(super) struct CellIndex {
    resolution: UVec3,
    /// Voxel (x fastest, then y, then z) → cell.
    map: Vec<u32>,
    cells: Vec<Cell>,
}

impl CellIndex {
    /// The index of merged cells whose blocks are `blocks[k]` in number, laid out in cell
    /// order.
    pub fn new(resolution: UVec3, merged: &Merged, blocks: &[u32]) -> CellIndex {
        let mut first = 0;
        let cells = merged
            .cells
            .iter()
            .zip(blocks)
            .map(|(c, &n)| {
                let cell = Cell {
                    lo: c.reach_lo,
                    hi: c.reach_hi,
                    first,
                    end: first + n,
                };
                first += n;
                cell
            })
            .collect();
        CellIndex {
            resolution,
            map: merged.map.clone(),
            cells,
        }
    }

    /// The cell that voxel `v` (inside the grid) belongs to.
    #[inline(always)]
    pub fn cell_at(&self, v: IVec3) -> &Cell {
        let r = self.resolution;
        let i = v.x as u32 + r.x * (v.y as u32 + r.y * v.z as u32);
        &self.cells[self.map[i as usize] as usize]
    }

    /// All cells.
    pub fn cells(&self) -> &[Cell] {
        &self.cells
    }

    /// Cells that hold triangles.
    pub fn occupied(&self) -> usize {
        self.cells.iter().filter(|c| c.end > c.first).count()
    }

    /// Blocks over all cells.
    pub fn block_count(&self) -> usize {
        self.cells.last().map_or(0, |c| c.end as usize)
    }

    /// Bytes held.
    pub fn bytes(&self) -> usize {
        std::mem::size_of_val(self.map.as_slice()) + std::mem::size_of_val(self.cells.as_slice())
    }

    /// Checks the index's invariants; returns a description of the first broken one.
    pub fn validate(&self) -> Result<(), String> {
        let r = self.resolution;
        if self.map.len() != (r.x * r.y * r.z) as usize {
            return Err("the voxel map does not match the resolution".into());
        }
        if self.cells.windows(2).any(|w| w[0].end != w[1].first)
            || self.cells.first().is_some_and(|c| c.first != 0)
        {
            return Err("cells' blocks are not laid out in cell order".into());
        }
        for (v, &m) in self.map.iter().enumerate() {
            let Some(cell) = self.cells.get(m as usize) else {
                return Err(format!("voxel {v} names cell {m} of {}", self.cells.len()));
            };
            let p = [
                v as u32 % r.x,
                (v as u32 / r.x) % r.y,
                v as u32 / (r.x * r.y),
            ];
            if (0..3).any(|a| p[a] < cell.lo[a] as u32 || p[a] > cell.hi[a] as u32) {
                return Err(format!("voxel {p:?} lies outside the box of its cell {m}"));
            }
        }
        Ok(())
    }
}
