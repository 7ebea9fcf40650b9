//! The triangles a grid is built over, made from the mesh's vertices and indices each time
//! the build asks for one instead of copied out first: the copy (40 bytes a triangle,
//! 35 MB for the full dragon) was memory the build wrote once and read back, and on a
//! machine that hands out fresh pages slowly, writing it cost more than making the
//! triangles again where they are needed.

use glam::Vec3;

use crate::accel::Triangle;

/// A triangle list seen through an indexed mesh.
#[derive(Clone, Copy, Debug)]
pub(in crate::accel::grid) struct MeshTriangles<'a> {
    vertices: &'a [Vec3],
    indices: &'a [[u32; 3]],
}

impl<'a> MeshTriangles<'a> {
    pub fn new(vertices: &'a [Vec3], indices: &'a [[u32; 3]]) -> MeshTriangles<'a> {
        MeshTriangles { vertices, indices }
    }

    /// Triangle `t`, or `None` when it is degenerate (no area, non-finite corners) or its
    /// corners lie past the vertex array: such a triangle goes into no cell.
    #[inline]
    pub fn live(&self, t: usize) -> Option<Triangle> {
        let corners = self.indices[t];
        corners
            .iter()
            .all(|&i| (i as usize) < self.vertices.len())
            .then(|| self.get(t as u32))
            .filter(|triangle| !triangle.is_degenerate())
    }

    /// Triangle `t`, one [`MeshTriangles::live`] has given.
    #[inline(always)]
    pub fn get(&self, t: u32) -> Triangle {
        let [a, b, c] = self.indices[t as usize];
        Triangle::new(
            self.vertices[a as usize],
            self.vertices[b as usize],
            self.vertices[c as usize],
        )
    }
}
