//! PLY meshes (ASCII or binary, optionally gzip-compressed) through the `ply-rs-bw` crate.
//!
//! A PLY file holds one mesh and nothing else: it becomes one instance with a grey
//! Lambertian material, without camera or lights.

use std::io::{BufReader, Read};
use std::path::Path;

use glam::Vec3;
use ply_rs_bw::parser::Parser;
use ply_rs_bw::ply::{Property, PropertyAccess};

use super::{LoadError, Loaded};
use crate::limits::check_memory;
use crate::scene::{Material, Mesh, SceneBuilder};

/// A vertex position; other vertex properties are ignored.
#[derive(Default)]
struct PlyVertex(Vec3);

/// A polygon as vertex indices.
#[derive(Default)]
struct PlyFace(Vec<i64>);

fn scalar(p: &Property) -> Option<f32> {
    Some(match *p {
        Property::Float(v) => v,
        Property::Double(v) => v as f32,
        Property::Char(v) => v as f32,
        Property::UChar(v) => v as f32,
        Property::Short(v) => v as f32,
        Property::UShort(v) => v as f32,
        Property::Int(v) => v as f32,
        Property::UInt(v) => v as f32,
        _ => return None,
    })
}

impl PropertyAccess for PlyVertex {
    fn new() -> Self {
        PlyVertex::default()
    }
    fn set_property(
        &mut self,
        key: &str,
        property: Property,
    ) -> ply_rs_bw::ply::PropertyAccessResult {
        let axis = match key {
            "x" => 0,
            "y" => 1,
            "z" => 2,
            _ => return ply_rs_bw::ply::PropertyAccessResult::Ignored,
        };
        match scalar(&property) {
            Some(v) => {
                self.0[axis] = v;
                ply_rs_bw::ply::PropertyAccessResult::Set
            }
            None => ply_rs_bw::ply::PropertyAccessResult::Ignored,
        }
    }
}

impl PropertyAccess for PlyFace {
    fn new() -> Self {
        PlyFace::default()
    }
    fn set_property(
        &mut self,
        key: &str,
        property: Property,
    ) -> ply_rs_bw::ply::PropertyAccessResult {
        if key != "vertex_indices" && key != "vertex_index" {
            return ply_rs_bw::ply::PropertyAccessResult::Ignored;
        }
        self.0 = match property {
            Property::ListChar(v) => v.into_iter().map(i64::from).collect(),
            Property::ListUChar(v) => v.into_iter().map(i64::from).collect(),
            Property::ListShort(v) => v.into_iter().map(i64::from).collect(),
            Property::ListUShort(v) => v.into_iter().map(i64::from).collect(),
            Property::ListInt(v) => v.into_iter().map(i64::from).collect(),
            Property::ListUInt(v) => v.into_iter().map(i64::from).collect(),
            _ => return ply_rs_bw::ply::PropertyAccessResult::Ignored,
        };
        ply_rs_bw::ply::PropertyAccessResult::Set
    }
}

/// Reads the positions and triangles of a PLY file (`.ply` or `.ply.gz`). Polygons with
/// more than three corners are split into fans.
pub fn read_mesh(path: &Path) -> Result<(Vec<Vec3>, Vec<[u32; 3]>), LoadError> {
    let io = |source| LoadError::Io {
        path: path.to_path_buf(),
        source,
    };
    let file_size = std::fs::metadata(path).map_err(io)?.len();
    let mut file = BufReader::new(std::fs::File::open(path).map_err(io)?);
    let mut magic = [0u8; 2];
    let gzip = file.get_mut().read(&mut magic).map_err(io)? == 2 && magic == [0x1f, 0x8b];
    let file = BufReader::new(std::fs::File::open(path).map_err(io)?);
    let source: Box<dyn Read> = if gzip {
        Box::new(flate2::read::MultiGzDecoder::new(file))
    } else {
        Box::new(file)
    };
    // Deflate expands at most about 1032:1, which bounds what a gzip file can hold.
    let budget = if gzip {
        file_size.saturating_mul(1032)
    } else {
        file_size
    };
    parse_mesh(source, path, budget)
}

