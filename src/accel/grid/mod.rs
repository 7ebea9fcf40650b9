//! A uniform grid over one mesh's triangles, in object space.
//!
//! Triangles go only into the cells they really overlap (triangle–box separating-axis
//! test). Storage is compact (after Lagae & Dutré 2008): one occupancy bit per cell, a
//! running count of occupied cells per 64-bit word (so an occupied cell's rank is one
//! popcount away), offsets for occupied cells only, and each cell's triangles copied in
//! blocks of eight, vertex and edges lane by lane, cell after cell, so a cell's triangles
//! are one contiguous read and are tested eight at a time ([`block`]). A second bit array marks the
//! occupied macrocells of `2^MACRO_SHIFT`³ cells, which lets the walk cross empty space in
//! large steps. Traversal is the 3D-DDA of Amanatides & Woo (1987), accepting a hit only if
//! it lies within the current cell.

mod block;
mod build;
mod overlap;
mod traverse;

pub use traverse::{TraversalCounts, TraversalStats};

use std::ops::Range;

use glam::{IVec3, UVec3, Vec3};

use block::Block;

use super::frame::GridFrame;
use crate::scene::Aabb;

/// Cells per triangle aimed for by the resolution heuristic (λ in Cleary & Wyvill 1988).
pub const DEFAULT_DENSITY: f32 = 5.0;

/// A macrocell is 2^MACRO_SHIFT cells along each axis.
const MACRO_SHIFT: i32 = 3;

/// A uniform grid accelerating ray queries against one triangle list.
#[derive(Clone, Debug)]
pub struct Grid {
    /// The box the cells tile (the triangles' bounds, slightly padded) and its cells.
    frame: GridFrame,
    /// One bit per cell (x fastest, then y, then z): set when the cell holds a triangle.
    occupancy: Vec<u64>,
    /// Occupied cells before each word of `occupancy`.
    rank: Vec<u32>,
    /// For the k-th occupied cell, `offsets[k]..offsets[k + 1]` indexes `blocks`.
    offsets: Vec<u32>,
    /// The triangles of every occupied cell, eight to a block, cell after cell.
    blocks: Vec<Block>,
    /// Triangle references in `blocks` (lanes in use).
    references: usize,
    /// Macrocells per axis.
    macro_resolution: UVec3,
    /// One bit per macrocell: set when any of its cells holds a triangle.
    macro_occupancy: Vec<u64>,
    /// Triangles given to the build, degenerate ones included.
    triangle_count: usize,
    /// Triangles that went into cells (the non-degenerate ones).
    inserted: usize,
}

/// A closest hit in a grid.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GridHit {
    /// Ray parameter.
    pub t: f32,
    /// Barycentric weight of the triangle's second vertex.
    pub u: f32,
    /// Barycentric weight of the triangle's third vertex.
    pub v: f32,
    /// Index of the triangle in the mesh.
    pub triangle: u32,
}

/// Figures that describe a built grid.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GridStats {
    /// Cells per axis.
    pub resolution: UVec3,
    /// Total cells.
    pub cells: usize,
    /// Triangles inserted (degenerate ones are left out).
    pub triangles: usize,
    /// Total triangle references over all cells.
    pub references: usize,
    /// Fraction of cells that hold no triangle.
    pub empty_fraction: f64,
    /// Bytes held by the structure, vertices and cell arrays included.
    pub bytes: usize,
}

impl Grid {
    /// Bounds of the grid's cells.
    pub fn bounds(&self) -> Aabb {
        self.frame.bounds
    }

    /// Cells per axis.
    pub fn resolution(&self) -> UVec3 {
        self.frame.resolution
    }

    /// Size of one cell.
    pub fn cell_size(&self) -> Vec3 {
        self.frame.cell_size
    }

    /// Number of cells.
    fn cell_count(&self) -> usize {
        self.frame.cell_count()
    }

    /// Figures that describe this grid.
    pub fn stats(&self) -> GridStats {
        let cells = self.cell_count();
        let occupied = self.offsets.len() - 1;
        GridStats {
            resolution: self.frame.resolution,
            cells,
            triangles: self.inserted,
            references: self.references,
            empty_fraction: 1.0 - occupied as f64 / cells as f64,
            bytes: std::mem::size_of::<Grid>()
                + std::mem::size_of_val(self.occupancy.as_slice())
                + std::mem::size_of_val(self.rank.as_slice())
                + std::mem::size_of_val(self.offsets.as_slice())
                + std::mem::size_of_val(self.blocks.as_slice())
                + std::mem::size_of_val(self.macro_occupancy.as_slice()),
        }
    }

