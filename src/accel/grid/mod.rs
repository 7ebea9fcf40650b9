//! A uniform grid over one mesh's triangles, in object space (or in world space, for a mesh
//! placed once).
//!
//! Triangles go only into the cells they really overlap (triangle–box separating-axis
//! test). Storage is compact (after Lagae & Dutré 2008): offsets for occupied cells only,
//! found through a two-level index of macrocell records ([`cells`]), and each cell's
//! triangles copied in blocks of eight, vertex and edges lane by lane, cell after cell, so
//! a cell's triangles are one contiguous read and are tested eight at a time ([`block`]).
//! Empty macrocells know how far empty space reaches from them towards each octant of
//! directions ([`reach`]), and empty cells of occupied macrocells the same at the level of
//! cells ([`cell_reach`]), so the walk leaps over empty space. Large grids keep boxes of
//! each occupied cell's triangles, and the largest of each block's, so the walk passes cells
//! and blocks the ray cannot meet there without reading them ([`cell_box`]). Traversal is
//! the 3D-DDA of Amanatides & Woo (1987), accepting a hit only if it lies within the
//! current cell.

mod build;
mod cell_lanes;
pub(crate) mod frame;
mod storage;
mod view;
pub(crate) mod walk;

pub use view::{View, ViewGrid, ViewHit};
pub use walk::stats::{TraversalCounts, TraversalStats};

use glam::{UVec3, Vec3};

use crate::geometry::Aabb;
use frame::GridFrame;
use storage::block::{self, Block};
use storage::cell_box;
use storage::cells::{CellIndex, Lookup};

/// A uniform grid accelerating ray queries against one triangle list.
#[derive(Clone, Debug)]
pub struct Grid {
    /// The box the cells tile (the triangles' bounds, slightly padded) and its cells.
    frame: GridFrame,
    /// Which cells hold triangles, and where their blocks lie.
    cells: CellIndex,
    /// The triangles of every occupied cell, eight to a block, cell after cell.
    blocks: Vec<Block>,
    /// For a grid whose blocks outgrow the last-level cache ([`cell_box::boxes_for`]), each
    /// block's box word within its cell, so the walk tests only the blocks of a cell whose
    /// boxes the ray meets; empty otherwise.
    block_boxes: Vec<u32>,
    /// Triangle references in `blocks` (lanes in use).
    references: usize,
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

    /// Triangles inserted (degenerate ones are left out).
    pub fn triangles(&self) -> usize {
        self.inserted
    }

    /// Number of cells.
    fn cell_count(&self) -> usize {
        self.frame.cell_count()
    }

    /// Figures that describe this grid.
    pub fn stats(&self) -> GridStats {
        let cells = self.cell_count();
        let occupied = self.cells.occupied();
        GridStats {
            resolution: self.frame.resolution,
            cells,
            triangles: self.inserted,
            references: self.references,
            empty_fraction: 1.0 - occupied as f64 / cells as f64,
            bytes: std::mem::size_of::<Grid>()
                + self.cells.bytes()
                + std::mem::size_of_val(self.blocks.as_slice())
                + std::mem::size_of_val(self.block_boxes.as_slice()),
        }
    }

    /// Where cell `c` is counted in storage order.
    #[inline]
    fn storage_key(&self, c: UVec3) -> usize {
        CellIndex::storage_key(CellIndex::macro_resolution_for(self.frame.resolution), c)
    }

    /// Every triangle of the grid once, as its blocks hold it (the very numbers the walk
    /// tests), with its index in the mesh, in the order of first appearance.
    pub(crate) fn unique_triangles(&self) -> Vec<(crate::accel::Triangle, u32)> {
        let mut seen = vec![false; self.triangle_count];
        let mut triangles = Vec::with_capacity(self.inserted);
        for block in &self.blocks {
            for (triangle, id) in (0..block::LANES).filter_map(|l| block.get(l)) {
                if !std::mem::replace(&mut seen[id as usize], true) {
                    triangles.push((triangle, id));
                }
            }
        }
        triangles
    }

    /// Checks the structure's invariants; returns a description of the first broken one.
    pub fn validate(&self) -> Result<(), String> {
        self.cells.validate(self.frame.resolution)?;
        if self.cells.block_count() != self.blocks.len() {
            return Err("offsets and blocks disagree in length".into());
        }
        let boxes = self.block_boxes.len();
        if boxes != 0 && (boxes != self.blocks.len() || self.cells.box_margin().is_none()) {
            return Err(format!(
                "{boxes} block boxes for {} blocks",
                self.blocks.len()
            ));
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
                    let Lookup::Blocks(range, k) = self.cells.lookup(c.as_ivec3(), 0) else {
                        continue;
                    };
                    let boxed = self.cells.box_margin().map(|m| (self.cells.cell_box(k), m));
                    let lo = self.frame.bounds.min + c.as_vec3() * self.frame.cell_size;
                    let cell = Aabb {
                        min: lo - self.frame.cell_size * 1e-3,
                        max: lo + self.frame.cell_size * 1.001,
                    };
                    let stored = range.flat_map(|k| {
                        (0..block::LANES).filter_map(move |l| self.blocks[k].get(l).map(|s| (k, s)))
                    });
                    for (block_number, (triangle, id)) in stored {
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
                        if let Some((word, margin)) = boxed
                            && !cell_box::holds(&self.frame, c.as_ivec3(), word, margin, &triangle)
                        {
                            return Err(format!("cell {c}'s box does not hold triangle {id}"));
                        }
                        if let Some((_, margin)) = boxed.filter(|_| boxes != 0)
                            && !cell_box::holds(
                                &self.frame,
                                c.as_ivec3(),
                                self.block_boxes[block_number],
                                margin,
                                &triangle,
                            )
                        {
                            return Err(format!(
                                "block {block_number}'s box does not hold triangle {id}"
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
