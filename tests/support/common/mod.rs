//! Small glTF files written on the fly: a unit quad mesh in an external `.bin` buffer, with
//! nodes, materials, cameras and extensions chosen by each test.
#![allow(dead_code)]

use std::path::{Path, PathBuf};

use serde_json::{Value, json};

/// The quad's corners (z = 0, facing +Z) and its two triangles.
pub const QUAD_POSITIONS: [[f32; 3]; 4] = [
    [-1.0, -1.0, 0.0],
    [1.0, -1.0, 0.0],
    [1.0, 1.0, 0.0],
    [-1.0, 1.0, 0.0],
];
pub const QUAD_INDICES: [u16; 6] = [0, 1, 2, 0, 2, 3];

/// A glTF document with one buffer holding the quad: accessor 0 = positions,
/// accessor 1 = u16 indices. Mesh 0 uses them with material 0.
pub fn quad_document() -> Value {
    json!({
        "asset": {"version": "2.0"},
        "buffers": [{"uri": "quad.bin", "byteLength": 60}],
        "bufferViews": [
            {"buffer": 0, "byteOffset": 0, "byteLength": 48},
            {"buffer": 0, "byteOffset": 48, "byteLength": 12}
        ],
        "accessors": [
            {"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3",
             "min": [-1.0, -1.0, 0.0], "max": [1.0, 1.0, 0.0]},
            {"bufferView": 1, "componentType": 5123, "count": 6, "type": "SCALAR"}
        ],
        "materials": [{"name": "white", "pbrMetallicRoughness": {"baseColorFactor": [0.8, 0.8, 0.8, 1.0], "metallicFactor": 0.0}}],
        "meshes": [{"name": "quad", "primitives": [{"attributes": {"POSITION": 0}, "indices": 1, "material": 0}]}],
        "nodes": [{"mesh": 0}],
        "scenes": [{"nodes": [0]}],
        "scene": 0
    })
}

/// The quad's buffer bytes.
pub fn quad_buffer() -> Vec<u8> {
    let mut bytes = Vec::new();
    for p in QUAD_POSITIONS {
        for c in p {
            bytes.extend_from_slice(&c.to_le_bytes());
        }
    }
    for i in QUAD_INDICES {
        bytes.extend_from_slice(&i.to_le_bytes());
    }
    bytes
}

/// Writes `document` as `name` (and the quad buffer beside it) into `dir`, and checks it
/// with Khronos' glTF-Validator (`tools/dev/npm`, installed by `tools/dev/setup.sh`).
pub fn write_gltf(dir: &Path, name: &str, document: &Value) -> PathBuf {
    let path = write_unchecked_gltf(dir, name, document);
    validate_gltf(&path);
    path
}

/// Panics with the report unless Khronos' glTF-Validator (`tools/dev/npm/validate.mjs`,
/// installed by `tools/dev/setup.sh`) finds no error in the file at `path`.
pub fn validate_gltf(path: &Path) {
    let validator = Path::new(env!("CARGO_MANIFEST_DIR")).join("tools/dev/npm/validate.mjs");
    let out = std::process::Command::new("node")
        .arg(validator)
        .arg(path)
        .output()
        .expect("node runs (tools/dev/setup.sh)");
    assert!(
        out.status.success(),
        "{}{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
}

/// [`write_gltf`] for a document that breaks the specification on purpose.
pub fn write_unchecked_gltf(dir: &Path, name: &str, document: &Value) -> PathBuf {
    std::fs::write(dir.join("quad.bin"), quad_buffer()).unwrap();
    let path = dir.join(name);
    std::fs::write(&path, serde_json::to_vec_pretty(document).unwrap()).unwrap();
    path
}
