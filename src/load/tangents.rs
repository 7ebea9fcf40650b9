//! Tangents for normal mapping when a file has none, by MikkTSpace (Mikkelsen 2008), the
//! convention Blender bakes normal maps in and glTF prescribes.

use glam::{Vec2, Vec3, Vec4};

use crate::scene::Mesh;

/// Gives `mesh` per-corner tangents from its texture-coordinate set `uv_set`. MikkTSpace
/// works per triangle corner, so the mesh is first split into three vertices per triangle
/// (only meshes with normal maps and no tangents pay for this). Returns false, leaving the
/// mesh unchanged, when the mesh has no such texture coordinates or MikkTSpace fails.
pub fn generate_tangents(mesh: &mut Mesh, uv_set: usize) -> bool {
    let Some(uvs) = mesh
        .uvs
        .get(uv_set)
        .filter(|u| u.len() == mesh.positions.len())
    else {
        return false;
    };
    let corners: Vec<usize> = mesh
        .indices
        .iter()
        .flat_map(|t| t.map(|i| i as usize))
        .collect();
    let positions: Vec<Vec3> = corners.iter().map(|&i| mesh.positions[i]).collect();
    let normals: Vec<Vec3> = if mesh.normals.is_empty() {
        // Flat shading: each corner gets its face normal.
        mesh.indices
            .iter()
            .flat_map(|t| {
                let [a, b, c] = t.map(|i| mesh.positions[i as usize]);
                let n = (b - a).cross(c - a).normalize_or_zero();
                [n, n, n]
            })
            .collect()
    } else {
        corners.iter().map(|&i| mesh.normals[i]).collect()
    };
    let mut geometry = Corners {
        positions: &positions,
        normals: &normals,
        uvs: corners.iter().map(|&i| uvs[i]).collect(),
        tangents: vec![Vec4::new(1.0, 0.0, 0.0, 1.0); corners.len()],
    };
    if !mikktspace::generate_tangents(&mut geometry) {
        return false;
    }
    let tangents = geometry.tangents;
    let split = |v: &Vec<Vec2>| -> Vec<Vec2> {
        if v.len() == mesh.positions.len() {
            corners.iter().map(|&i| v[i]).collect()
        } else {
            Vec::new()
        }
    };
    mesh.uvs = mesh.uvs.iter().map(split).collect();
    if !mesh.colours.is_empty() {
        mesh.colours = corners.iter().map(|&i| mesh.colours[i]).collect();
    }
    mesh.normals = if mesh.normals.is_empty() {
        Vec::new()
    } else {
        normals
    };
    mesh.positions = positions;
    mesh.tangents = tangents;
    mesh.indices = (0..mesh.indices.len() as u32)
        .map(|t| [3 * t, 3 * t + 1, 3 * t + 2])
        .collect();
    true
}

/// A triangle list, one entry per corner, as MikkTSpace sees it.
struct Corners<'a> {
    positions: &'a [Vec3],
    normals: &'a [Vec3],
    uvs: Vec<Vec2>,
    tangents: Vec<Vec4>,
}

impl mikktspace::Geometry for Corners<'_> {
    fn num_faces(&self) -> usize {
        self.positions.len() / 3
    }

    fn num_vertices_of_face(&self, _face: usize) -> usize {
        3
    }

    fn position(&self, face: usize, vert: usize) -> [f32; 3] {
        self.positions[3 * face + vert].into()
    }

    fn normal(&self, face: usize, vert: usize) -> [f32; 3] {
        self.normals[3 * face + vert].into()
    }

    fn tex_coord(&self, face: usize, vert: usize) -> [f32; 2] {
        self.uvs[3 * face + vert].into()
    }

    fn set_tangent_encoded(&mut self, tangent: [f32; 4], face: usize, vert: usize) {
        // MikkTSpace's bitangent follows increasing v, which in glTF runs down the image;
        // a glTF normal map's +Y (green) points up the image, so the sign flips.
        let [x, y, z, w] = tangent;
        self.tangents[3 * face + vert] = Vec4::new(x, y, z, -w);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A quad in the XY plane facing +Z with u along +X and v along −Y (glTF's v points down
    /// the image): the tangent must be +X and the bitangent, sign × N × T, must point up the
    /// image (−v), where a glTF normal map's green axis points.
    #[test]
    fn tangents_follow_the_texture_axes() {
        let mut mesh = Mesh {
            name: "quad".into(),
            positions: vec![
                Vec3::new(0.0, 0.0, 0.0),
                Vec3::new(1.0, 0.0, 0.0),
                Vec3::new(1.0, 1.0, 0.0),
                Vec3::new(0.0, 1.0, 0.0),
            ],
            normals: vec![Vec3::Z; 4],
            uvs: vec![vec![
                Vec2::new(0.0, 1.0),
                Vec2::new(1.0, 1.0),
                Vec2::new(1.0, 0.0),
                Vec2::new(0.0, 0.0),
            ]],
            indices: vec![[0, 1, 2], [0, 2, 3]],
            ..Mesh::default()
        };
        assert!(generate_tangents(&mut mesh, 0));
        assert_eq!(mesh.positions.len(), 6);
        for t in &mesh.tangents {
            assert!((t.truncate() - Vec3::X).length() < 1e-5, "{t}");
            // Up the image, where v shrinks: +Y here.
            let bitangent = t.w * Vec3::Z.cross(t.truncate());
            assert!((bitangent - Vec3::Y).length() < 1e-5, "{bitangent}");
        }
    }
}
