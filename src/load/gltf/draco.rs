//! `KHR_draco_mesh_compression`: a primitive whose geometry is one Draco bitstream in a
//! buffer view, its attributes named by Draco unique ids.
//!
//! Decoded by `draco-core`, a Rust port of Google's reference decoder that bounds what a
//! hostile header may make it allocate (its `DecodeLimits`; ours are the memory budget).
//! The glTF accessors keep their role as the description of each attribute (component
//! type, normalisation, count), as the extension's specification requires.

use std::collections::HashMap;

use draco_core::{DecodeLimits, DecoderBuffer, Mesh, MeshDecoder};

use super::accessor::{Elements, normalize_as};
use crate::limits::memory_left;
use crate::load::guard::catching_panics;

/// The extension's name.
pub const EXTENSION: &str = "KHR_draco_mesh_compression";

/// A decoded Draco primitive: its attributes by glTF semantic, and its triangles.
pub(super) struct DracoGeometry {
    attributes: HashMap<String, Elements>,
    pub indices: Vec<u32>,
}

impl DracoGeometry {
    /// The attribute for `semantic` (`"POSITION"`, `"TEXCOORD_0"`, ...), if the stream has it.
    pub fn take(&mut self, semantic: &str) -> Option<Elements> {
        self.attributes.remove(semantic)
    }
}

/// The primitive's Draco geometry, or `None` when it has no such extension.
pub(super) fn decode(
    primitive: &gltf::Primitive,
    document: &gltf::Document,
    buffers: &[gltf::buffer::Data],
) -> Result<Option<DracoGeometry>, String> {
    let Some(extension) = primitive.extension_value(EXTENSION) else {
        return Ok(None);
    };
    let view_index = extension["bufferView"]
        .as_u64()
        .ok_or(format!("{EXTENSION} without a bufferView"))? as usize;
    let view = document.views().nth(view_index).ok_or(format!(
        "{EXTENSION}: buffer view {view_index} does not exist"
    ))?;
    let buffer = buffers
        .get(view.buffer().index())
        .map_or(&[][..], |b| &b.0[..]);
    let stream = view
        .offset()
        .checked_add(view.length())
        .and_then(|end| buffer.get(view.offset()..end))
        .ok_or(format!(
            "{EXTENSION}: buffer view {view_index} runs past its buffer ({} bytes)",
            buffer.len()
        ))?;
    let defaults = DecodeLimits::default();
    let limits = defaults.with_max_decoded_bytes(defaults.max_decoded_bytes.min(memory_left()));
    let mut mesh = Mesh::new();
    catching_panics(|| {
        MeshDecoder::new().decode(
            &mut DecoderBuffer::new(stream).with_limits(limits),
            &mut mesh,
        )
    })
    .map_err(|why| {
        format!("{EXTENSION}: the Draco stream cannot be decoded (the decoder failed: {why})")
    })?
    .map_err(|e| format!("{EXTENSION}: the Draco stream cannot be decoded ({e})"))?;
    let points = mesh.num_points();
    let mut attributes = HashMap::new();
    let Some(map) = extension["attributes"].as_object() else {
        return Err(format!("{EXTENSION} without an attributes map"));
    };
    for (semantic, id) in map {
        let id = id
            .as_u64()
            .ok_or(format!("{EXTENSION}: attribute {semantic} has no id"))?;
        let Some(attribute) = u32::try_from(id)
            .ok()
            .and_then(|id| mesh.attribute_by_unique_id(id))
        else {
            return Err(format!(
                "{EXTENSION}: attribute {semantic} (id {id}) is not in the Draco stream"
            ));
        };
        // The accessor describes the decoded attribute (component count, normalisation).
        let accessor = primitive
            .attributes()
            .find(|(s, _)| s.to_string() == *semantic)
            .map(|(_, a)| a);
        let components = accessor
            .as_ref()
            .map_or(attribute.num_components() as usize, |a| {
                a.dimensions().multiplicity()
            });
        let mut values = attribute.read_f32s(points, components);
        if let Some(a) = accessor.as_ref().filter(|a| a.normalized()) {
            for v in &mut values {
                *v = normalize_as(a.data_type(), *v);
            }
        }
        attributes.insert(semantic.clone(), Elements { values, components });
    }
    let indices = mesh
        .faces()
        .iter()
        .flat_map(|face| face.map(|p| p.0))
        .collect();
    Ok(Some(DracoGeometry {
        attributes,
        indices,
    }))
}
