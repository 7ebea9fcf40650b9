//! glTF extensions and storage forms read by hand-built files whose answers are known:
//! quantised attributes (`KHR_mesh_quantization`), sparse accessors without a bufferView,
//! `EXT_mesh_gpu_instancing`, `KHR_materials_unlit`,
//! `KHR_materials_pbrSpecularGlossiness`, `KHR_materials_variants`,
//! `KHR_materials_anisotropy`, and which sheen `KHR_materials_sheen` means.

#[path = "support/binary/mod.rs"]
mod binary;
#[path = "support/common/mod.rs"]
mod common;
#[path = "support/image_stats/mod.rs"]
mod image_stats;

use std::path::{Path, PathBuf};

use glam::{Quat, Vec3};
use gridtrace::load::{LoadOptions, load_scene, load_scene_with};
use gridtrace::scene::{AnisotropyModel, SheenModel};
use serde_json::{Value, json};

/// Writes `document` with `buffer` as its only buffer, in a base64 data URI, and checks it
/// with Khronos' glTF-Validator (`tools/dev/npm`, installed by `tools/dev/setup.sh`).
fn write(dir: &Path, name: &str, buffer: &[u8], document: Value) -> PathBuf {
    let path = write_unchecked(dir, name, buffer, document);
    common::validate_gltf(&path);
    path
}

/// [`write`] without the validator, for a file that breaks the specification on purpose.
fn write_unchecked(dir: &Path, name: &str, buffer: &[u8], mut document: Value) -> PathBuf {
    let generator = document["asset"]["generator"].take();
    document["asset"] = json!({"version": "2.0"});
    if generator.is_string() {
        document["asset"]["generator"] = generator;
    }
    document["buffers"] = json!([{
        "uri": format!("data:application/octet-stream;base64,{}", base64::encode(buffer)),
        "byteLength": buffer.len()
    }]);
    let path = dir.join(name);
    std::fs::write(&path, serde_json::to_vec_pretty(&document).unwrap()).unwrap();
    path
}

fn i16s(values: &[i16]) -> Vec<u8> {
    values.iter().flat_map(|v| v.to_le_bytes()).collect()
}

fn f32s(values: &[f32]) -> Vec<u8> {
    values.iter().flat_map(|v| v.to_le_bytes()).collect()
}

#[test]
fn quantised_attributes_and_sparse_accessors_without_a_view_are_read() {
    // Positions: i16, not normalised, 8-byte stride (6 bytes + 2 of padding), scaled by the
    // node; normals: normalised i8 with a 4-byte stride; u16 indices.
    let mut buffer = i16s(&[
        -100, -100, 0, 0, 100, -100, 0, 0, 100, 100, 0, 0, -100, 100, 0, 0,
    ]);
    buffer.extend([0u8, 0, 127, 0].repeat(4));
    buffer.extend(i16s(&[0, 1, 2, 0, 2, 3]));
    // A sparse accessor over zeros: vertices 1 to 3 become a square's corners.
    buffer.extend([1, 2, 3, 0]);
    buffer.extend(f32s(&[5.0, 0.0, 0.0, 5.0, 5.0, 0.0, 0.0, 5.0, 0.0]));
    let document = json!({
        "extensionsUsed": ["KHR_mesh_quantization"],
        "extensionsRequired": ["KHR_mesh_quantization"],
        "bufferViews": [
            {"buffer": 0, "byteOffset": 0, "byteLength": 32, "byteStride": 8},
            {"buffer": 0, "byteOffset": 32, "byteLength": 16, "byteStride": 4},
            {"buffer": 0, "byteOffset": 48, "byteLength": 12},
            {"buffer": 0, "byteOffset": 60, "byteLength": 3},
            {"buffer": 0, "byteOffset": 64, "byteLength": 36}
        ],
        "accessors": [
            {"bufferView": 0, "componentType": 5122, "count": 4, "type": "VEC3",
             "min": [-100, -100, 0], "max": [100, 100, 0]},
            {"bufferView": 1, "componentType": 5120, "normalized": true, "count": 4, "type": "VEC3"},
            {"bufferView": 2, "componentType": 5123, "count": 6, "type": "SCALAR"},
            {"componentType": 5126, "count": 4, "type": "VEC3", "min": [0, 0, 0], "max": [5, 5, 0],
             "sparse": {"count": 3,
                        "indices": {"bufferView": 3, "componentType": 5121},
                        "values": {"bufferView": 4}}}
        ],
        "meshes": [
            {"primitives": [{"attributes": {"POSITION": 0, "NORMAL": 1}, "indices": 2}]},
            {"primitives": [{"attributes": {"POSITION": 3}, "indices": 2}]}
        ],
        "nodes": [{"mesh": 0, "scale": [0.01, 0.01, 0.01]}, {"mesh": 1}],
        "scenes": [{"nodes": [0, 1]}]
    });
    let dir = tempfile::tempdir().unwrap();
    let loaded = load_scene(&write(dir.path(), "q.gltf", &buffer, document)).unwrap();
    assert!(loaded.warnings.is_empty(), "{:?}", loaded.warnings);
    let scene = loaded.scene;
    let quantised = &scene.meshes[scene.instances[0].mesh];
    assert_eq!(quantised.positions[2], Vec3::new(100.0, 100.0, 0.0));
    assert!(quantised.normals.iter().all(|&n| n == Vec3::Z));
    let corner = scene.instances[0]
        .world_from_object
        .transform_point3(quantised.positions[0]);
    assert!(
        (corner - Vec3::new(-1.0, -1.0, 0.0)).length() < 1e-6,
        "{corner}"
    );
    let sparse = &scene.meshes[scene.instances[1].mesh];
    assert_eq!(
        sparse.positions,
        [
            Vec3::ZERO,
            Vec3::new(5.0, 0.0, 0.0),
            Vec3::new(5.0, 5.0, 0.0),
            Vec3::new(0.0, 5.0, 0.0)
        ]
    );
}