/// Parses PLY content from `source`, which holds at most `budget` bytes; `path` names it in
/// messages. Element counts the budget cannot hold are refused before anything is read.
pub fn parse_mesh(
    source: impl Read,
    path: &Path,
    budget: u64,
) -> Result<(Vec<Vec3>, Vec<[u32; 3]>), LoadError> {
    // The PLY parser's messages span several lines; the first says what is wrong.
    let invalid = |what: String| LoadError::Invalid {
        path: path.to_path_buf(),
        what: what
            .lines()
            .next()
            .unwrap_or_default()
            .trim_end()
            .to_string(),
    };
    let mut reader = ply_rs_bw::parser::Reader::new(BufReader::new(source));

    let vertex_parser = Parser::<PlyVertex>::new();
    let face_parser = Parser::<PlyFace>::new();
    let header = vertex_parser
        .read_header(&mut reader)
        .map_err(|e| invalid(format!("bad PLY header: {e}")))?;
    check_declared_sizes(&header, budget).map_err(invalid)?;
    check_memory(
        || "the mesh its header declares".into(),
        header
            .elements
            .values()
            .map(|e| bytes_in_memory(&e.name, e.count as u64))
            .fold(0, u64::saturating_add),
    )
    .map_err(|e| invalid(e.to_string()))?;
    let mut positions = Vec::new();
    let mut faces = Vec::new();
    for element in header.elements.values() {
        match element.name.as_str() {
            "vertex" => {
                positions = vertex_parser
                    .read_payload_for_element(&mut reader, element, &header)
                    .map_err(|e| invalid(format!("bad vertex data: {e}")))?
                    .into_iter()
                    .map(|v| v.0)
                    .collect();
            }
            "face" => {
                faces = face_parser
                    .read_payload_for_element(&mut reader, element, &header)
                    .map_err(|e| invalid(format!("bad face data: {e}")))?;
            }
            _ => {
                // Skip other elements (edges, materials, ...) by reading them as faces.
                face_parser
                    .read_payload_for_element(&mut reader, element, &header)
                    .map_err(|e| invalid(format!("bad '{}' data: {e}", element.name)))?;
            }
        }
    }
    let n = positions.len() as i64;
    let mut triangles = Vec::with_capacity(faces.len());
    for (i, face) in faces.iter().enumerate() {
        if let Some(bad) = face.0.iter().find(|&&v| v < 0 || v >= n) {
            return Err(invalid(format!(
                "face {i} uses vertex {bad}, but there are {n} vertices"
            )));
        }
        for k in 1..face.0.len().saturating_sub(1) {
            triangles.push([face.0[0] as u32, face.0[k] as u32, face.0[k + 1] as u32]);
        }
    }
    Ok((positions, triangles))
}

/// Memory `count` parsed elements named `name` take at least: a vertex its position, any
/// other element (read as a polygon) its list of at least three 64-bit corners, and the
/// triangles it becomes.
fn bytes_in_memory(name: &str, count: u64) -> u64 {
    let per_element = match name {
        "vertex" => std::mem::size_of::<PlyVertex>() + std::mem::size_of::<Vec3>(),
        _ => std::mem::size_of::<PlyFace>() + 3 * 8 + std::mem::size_of::<[u32; 3]>(),
    };
    count.saturating_mul(per_element as u64)
}

/// Refuses headers whose elements cannot fit in `budget` bytes: each element needs at least
/// its scalar properties and list counts in binary, or a character and a separator per
/// property in ASCII. A binary element without properties takes no bytes at all, so any
/// count of it would be created from nothing (found by fuzzing: 777,777,721 of them).
fn check_declared_sizes(header: &ply_rs_bw::ply::Header, budget: u64) -> Result<(), String> {
    use ply_rs_bw::ply::{Encoding, PropertyType, ScalarType};
    let size = |t: &ScalarType| match t {
        ScalarType::Char | ScalarType::UChar => 1u64,
        ScalarType::Short | ScalarType::UShort => 2,
        ScalarType::Int | ScalarType::UInt | ScalarType::Float => 4,
        ScalarType::Double => 8,
    };
    let mut needed = 0u64;
    for element in header.elements.values() {
        let properties = element.properties.values();
        let per_element = match header.encoding {
            Encoding::Ascii => 2 * element.properties.len() as u64,
            _ => properties
                .map(|p| match &p.data_type {
                    PropertyType::Scalar(t) => size(t),
                    PropertyType::List(count, _) => size(count),
                })
                .sum(),
        };
        if per_element == 0 && element.count > 0 && header.encoding != Encoding::Ascii {
            return Err(format!(
                "element '{}' declares {} items but no properties",
                element.name, element.count
            ));
        }
        needed = needed.saturating_add((element.count as u64).saturating_mul(per_element.max(1)));
    }
    if needed > budget {
        return Err(format!(
            "the header declares at least {needed} bytes of data, but the file can hold at most {budget}"
        ));
    }
    Ok(())
}

