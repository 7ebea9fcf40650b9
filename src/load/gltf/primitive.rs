//! A glTF mesh primitive as a scene mesh: its vertex attributes read from accessors (any
//! storage, `KHR_mesh_quantization` included) or from a Draco stream, its triangles from a
//! list, strip or fan.

use glam::{Vec2, Vec3, Vec4};
use gltf::mesh::Mode;

use super::accessor::{Elements, read_floats, read_indices};
use super::deform::{self, Deformation};
use super::draco::{self, DracoGeometry};
use super::{GltfLoader, MAX_UV_SETS};
use crate::load::LoadError;
use crate::load::tangents::generate_tangents;
use crate::scene::Mesh;

/// The attributes of one primitive, from wherever its file keeps them.
pub(super) struct VertexSource<'a> {
    primitive: &'a gltf::Primitive<'a>,
    buffers: &'a [gltf::buffer::Data],
    draco: Option<DracoGeometry>,
}

impl<'a> VertexSource<'a> {
    pub fn new(
        primitive: &'a gltf::Primitive<'a>,
        document: &gltf::Document,
        buffers: &'a [gltf::buffer::Data],
    ) -> Result<(VertexSource<'a>, Option<String>), String> {
        // A Draco stream that cannot be decoded falls back to the accessors' own data when
        // every one of them has some (the extension allows files to carry both).
        let has_fallback = primitive.attributes().all(|(_, a)| a.view().is_some())
            && primitive.indices().is_none_or(|a| a.view().is_some());
        let (draco, warning) = match draco::decode(primitive, document, buffers) {
            Ok(draco) => (draco, None),
            Err(why) if has_fallback => (
                None,
                Some(format!("{why}; using the uncompressed accessors")),
            ),
            Err(why) => return Err(why),
        };
        let source = VertexSource {
            primitive,
            buffers,
            draco,
        };
        Ok((source, warning))
    }

    /// The attribute named `semantic` (`"POSITION"`, `"TEXCOORD_1"`, ...), if present.
    pub fn attribute(&mut self, semantic: &str) -> Result<Option<Elements>, String> {
        if let Some(draco) = &mut self.draco
            && let Some(elements) = draco.take(semantic)
        {
            return Ok(Some(elements));
        }
        match self
            .primitive
            .attributes()
            .find(|(s, _)| s.to_string() == semantic)
        {
            Some((_, accessor)) => read_floats(&accessor, self.buffers)
                .map(Some)
                .map_err(|why| format!("{semantic}: {why}")),
            None => Ok(None),
        }
    }

    /// Any accessor of the file (morph targets), as numbers.
    pub fn read(&self, accessor: &gltf::Accessor) -> Result<Elements, String> {
        read_floats(accessor, self.buffers)
    }

    /// The corner indices, or `None` for non-indexed geometry.
    pub fn indices(&mut self) -> Result<Option<Vec<u32>>, String> {
        if let Some(draco) = &mut self.draco {
            return Ok(Some(std::mem::take(&mut draco.indices)));
        }
        self.primitive
            .indices()
            .map(|accessor| read_indices(&accessor, self.buffers))
            .transpose()
    }
}