#[test]
fn gpu_instancing_places_every_copy() {
    let mut buffer = f32s(&[-1.0, -1.0, 0.0, 1.0, -1.0, 0.0, 0.0, 1.0, 0.0]);
    buffer.extend(i16s(&[0, 1, 2, 0]));
    // Three instances: translations, and rotations as normalised i16 quaternions.
    buffer.extend(f32s(&[0.0, 0.0, 0.0, 5.0, 0.0, 0.0, 0.0, 7.0, 0.0]));
    let s = (std::f32::consts::FRAC_1_SQRT_2 * 32767.0).round() as i16;
    buffer.extend(i16s(&[0, 0, 0, 32767, 0, s, 0, s, 32767, 0, 0, 0]));
    let document = json!({
        "extensionsUsed": ["EXT_mesh_gpu_instancing"],
        "bufferViews": [
            {"buffer": 0, "byteOffset": 0, "byteLength": 36},
            {"buffer": 0, "byteOffset": 36, "byteLength": 6},
            {"buffer": 0, "byteOffset": 44, "byteLength": 36},
            {"buffer": 0, "byteOffset": 80, "byteLength": 24}
        ],
        "accessors": [
            {"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3",
             "min": [-1, -1, 0], "max": [1, 1, 0]},
            {"bufferView": 1, "componentType": 5123, "count": 3, "type": "SCALAR"},
            {"bufferView": 2, "componentType": 5126, "count": 3, "type": "VEC3"},
            {"bufferView": 3, "componentType": 5122, "normalized": true, "count": 3, "type": "VEC4"}
        ],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "indices": 1}]}],
        "nodes": [{"mesh": 0, "translation": [0, 0, -2],
                   "extensions": {"EXT_mesh_gpu_instancing":
                       {"attributes": {"TRANSLATION": 2, "ROTATION": 3}}}}],
        "scenes": [{"nodes": [0]}]
    });
    let dir = tempfile::tempdir().unwrap();
    let loaded = load_scene(&write(dir.path(), "i.gltf", &buffer, document)).unwrap();
    assert!(loaded.warnings.is_empty(), "{:?}", loaded.warnings);
    let instances = &loaded.scene.instances;
    assert_eq!(instances.len(), 3);
    let expected = [
        (Vec3::new(0.0, 0.0, -2.0), Quat::IDENTITY),
        (
            Vec3::new(5.0, 0.0, -2.0),
            Quat::from_rotation_y(std::f32::consts::FRAC_PI_2),
        ),
        (
            Vec3::new(0.0, 7.0, -2.0),
            Quat::from_rotation_x(std::f32::consts::PI),
        ),
    ];
    for (instance, (translation, rotation)) in instances.iter().zip(expected) {
        let (_, r, t) = instance.world_from_object.to_scale_rotation_translation();
        assert!((t - translation).length() < 1e-5, "{t}");
        assert!(r.angle_between(rotation) < 1e-3, "{r} vs {rotation}");
    }
}

