//! A uniform grid over one mesh's triangles, in object space.
//!
//! Cells are stored compactly (Lagae & Dutré 2008): one offset per cell into a single flat
//! array of triangle references. Triangles are inserted only into the cells they really
//! overlap (triangle–box separating-axis test), and traversal is the 3D-DDA of
//! Amanatides & Woo (1987), accepting a hit only if it lies within the current cell.

mod build;
mod overlap;
mod traverse;

use glam::{UVec3, Vec3};

use super::Triangle;
use crate::scene::Aabb;

/// Cells per triangle aimed for by the resolution heuristic (λ in Cleary & Wyvill 1988).
pub const DEFAULT_DENSITY: f32 = 5.0;

/// A uniform grid accelerating ray queries against one triangle list.
#[derive(Clone, Debug)]
pub struct Grid {
    /// The box the cells tile (the triangles' bounds, slightly padded).
    bounds: Aabb,
    /// Cells per axis.
    resolution: UVec3,
    /// Size of one cell per axis.
    cell_size: Vec3,
    /// `1 / cell_size`.
    inv_cell_size: Vec3,
    /// `cell_start[c]..cell_start[c + 1]` indexes `references` for cell `c`.
    cell_start: Vec<u32>,
    /// Triangle indices, grouped by cell.
    references: Vec<u32>,
    /// The triangles, indexed as in the mesh.
    triangles: Vec<Triangle>,
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
    /// Bytes held by the structure, triangles included.
    pub bytes: usize,
}

impl Grid {
    /// The triangles the grid was built over.
    pub fn triangles(&self) -> &[Triangle] {
        &self.triangles
    }

    /// Bounds of the grid's cells.
    pub fn bounds(&self) -> Aabb {
        self.bounds
    }

    /// Cells per axis.
    pub fn resolution(&self) -> UVec3 {
        self.resolution
    }

    /// Size of one cell.
    pub fn cell_size(&self) -> Vec3 {
        self.cell_size
    }

    /// Figures that describe this grid.
    pub fn stats(&self) -> GridStats {
        let cells = self.cell_start.len() - 1;
        let empty = self.cell_start.windows(2).filter(|w| w[0] == w[1]).count();
        let inserted = self.triangles.iter().filter(|t| !t.is_degenerate()).count();
        GridStats {
            resolution: self.resolution,
            cells,
            triangles: inserted,
            references: self.references.len(),
            empty_fraction: if cells == 0 {
                1.0
            } else {
                empty as f64 / cells as f64
            },
            bytes: std::mem::size_of::<Grid>()
                + self.cell_start.len() * 4
                + self.references.len() * 4
                + self.triangles.len() * std::mem::size_of::<Triangle>(),
        }
    }

    /// Triangle references of the cell at integer coordinates `c`.
    #[inline]
    fn cell(&self, c: UVec3) -> &[u32] {
        let i = self.cell_index(c);
        &self.references[self.cell_start[i] as usize..self.cell_start[i + 1] as usize]
    }

    #[inline]
    fn cell_index(&self, c: UVec3) -> usize {
        (c.x + self.resolution.x * (c.y + self.resolution.y * c.z)) as usize
    }

    /// Checks the structure's invariants; returns a description of the first broken one.
    pub fn validate(&self) -> Result<(), String> {
        let cells = (self.resolution.x * self.resolution.y * self.resolution.z) as usize;
        if self.cell_start.len() != cells + 1 {
            return Err(format!(
                "{} offsets for {cells} cells",
                self.cell_start.len()
            ));
        }
        if self.cell_start.windows(2).any(|w| w[0] > w[1]) {
            return Err("cell offsets decrease".into());
        }
        if *self.cell_start.last().unwrap() as usize != self.references.len() {
            return Err("last offset is not the reference count".into());
        }
        if let Some(r) = self
            .references
            .iter()
            .find(|&&r| r as usize >= self.triangles.len())
        {
            return Err(format!(
                "reference {r} past {} triangles",
                self.triangles.len()
            ));
        }
        for (i, tri) in self.triangles.iter().enumerate() {
            if tri.is_degenerate() {
                continue;
            }
            let b = tri.bounds();
            if b.min.cmplt(self.bounds.min).any() || b.max.cmpgt(self.bounds.max).any() {
                return Err(format!("triangle {i} sticks out of the grid bounds"));
            }
            if !self.references.contains(&(i as u32)) {
                return Err(format!("triangle {i} is in no cell"));
            }
        }
        Ok(())
    }
}