impl GltfLoader {
    pub(super) fn convert_primitive(
        &mut self,
        document: &gltf::Document,
        mesh: &gltf::Mesh,
        primitive: &gltf::Primitive,
        deformation: Deformation,
    ) -> Result<Option<Mesh>, LoadError> {
        let name = format!(
            "mesh {} '{}' primitive {}",
            mesh.index(),
            mesh.name().unwrap_or(""),
            primitive.index()
        );
        if matches!(
            primitive.mode(),
            Mode::Points | Mode::Lines | Mode::LineLoop | Mode::LineStrip
        ) {
            self.warn(format!(
                "{name}: skipping {:?} primitive (only triangles are rendered)",
                primitive.mode()
            ));
            return Ok(None);
        }
        let path = self.path.clone();
        let invalid = |why: String| LoadError::Invalid {
            path: path.clone(),
            what: format!("{name}: {why}"),
        };
        let (mut source, fallback) =
            VertexSource::new(primitive, document, &self.buffers).map_err(invalid)?;
        let fallback = fallback.map(|warning| format!("{name}: {warning}"));
        let Some(positions) = source.attribute("POSITION").map_err(invalid)? else {
            return Err(invalid("no POSITION attribute".into()));
        };
        let mut positions: Vec<Vec3> = (0..positions.len())
            .map(|i| Vec3::from(positions.get::<3>(i)))
            .collect();
        let corners: Vec<u32> = match source.indices().map_err(invalid)? {
            Some(indices) => indices,
            None => (0..positions.len() as u32).collect(),
        };
        // The position, not the value: a buffer's bytes never reach a message (the file
        // may be a hard link to one the scene's author could not otherwise show).
        if let Some(bad) = corners.iter().position(|&i| i as usize >= positions.len()) {
            return Err(invalid(format!(
                "indices[{bad}] is past the {} vertices",
                positions.len()
            )));
        }
        let count = positions.len();
        let per_vertex = move |e: Option<Elements>| e.filter(|e| e.len() == count);
        let mut normals: Vec<Vec3> = per_vertex(source.attribute("NORMAL").map_err(invalid)?)
            .map(|n| (0..n.len()).map(|i| Vec3::from(n.get::<3>(i))).collect())
            .unwrap_or_default();
        let mut tangents: Vec<Vec4> = per_vertex(source.attribute("TANGENT").map_err(invalid)?)
            .map(|t| (0..t.len()).map(|i| Vec4::from(t.get::<4>(i))).collect())
            .unwrap_or_default();
        if !deformation.is_rest() {
            deform::apply(
                &mut source,
                primitive,
                deformation,
                &mut positions,
                &mut normals,
                &mut tangents,
            )
            .map_err(invalid)?;
        }
        let normals: Vec<Vec3> = normals
            .iter()
            .map(|n| n.try_normalize().unwrap_or(Vec3::ZERO))
            .collect();
        // Without (usable) normals, glTF asks for flat shading: empty means face normals.
        let normals = if normals.iter().all(|n| *n != Vec3::ZERO) {
            normals
        } else {
            Vec::new()
        };
        let mut uvs = Vec::new();
        while uvs.len() < MAX_UV_SETS {
            let Some(set) = source
                .attribute(&format!("TEXCOORD_{}", uvs.len()))
                .map_err(invalid)?
            else {
                break;
            };
            uvs.push(if set.len() == positions.len() {
                (0..set.len())
                    .map(|i| Vec2::from(set.get::<2>(i)))
                    .collect()
            } else {
                Vec::new()
            });
        }
        let colours: Vec<Vec4> = per_vertex(source.attribute("COLOR_0").map_err(invalid)?)
            .map(|c| {
                let opaque = c.components < 4;
                (0..c.len())
                    .map(|i| {
                        let v = Vec4::from(c.get::<4>(i));
                        if opaque { v.with_w(1.0) } else { v }
                    })
                    .collect()
            })
            .unwrap_or_default();
        let indices = triangles(primitive.mode(), &corners);
        let leftover = if primitive.mode() == Mode::Triangles {
            corners.len() % 3
        } else {
            0
        };
        if let Some(warning) = fallback {
            self.warn(warning);
        }
        if leftover != 0 {
            self.warn(format!(
                "{name}: {leftover} index(es) left over after the last whole triangle"
            ));
        }
        // COLOR_0 multiplies the base colour of any material, the default one included
        // (glTF 2.0 §3.7.2.1).
        let material = self.material_for(primitive);
        if !colours.is_empty() {
            self.coloured_materials.insert(material);
        }
        let mut mesh = Mesh {
            name,
            positions,
            normals,
            uvs,
            colours,
            tangents,
            indices,
            material,
        };
        let normal_uvs = self
            .material_index(primitive)
            .and_then(|m| self.normal_mapped.get(m).copied().flatten());
        if let Some(set) = normal_uvs
            && mesh.tangents.is_empty()
            && !generate_tangents(&mut mesh, set)
        {
            self.warn(format!(
                "{}: a normal map needs TEXCOORD_{set}, which is missing; the normal map is ignored here",
                mesh.name
            ));
        }
        Ok(Some(mesh))
    }
}

/// Triangles from a list, strip or fan of corner indices (glTF 2.0 §3.7.2.1).
fn triangles(mode: Mode, corners: &[u32]) -> Vec<[u32; 3]> {
    match mode {
        Mode::TriangleStrip => (0..corners.len().saturating_sub(2))
            .map(|i| {
                if i % 2 == 0 {
                    [corners[i], corners[i + 1], corners[i + 2]]
                } else {
                    [corners[i], corners[i + 2], corners[i + 1]]
                }
            })
            .collect(),
        Mode::TriangleFan => (1..corners.len().saturating_sub(1))
            .map(|i| [corners[i], corners[i + 1], corners[0]])
            .collect(),
        _ => corners
            .chunks_exact(3)
            .map(|c| [c[0], c[1], c[2]])
            .collect(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn strips_and_fans_keep_winding() {
        assert_eq!(
            triangles(Mode::TriangleStrip, &[0, 1, 2, 3]),
            vec![[0, 1, 2], [1, 3, 2]]
        );
        assert_eq!(
            triangles(Mode::TriangleFan, &[0, 1, 2, 3]),
            vec![[1, 2, 0], [2, 3, 0]]
        );
        assert_eq!(triangles(Mode::Triangles, &[0, 1, 2, 3]), vec![[0, 1, 2]]);
        assert!(triangles(Mode::TriangleStrip, &[0, 1]).is_empty());
    }
}