/// A quad filling the view of a camera 3 units in front of it, with `material`.
fn quad_facing_camera(material: Value, extension: &str) -> (Vec<u8>, Value) {
    let mut buffer = f32s(&[
        -1.0, -1.0, 0.0, 1.0, -1.0, 0.0, 1.0, 1.0, 0.0, -1.0, 1.0, 0.0,
    ]);
    buffer.extend(i16s(&[0, 1, 2, 0, 2, 3]));
    let document = json!({
        "extensionsUsed": [extension],
        "bufferViews": [
            {"buffer": 0, "byteOffset": 0, "byteLength": 48},
            {"buffer": 0, "byteOffset": 48, "byteLength": 12}
        ],
        "accessors": [
            {"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3",
             "min": [-1, -1, 0], "max": [1, 1, 0]},
            {"bufferView": 1, "componentType": 5123, "count": 6, "type": "SCALAR"}
        ],
        "materials": [material],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "indices": 1, "material": 0}]}],
        "cameras": [{"type": "perspective", "perspective": {"yfov": 0.4, "aspectRatio": 1.0, "znear": 0.1}}],
        "nodes": [{"mesh": 0}, {"camera": 0, "translation": [0, 0, 3]}],
        "scenes": [{"nodes": [0, 1]}]
    });
    (buffer, document)
}

#[test]
fn an_unlit_surface_shows_its_base_colour_whatever_the_light() {
    let colour = [0.2, 0.5, 0.8];
    let (buffer, document) = quad_facing_camera(
        json!({"pbrMetallicRoughness": {"baseColorFactor": [0.2, 0.5, 0.8, 1.0]},
               "extensions": {"KHR_materials_unlit": {}}}),
        "KHR_materials_unlit",
    );
    let dir = tempfile::tempdir().unwrap();
    let path = write(dir.path(), "u.gltf", &buffer, document);
    for light in ["none", "4,4,4"] {
        let out = dir.path().join(format!("u-{light}.exr"));
        let result = binary::gridtrace(
            &[
                path.to_str().unwrap(),
                "-o",
                out.to_str().unwrap(),
                "--spp",
                "1",
                "--width",
                "128",
                "--height",
                "128",
                "--environment",
                light,
                "-q",
            ],
            dir.path(),
        );
        assert!(result.status.success(), "{}", binary::stderr(&result));
        for pixel in image_stats::read_exr(&out) {
            let error = (pixel - glam::DVec3::from(colour)).abs().max_element();
            assert!(error < 1e-6, "{light}: {pixel} instead of {colour:?}");
        }
    }
}

#[test]
fn specular_glossiness_becomes_metallic_roughness() {
    let (buffer, document) = quad_facing_camera(
        json!({"extensions": {"KHR_materials_pbrSpecularGlossiness": {
            "diffuseFactor": [0.0, 0.0, 0.0, 1.0],
            "specularFactor": [1.0, 0.77, 0.34],
            "glossinessFactor": 0.8}}}),
        "KHR_materials_pbrSpecularGlossiness",
    );
    let dir = tempfile::tempdir().unwrap();
    let loaded = load_scene(&write(dir.path(), "sg.gltf", &buffer, document)).unwrap();
    assert!(loaded.warnings.is_empty(), "{:?}", loaded.warnings);
    let pbr = loaded.scene.materials[0].pbr;
    assert!(pbr.metallic > 0.99, "{pbr:?}");
    assert!(
        (pbr.base_colour - Vec3::new(1.0, 0.77, 0.34))
            .abs()
            .max_element()
            < 0.02
    );
    assert!((pbr.roughness - 0.2).abs() < 1e-6);
}

