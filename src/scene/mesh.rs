//! Triangle meshes in object space.

use glam::{Vec2, Vec3, Vec4};

use crate::geometry::Aabb;

/// An indexed triangle mesh with one material.
#[derive(Clone, Debug, Default)]
pub struct Mesh {
    /// Name for messages (for glTF: mesh name and primitive index).
    pub name: String,
    /// Vertex positions.
    pub positions: Vec<Vec3>,
    /// Per-vertex shading normals, unit length; same length as `positions`, or empty for
    /// flat shading with the face normal.
    pub normals: Vec<Vec3>,
    /// Texture-coordinate sets (`TEXCOORD_n`), each empty or as long as `positions`.
    pub uvs: Vec<Vec<Vec2>>,
    /// Per-vertex linear RGBA colours (`COLOR_0`); empty or as long as `positions`.
    pub colours: Vec<Vec4>,
    /// Per-vertex tangents with the bitangent sign in w (glTF `TANGENT`, or MikkTSpace);
    /// empty unless a normal map needs them.
    pub tangents: Vec<Vec4>,
    /// Triangles as vertex indices, counter-clockwise seen from the front.
    pub indices: Vec<[u32; 3]>,
    /// Index into [`super::Scene::materials`].
    pub material: usize,
}

impl Mesh {
    /// Texture coordinates of set `set` at vertex `vertex`; zero if the mesh has none.
    pub fn uv(&self, set: usize, vertex: usize) -> Vec2 {
        self.uvs
            .get(set)
            .and_then(|uvs| uvs.get(vertex))
            .copied()
            .unwrap_or(Vec2::ZERO)
    }

    /// Bounds of the finite vertices (a NaN or infinite corner's triangles are never hit, and
    /// must not throw the default camera to infinity).
    pub fn bounds(&self) -> Aabb {
        Aabb::from_points(self.positions.iter().copied().filter(|p| p.is_finite()))
    }

    /// Area-weighted vertex normals, for meshes that come without normals.
    ///
    /// Vertices used by no triangle (or only by degenerate ones) get +Z.
    pub fn compute_vertex_normals(positions: &[Vec3], indices: &[[u32; 3]]) -> Vec<Vec3> {
        let mut sums = vec![Vec3::ZERO; positions.len()];
        for tri in indices {
            let [a, b, c] = tri.map(|i| positions[i as usize]);
            // The cross product's length is twice the area: an area weight for free.
            let n = (b - a).cross(c - a);
            for &i in tri {
                sums[i as usize] += n;
            }
        }
        sums.into_iter()
            .map(|n| n.try_normalize().unwrap_or(Vec3::Z))
            .collect()
    }
}