    #[inline]
    fn cell_index(&self, c: UVec3) -> usize {
        self.frame.cell_index(c)
    }

    /// Where the blocks of cell `index` lie in `blocks`; `None` for empty cells.
    #[inline]
    fn cell_range(&self, index: usize) -> Option<Range<usize>> {
        let word = self.occupancy[index >> 6];
        let bit = 1u64 << (index & 63);
        if word & bit == 0 {
            return None;
        }
        let k = self.rank[index >> 6] as usize + (word & (bit - 1)).count_ones() as usize;
        Some(self.offsets[k] as usize..self.offsets[k + 1] as usize)
    }

    /// True when the macrocell holding cell `c` holds a triangle.
    #[inline]
    fn macro_occupied(&self, c: IVec3) -> bool {
        let m = (c >> MACRO_SHIFT).as_uvec3();
        let index =
            (m.x + self.macro_resolution.x * (m.y + self.macro_resolution.y * m.z)) as usize;
        self.macro_occupancy[index >> 6] & (1 << (index & 63)) != 0
    }

    /// Checks the structure's invariants; returns a description of the first broken one.
    pub fn validate(&self) -> Result<(), String> {
        let cells = self.cell_count();
        if self.occupancy.len() != cells.div_ceil(64) || self.rank.len() != self.occupancy.len() {
            return Err(format!(
                "{} occupancy words and {} ranks for {cells} cells",
                self.occupancy.len(),
                self.rank.len()
            ));
        }
        let mut occupied = 0u32;
        for (w, &word) in self.occupancy.iter().enumerate() {
            if self.rank[w] != occupied {
                return Err(format!(
                    "rank of word {w} is {}, expected {occupied}",
                    self.rank[w]
                ));
            }
            occupied += word.count_ones();
        }
        if self.offsets.len() != occupied as usize + 1 {
            return Err(format!(
                "{} offsets for {occupied} occupied cells",
                self.offsets.len()
            ));
        }
        if self.offsets.windows(2).any(|w| w[0] >= w[1]) {
            return Err("an occupied cell is empty or offsets decrease".into());
        }
        if *self.offsets.last().unwrap() as usize != self.blocks.len() {
            return Err("offsets and blocks disagree in length".into());
        }
        if self.blocks.iter().any(|b| b.len() == 0)
            || self.blocks.iter().map(Block::len).sum::<usize>() != self.references
        {
            return Err("a block is empty, or the blocks hold the wrong reference count".into());
        }
        let mut seen = vec![false; self.triangle_count];
        for z in 0..self.frame.resolution.z {
            for y in 0..self.frame.resolution.y {
                for x in 0..self.frame.resolution.x {
                    let c = UVec3::new(x, y, z);
                    let Some(range) = self.cell_range(self.cell_index(c)) else {
                        continue;
                    };
                    if !self.macro_occupied(c.as_ivec3()) {
                        return Err(format!(
                            "cell {c} is occupied but its macrocell is marked empty"
                        ));
                    }
                    let lo = self.frame.bounds.min + c.as_vec3() * self.frame.cell_size;
                    let cell = Aabb {
                        min: lo - self.frame.cell_size * 1e-3,
                        max: lo + self.frame.cell_size * 1.001,
                    };
                    let stored = range
                        .flat_map(|k| (0..block::LANES).filter_map(move |l| self.blocks[k].get(l)));
                    for (triangle, id) in stored {
                        let id = id as usize;
                        let b = triangle.bounds();
                        if id >= self.triangle_count {
                            return Err(format!(
                                "cell {c} refers to triangle {id} of {}",
                                self.triangle_count
                            ));
                        }
                        if b.max.cmplt(cell.min).any() || b.min.cmpgt(cell.max).any() {
                            return Err(format!(
                                "triangle {id} is stored in cell {c}, which it does not touch"
                            ));
                        }
                        seen[id] = true;
                    }
                }
            }
        }
        let in_cells = seen.iter().filter(|&&s| s).count();
        if in_cells != self.inserted {
            return Err(format!(
                "{in_cells} triangles are in cells, {} were inserted",
                self.inserted
            ));
        }
        Ok(())
    }
}