/// A 2×1 PNG (RGBA, 8-bit) as a data URI.
fn png_uri(texels: [[u8; 4]; 2]) -> String {
    let image = image::RgbaImage::from_fn(2, 1, |x, _| image::Rgba(texels[x as usize]));
    let mut bytes = Vec::new();
    image
        .write_to(
            &mut std::io::Cursor::new(&mut bytes),
            image::ImageFormat::Png,
        )
        .unwrap();
    format!("data:image/png;base64,{}", base64::encode(bytes))
}

#[test]
fn specular_glossiness_textures_are_baked_texel_by_texel() {
    // Texel 0: black diffuse under a gold specular, glossy: a polished metal. Texel 1: an
    // orange diffuse under a dark specular (F0 ≈ 0.003), half glossy: a dielectric.
    let diffuse = png_uri([[0, 0, 0, 255], [200, 100, 50, 128]]);
    let spec_gloss = png_uri([[255, 196, 87, 255], [10, 10, 10, 128]]);
    let (buffer, mut document) = quad_facing_camera(
        json!({"extensions": {"KHR_materials_pbrSpecularGlossiness": {
            "diffuseTexture": {"index": 0},
            "specularGlossinessTexture": {"index": 1}}}}),
        "KHR_materials_pbrSpecularGlossiness",
    );
    document["images"] = json!([{"uri": diffuse}, {"uri": spec_gloss}]);
    document["textures"] = json!([{"source": 0}, {"source": 1}]);
    document["meshes"][0]["primitives"][0]["attributes"]["TEXCOORD_0"] = json!(2);
    let uv_offset = buffer.len();
    let mut buffer = buffer;
    buffer.extend(f32s(&[0.0, 1.0, 1.0, 1.0, 1.0, 0.0, 0.0, 0.0]));
    document["bufferViews"]
        .as_array_mut()
        .unwrap()
        .push(json!({"buffer": 0, "byteOffset": uv_offset, "byteLength": 32}));
    document["accessors"]
        .as_array_mut()
        .unwrap()
        .push(json!({"bufferView": 2, "componentType": 5126, "count": 4, "type": "VEC2"}));
    let dir = tempfile::tempdir().unwrap();
    let loaded = load_scene(&write(dir.path(), "sgt.gltf", &buffer, document)).unwrap();
    assert!(loaded.warnings.is_empty(), "{:?}", loaded.warnings);
    let scene = loaded.scene;
    let material = &scene.materials[0];
    let base = &scene.textures[material.textures.base_colour.unwrap().texture];
    let metal_rough = &scene.textures[material.textures.metallic.unwrap().texture.texture];
    let unit = |c: u16| f32::from(c) / 65535.0;
    // Texel 0: metal, smooth, base colour the specular colour.
    assert!(
        unit(metal_rough.texels[0][2]) > 0.99,
        "{:?}",
        metal_rough.texels[0]
    );
    assert!(unit(metal_rough.texels[0][1]) < 1e-4);
    for c in 0..3 {
        let expected = [255u16, 196, 87][c] * 257;
        assert!(
            base.texels[0][c].abs_diff(expected) <= 3 * 257,
            "{:?}",
            base.texels[0]
        );
    }
    // Texel 1: no metal, roughness 0.5, the diffuse colour brightened by 1/(1 − 0.04) and
    // dimmed by 1 − F0, alpha kept.
    assert_eq!(metal_rough.texels[1][2], 0);
    assert!((unit(metal_rough.texels[1][1]) - (1.0 - 128.0 / 255.0)).abs() < 1e-3);
    let f0 = gridtrace::scene::srgb_to_linear(10.0 / 255.0);
    for c in 0..3 {
        let ours = gridtrace::scene::srgb_to_linear(unit(base.texels[1][c]));
        let diffuse = gridtrace::scene::srgb_to_linear([200.0f32, 100.0, 50.0][c] / 255.0);
        let expected = diffuse * (1.0 - f0) / 0.96;
        assert!(
            (ours / expected - 1.0).abs() < 0.01,
            "channel {c}: {ours} vs {expected}"
        );
    }
    assert_eq!(base.texels[1][3], 128 * 257);
}