/// Loads a PLY file as a one-mesh scene.
pub fn load(path: &Path) -> Result<Loaded, LoadError> {
    let (positions, indices) = read_mesh(path)?;
    let mut builder = SceneBuilder::new();
    let material = builder.add_material(Material::default_grey("ply"));
    let normals = Mesh::compute_vertex_normals(&positions, &indices);
    let name = path
        .file_name()
        .map_or_else(String::new, |n| n.to_string_lossy().into_owned());
    let mesh = builder.add_full_mesh(Mesh {
        name: name.clone(),
        positions,
        normals,
        indices,
        material,
        ..Mesh::default()
    });
    builder.add_instance(mesh, glam::Affine3A::IDENTITY, name);
    Ok(Loaded {
        scene: builder.build(),
        warnings: Vec::new(),
        files: Vec::new(),
        frame: None,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::io::Write;

    const ASCII: &str = "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\n\
        property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n\
        0 0 0\n1 0 0\n1 1 0\n0 1 0\n4 0 1 2 3\n";

    #[test]
    fn reads_ascii_plain_and_gzipped_and_splits_quads() {
        let dir = tempfile::tempdir().unwrap();
        let plain = dir.path().join("q.ply");
        std::fs::write(&plain, ASCII).unwrap();
        let gz = dir.path().join("q.ply.gz");
        let mut enc = flate2::write::GzEncoder::new(
            std::fs::File::create(&gz).unwrap(),
            flate2::Compression::fast(),
        );
        enc.write_all(ASCII.as_bytes()).unwrap();
        enc.finish().unwrap();
        for path in [plain, gz] {
            let (p, t) = read_mesh(&path).unwrap();
            assert_eq!(p.len(), 4);
            assert_eq!(t, vec![[0, 1, 2], [0, 2, 3]]);
        }
    }

    #[test]
    fn reads_binary_little_endian_with_double_positions_and_extra_properties() {
        let mut bytes =
            b"ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty double x\n\
            property double y\nproperty double z\nproperty uchar red\nelement face 1\n\
            property list uchar uint vertex_indices\nend_header\n"
                .to_vec();
        for (x, y) in [(0.0f64, 0.0f64), (2.0, 0.0), (0.0, 2.0)] {
            for c in [x, y, 0.5] {
                bytes.extend_from_slice(&c.to_le_bytes());
            }
            bytes.push(7);
        }
        bytes.push(3);
        for i in [0u32, 1, 2] {
            bytes.extend_from_slice(&i.to_le_bytes());
        }
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("b.ply");
        std::fs::write(&path, bytes).unwrap();
        let (p, t) = read_mesh(&path).unwrap();
        assert_eq!(p[1], Vec3::new(2.0, 0.0, 0.5));
        assert_eq!(t, vec![[0, 1, 2]]);
    }

    #[test]
    fn rejects_out_of_range_indices_and_garbage_naming_the_file() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("bad.ply");
        std::fs::write(&path, ASCII.replace("4 0 1 2 3", "3 0 1 9")).unwrap();
        let err = read_mesh(&path).unwrap_err().to_string();
        assert!(err.contains("bad.ply") && err.contains("vertex 9"), "{err}");
        std::fs::write(&path, "not a ply file").unwrap();
        let err = read_mesh(&path).unwrap_err().to_string();
        assert!(err.contains("bad.ply") && err.contains("header"), "{err}");
    }
}
