//! Parsing a document whose animations use `KHR_animation_pointer`, whose channels target
//! any property by JSON pointer (Blender's exporter writes them for material, light and
//! camera animation with its experimental "Animation Pointer" option). The `gltf` crate
//! reads only node channels and refuses the whole file otherwise, so those channels are
//! taken out of the JSON before it parses the document: the file loads, its node
//! animation plays, and the extension is named among the ignored ones.

const EXTENSION: &[u8] = b"KHR_animation_pointer";

/// The document and binary chunk of glTF or GLB `bytes`, without pointer channels.
pub fn parse(bytes: &[u8]) -> Result<gltf::Gltf, String> {
    if !json_part(bytes)
        .windows(EXTENSION.len())
        .any(|w| w == EXTENSION)
    {
        return gltf::Gltf::from_slice_without_validation(bytes).map_err(|e| e.to_string());
    }
    let (json, blob) = if bytes.starts_with(b"glTF") {
        let mut glb = gltf::binary::Glb::from_slice(bytes).map_err(|e| e.to_string())?;
        let blob = glb.bin.take().map(|b| b.into_owned());
        (glb.json.into_owned(), blob)
    } else {
        (bytes.to_vec(), None)
    };
    let mut value: gltf::json::Value =
        gltf::json::deserialize::from_slice(&json).map_err(|e| e.to_string())?;
    if let Some(animations) = value.get_mut("animations").and_then(|a| a.as_array_mut()) {
        for animation in animations {
            if let Some(channels) = animation.get_mut("channels").and_then(|c| c.as_array_mut()) {
                channels.retain(|c| c["target"]["path"] != "pointer");
            }
        }
    }
    let root: gltf::json::Root =
        gltf::json::deserialize::from_value(value).map_err(|e| e.to_string())?;
    Ok(gltf::Gltf {
        document: gltf::Document::from_json_without_validation(root),
        blob,
    })
}

/// The bytes that can hold the JSON: a GLB's first chunk (its length at bytes 12–15), or
/// the whole of a .gltf. Searching there keeps the check off the binary chunk.
fn json_part(bytes: &[u8]) -> &[u8] {
    if bytes.starts_with(b"glTF") && bytes.len() >= 20 {
        let length = u32::from_le_bytes([bytes[12], bytes[13], bytes[14], bytes[15]]) as usize;
        &bytes[20..bytes.len().min(20 + length)]
    } else {
        bytes
    }
}