/// A morphed node reached through two parents (which the specification forbids, and a
/// hostile file may do a million times) is posed once and drawn twice.
#[test]
fn a_posed_node_reached_twice_is_posed_once() {
    let (mut buffer, mut document) = quad_facing_camera(json!({}), "KHR_materials_unlit");
    let offset = buffer.len();
    buffer.extend(f32s(&[0.0, 0.0, 1.0].repeat(4)));
    document["bufferViews"]
        .as_array_mut()
        .unwrap()
        .push(json!({"buffer": 0, "byteOffset": offset, "byteLength": 48}));
    document["accessors"].as_array_mut().unwrap().push(
        json!({"bufferView": 2, "componentType": 5126, "count": 4, "type": "VEC3",
               "min": [0, 0, 1], "max": [0, 0, 1]}),
    );
    document["meshes"][0]["primitives"][0]["targets"] = json!([{"POSITION": 2}]);
    document["meshes"][0]["weights"] = json!([0.5]);
    document["nodes"] = json!([
        {"children": [2], "translation": [-3, 0, 0]},
        {"children": [2], "translation": [3, 0, 0]},
        {"mesh": 0}
    ]);
    document["scenes"] = json!([{"nodes": [0, 1]}]);
    let dir = tempfile::tempdir().unwrap();
    let path = write_unchecked(dir.path(), "shared.gltf", &buffer, document);
    let scene = load_scene(&path).unwrap().scene;
    assert_eq!(scene.instances.len(), 2);
    assert_eq!(scene.meshes.len(), 1);
    assert!(scene.meshes[0].positions.iter().all(|p| p.z == 0.5));
}

/// `KHR_materials_variants` in a file written by pygltflib (tools/dev/make_third_party.py):
/// two squares, red by default; variant "Blue" maps both to blue, "Green" only the left one
/// (the right keeps its own red). Variants are picked by name or index; an unknown one is an
/// error listing the file's.
#[test]
fn material_variants_choose_each_primitives_material() {
    let path = Path::new("tests/data/scenes/third_party/pygltflib_variants.gltf");
    let colours = |variant: Option<&str>| -> Vec<Vec3> {
        let options = LoadOptions {
            material_variant: variant.map(String::from),
            ..LoadOptions::default()
        };
        let loaded = load_scene_with(path, &options).unwrap();
        assert!(loaded.warnings.is_empty(), "{:?}", loaded.warnings);
        let scene = loaded.scene;
        let mut meshes: Vec<_> = scene.meshes.iter().collect();
        meshes.sort_by(|a, b| a.positions[0].x.total_cmp(&b.positions[0].x));
        meshes
            .iter()
            .map(|m| scene.materials[m.material].pbr.base_colour)
            .collect()
    };
    let (red, blue, green) = (
        Vec3::new(0.8, 0.1, 0.1),
        Vec3::new(0.1, 0.1, 0.8),
        Vec3::new(0.1, 0.8, 0.1),
    );
    assert_eq!(colours(None), [red, red]);
    assert_eq!(colours(Some("Blue")), [blue, blue]);
    assert_eq!(colours(Some("Green")), [green, red]);
    assert_eq!(colours(Some("1")), [green, red]);
    let options = LoadOptions {
        material_variant: Some("Gold".into()),
        ..LoadOptions::default()
    };
    let error = load_scene_with(path, &options).unwrap_err().to_string();
    assert!(
        error.contains("pygltflib_variants.gltf") && error.contains("0 'Blue', 1 'Green'"),
        "{error}"
    );
}

/// `KHR_materials_anisotropy` follows the writer: a file Blender's exporter wrote (its
/// `asset.generator`) means Blender's Anisotropic, stretched as Cycles stretches it; any
/// other file means the extension's own model. Strength, rotation and texture are read, and
/// tangents are made for the anisotropic surface.
#[test]
fn anisotropy_is_read_and_its_model_follows_the_writer() {
    let material = json!({
        "pbrMetallicRoughness": {"metallicFactor": 1.0, "roughnessFactor": 0.3},
        "extensions": {"KHR_materials_anisotropy": {
            "anisotropyStrength": 0.7, "anisotropyRotation": 0.5
        }}
    });
    let dir = tempfile::tempdir().unwrap();
    for (generator, model) in [
        ("Khronos glTF Blender I/O v5.0.21", AnisotropyModel::Cycles),
        ("glTF-Transform v4.1.0", AnisotropyModel::Gltf),
    ] {
        let (buffer, mut document) =
            quad_facing_camera(material.clone(), "KHR_materials_anisotropy");
        let mut primitive = document["meshes"][0]["primitives"][0].take();
        primitive["attributes"]["NORMAL"] = json!(2);
        primitive["attributes"]["TEXCOORD_0"] = json!(3);
        document["meshes"][0]["primitives"][0] = primitive;
        let mut buffer = buffer;
        let normals_at = buffer.len();
        buffer.extend(f32s(&[0.0, 0.0, 1.0].repeat(4)));
        let uvs_at = buffer.len();
        buffer.extend(f32s(&[0.0, 1.0, 1.0, 1.0, 1.0, 0.0, 0.0, 0.0]));
        let views = document["bufferViews"].as_array_mut().unwrap();
        views.push(json!({"buffer": 0, "byteOffset": normals_at, "byteLength": 48}));
        views.push(json!({"buffer": 0, "byteOffset": uvs_at, "byteLength": 32}));
        let accessors = document["accessors"].as_array_mut().unwrap();
        accessors.push(json!({"bufferView": 2, "componentType": 5126, "count": 4, "type": "VEC3"}));
        accessors.push(json!({"bufferView": 3, "componentType": 5126, "count": 4, "type": "VEC2"}));
        document["asset"] = json!({"generator": generator});
        let path = write(dir.path(), "a.gltf", &buffer, document);
        let loaded = load_scene(&path).unwrap();
        assert!(loaded.warnings.is_empty(), "{:?}", loaded.warnings);
        let scene = loaded.scene;
        let m = &scene.materials[scene.meshes[0].material];
        assert_eq!(m.pbr.anisotropy.model, model, "{generator}");
        assert!((m.pbr.anisotropy.strength - 0.7).abs() < 1e-6);
        assert!((m.pbr.anisotropy.rotation - 0.5).abs() < 1e-6);
        let mesh = &scene.meshes[0];
        assert!(
            !mesh.tangents.is_empty() && mesh.tangents.len() == mesh.positions.len(),
            "tangents for the anisotropic surface"
        );
    }
}

/// `KHR_materials_sheen` follows the writer too: Blender's exporter writes the Principled
/// BSDF's sheen, which is Cycles' microfibre layer; any other file means the extension's
/// Charlie sheen.
#[test]
fn sheen_model_follows_the_writer() {
    let material = json!({
        "pbrMetallicRoughness": {"baseColorFactor": [0.3, 0.02, 0.05, 1.0], "metallicFactor": 0.0},
        "extensions": {"KHR_materials_sheen": {
            "sheenColorFactor": [1.0, 0.9, 0.8], "sheenRoughnessFactor": 0.5
        }}
    });
    let dir = tempfile::tempdir().unwrap();
    for (generator, model) in [
        ("Khronos glTF Blender I/O v5.0.21", SheenModel::Microfiber),
        ("glTF-Transform v4.1.0", SheenModel::Charlie),
    ] {
        let (buffer, mut document) = quad_facing_camera(material.clone(), "KHR_materials_sheen");
        document["asset"] = json!({"generator": generator});
        let path = write(dir.path(), "s.gltf", &buffer, document);
        let loaded = load_scene(&path).unwrap();
        assert!(loaded.warnings.is_empty(), "{:?}", loaded.warnings);
        let pbr = loaded.scene.materials[loaded.scene.meshes[0].material].pbr;
        assert_eq!(pbr.sheen_model, model, "{generator}");
        assert_eq!(pbr.sheen_colour, Vec3::new(1.0, 0.9, 0.8));
        assert!((pbr.sheen_roughness - 0.5).abs() < 1e-6);
    }
}
