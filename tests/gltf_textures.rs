//! Textures, vertex colours, tangents, alpha and volume as the glTF loader reads them, and as
//! the renderer shades them.

#[path = "support/common/mod.rs"]
mod common;

use common::{quad_document, write_gltf, write_unchecked_gltf};
use glam::{Vec2, Vec3};
use gridtrace::load::load_scene;
use gridtrace::scene::{AlphaMode, ColorSpace, Filter, Wrap};
use serde_json::json;

/// A 2×2 RGBA PNG: red, green / blue, half-transparent white (rows top to bottom).
fn png() -> Vec<u8> {
    let pixels: Vec<u8> = vec![
        255, 0, 0, 255, 0, 255, 0, 255, //
        0, 0, 255, 255, 255, 255, 255, 128,
    ];
    let mut bytes = std::io::Cursor::new(Vec::new());
    image::RgbaImage::from_raw(2, 2, pixels)
        .unwrap()
        .write_to(&mut bytes, image::ImageFormat::Png)
        .unwrap();
    bytes.into_inner()
}

/// The quad with UVs (accessor 2, in a second buffer) and the given images and materials.
fn textured_document(images: serde_json::Value, materials: serde_json::Value) -> serde_json::Value {
    let mut doc = quad_document();
    doc["images"] = images;
    doc["samplers"] = json!([
        {"magFilter": 9728, "wrapS": 33071, "wrapT": 33648},
        {}
    ]);
    doc["textures"] = json!([{"source": 0, "sampler": 0}, {"source": 0, "sampler": 1}]);
    doc["materials"] = materials;
    doc["buffers"]
        .as_array_mut()
        .unwrap()
        .push(json!({"uri": "uv.bin", "byteLength": 32}));
    doc["bufferViews"]
        .as_array_mut()
        .unwrap()
        .push(json!({"buffer": 1, "byteOffset": 0, "byteLength": 32}));
    doc["accessors"]
        .as_array_mut()
        .unwrap()
        .push(json!({"bufferView": 2, "componentType": 5126, "count": 4, "type": "VEC2"}));
    doc["meshes"][0]["primitives"][0]["attributes"]["TEXCOORD_0"] = json!(2);
    doc
}

fn write_uvs(dir: &std::path::Path) {
    let uvs: [f32; 8] = [0.0, 1.0, 1.0, 1.0, 1.0, 0.0, 0.0, 0.0];
    let bytes: Vec<u8> = uvs.iter().flat_map(|f| f.to_le_bytes()).collect();
    std::fs::write(dir.join("uv.bin"), bytes).unwrap();
}

#[test]
fn images_load_from_files_and_data_uris_once_each() {
    let dir = tempfile::tempdir().unwrap();
    write_uvs(dir.path());
    std::fs::write(dir.path().join("tex ture.png"), png()).unwrap();
    let data_uri = format!("data:image/png;base64,{}", base64::encode(png()));
    for uri in ["tex%20ture.png", data_uri.as_str()] {
        let doc = textured_document(
            json!([{"uri": uri}]),
            json!([
                {"name": "a", "pbrMetallicRoughness": {"metallicFactor": 0.0, "baseColorTexture": {"index": 0}}},
                {"name": "b", "emissiveFactor": [1.0, 1.0, 1.0], "emissiveTexture": {"index": 1},
                 "pbrMetallicRoughness": {"metallicFactor": 0.0}}
            ]),
        );
        let loaded = load_scene(&write_gltf(dir.path(), "t.gltf", &doc)).unwrap();
        assert!(loaded.warnings.is_empty(), "{:?}", loaded.warnings);
        let scene = &loaded.scene;
        assert_eq!(scene.textures.len(), 1, "one image, decoded once");
        let texture = &scene.textures[0];
        assert_eq!((texture.width, texture.height), (2, 2));
        let a = scene.materials[0].textures.base_colour.unwrap();
        // Sampler 0: nearest, clamp in u, mirrored repeat in v.
        assert_eq!(
            (a.filter, a.wrap_u, a.wrap_v),
            (Filter::Nearest, Wrap::ClampToEdge, Wrap::MirroredRepeat)
        );
        let b = scene.materials[1].textures.emissive.unwrap();
        assert_eq!(
            (b.filter, b.wrap_u, b.wrap_v),
            (Filter::Linear, Wrap::Repeat, Wrap::Repeat)
        );
        // Top-left texel red, bottom-right white at alpha 128/255.
        let red = texture.sample(&a, Vec2::new(0.25, 0.25), ColorSpace::Srgb);
        assert_eq!(red.truncate(), Vec3::X);
        let white = texture.sample(&a, Vec2::new(0.75, 0.75), ColorSpace::Linear);
        assert!((white.w - 128.0 / 255.0).abs() < 1e-4, "{white}");
        // Clamped in u: far right is still the right column.
        let clamped = texture.sample(&a, Vec2::new(7.0, 0.25), ColorSpace::Srgb);
        assert_eq!(clamped.truncate(), Vec3::Y);
    }
}

#[test]
fn a_missing_or_broken_image_warns_and_the_material_keeps_its_factors() {
    let dir = tempfile::tempdir().unwrap();
    write_uvs(dir.path());
    std::fs::write(dir.path().join("broken.png"), b"not a png").unwrap();
    for (uri, expect) in [
        ("absent.png", "not found"),
        ("broken.png", "cannot be decoded"),
    ] {
        let doc = textured_document(
            json!([{"uri": uri}]),
            json!([{"name": "a", "pbrMetallicRoughness": {"metallicFactor": 0.0,
                    "baseColorFactor": [0.5, 0.5, 0.5, 1.0], "baseColorTexture": {"index": 0}}}]),
        );
        let loaded = load_scene(&write_unchecked_gltf(dir.path(), "t.gltf", &doc)).unwrap();
        assert_eq!(loaded.warnings.len(), 1, "{:?}", loaded.warnings);
        assert!(
            loaded.warnings[0].contains(expect) && loaded.warnings[0].contains("t.gltf"),
            "{:?}",
            loaded.warnings
        );
        let m = &loaded.scene.materials[0];
        assert!(m.textures.base_colour.is_none());
        assert_eq!(m.pbr.base_colour, Vec3::splat(0.5));
    }
}

#[test]
fn texture_transform_texcoord_alpha_volume_and_colours_are_read() {
    let dir = tempfile::tempdir().unwrap();
    write_uvs(dir.path());
    std::fs::write(dir.path().join("t.png"), png()).unwrap();
    let mut doc = textured_document(
        json!([{"uri": "t.png"}]),
        json!([{
            "name": "leaf",
            "alphaMode": "MASK", "alphaCutoff": 0.3,
            "pbrMetallicRoughness": {"metallicFactor": 0.0, "baseColorFactor": [1.0, 1.0, 1.0, 0.8],
                "baseColorTexture": {"index": 0, "texCoord": 0, "extensions": {"KHR_texture_transform":
                    {"offset": [0.5, 0.0], "rotation": 0.0, "scale": [2.0, 2.0]}}}},
            "normalTexture": {"index": 1, "scale": 0.5,
                "extensions": {"KHR_texture_transform": {"offset": [0.25, 0.0]}}},
            "extensions": {"KHR_materials_transmission": {"transmissionFactor": 1.0},
                           "KHR_materials_volume": {"attenuationColor": [0.5, 0.25, 1.0], "attenuationDistance": 2.0}}
        }]),
    );
    doc["extensionsUsed"] = json!([
        "KHR_texture_transform",
        "KHR_materials_transmission",
        "KHR_materials_volume"
    ]);
    doc["extensionsRequired"] = json!(["KHR_texture_transform"]);
    let loaded = load_scene(&write_gltf(dir.path(), "t.gltf", &doc)).unwrap();
    assert!(loaded.warnings.is_empty(), "{:?}", loaded.warnings);
    let scene = &loaded.scene;
    let m = &scene.materials[0];
    assert_eq!(m.alpha_mode, AlphaMode::Mask { cutoff: 0.3 });
    assert_eq!(m.alpha, 0.8);
    let r = m.textures.base_colour.unwrap();
    let moved = r.transform.transform_point2(Vec2::new(0.25, 0.25));
    assert!((moved - Vec2::new(1.0, 0.5)).length() < 1e-6, "{moved}");
    assert_eq!(m.textures.normal_scale, 0.5);
    let n = m.textures.normal.unwrap();
    assert_eq!(
        n.transform.transform_point2(Vec2::ZERO),
        Vec2::new(0.25, 0.0)
    );
    // σ = −ln(colour)/distance.
    let expected = Vec3::new(0.5f32.ln(), 0.25f32.ln(), 0.0) / -2.0;
    assert!(
        (m.absorption - expected).abs().max_element() < 1e-6,
        "{}",
        m.absorption
    );
    // The normal map made tangents (MikkTSpace) for the quad, split per corner.
    let mesh = &scene.meshes[0];
    assert_eq!(mesh.tangents.len(), mesh.positions.len());
    assert_eq!(mesh.positions.len(), 6);
    for t in &mesh.tangents {
        assert!((t.truncate() - Vec3::X).length() < 1e-4, "{t}");
    }
}

/// The extension's own example: offset (0, 1), rotation π/2, scale ½ shows the lower-left
/// quadrant of the image, turned: the unit square lands on [0, ½] × [½, 1].
#[test]
fn texture_transform_follows_the_extensions_example() {
    let t = gridtrace::load::gltf::texture_transform(
        Vec2::new(0.0, 1.0),
        std::f32::consts::FRAC_PI_2,
        Vec2::splat(0.5),
    );
    for (uv, expected) in [
        (Vec2::new(0.0, 0.0), Vec2::new(0.0, 1.0)),
        (Vec2::new(1.0, 0.0), Vec2::new(0.0, 0.5)),
        (Vec2::new(0.0, 1.0), Vec2::new(0.5, 1.0)),
        (Vec2::new(1.0, 1.0), Vec2::new(0.5, 0.5)),
    ] {
        let got = t.transform_point2(uv);
        assert!(
            (got - expected).length() < 1e-6,
            "{uv} -> {got}, expected {expected}"
        );
    }
}

/// Blender's export of a glass with a Volume Absorption node (colour (0.9, 0.5, 0.2),
/// density 2 → attenuationDistance 0.5) and of a rough metal.
#[test]
fn blender_volume_glass_and_rough_metal() {
    let loaded = load_scene(std::path::Path::new(
        "tests/data/scenes/material_details.glb",
    ))
    .unwrap();
    let materials = &loaded.scene.materials;
    let glass = materials.iter().find(|m| m.name == "TintedGlass").unwrap();
    assert!(glass.pbr.transmission == 1.0 && glass.pbr.ior == 1.5 && glass.pbr.roughness == 0.0);
    // Blender writes doubleSided: false with the volume; glass is two-sided regardless.
    assert!(glass.double_sided);
    let expected = Vec3::new(0.9f32.ln(), 0.5f32.ln(), 0.2f32.ln()) / -0.5;
    assert!(
        (glass.absorption - expected).abs().max_element() < 1e-5,
        "{}",
        glass.absorption
    );
    let metal = materials.iter().find(|m| m.name == "RoughMetal").unwrap();
    assert!(metal.pbr.metallic == 1.0 && (metal.pbr.roughness - 0.4).abs() < 1e-6);
    assert!(loaded.warnings.is_empty(), "{:?}", loaded.warnings);
}

/// `COLOR_0` is read and switches the material's vertex colours on; `TEXCOORD_1` is kept as
/// the second set.
#[test]
fn vertex_colours_and_a_second_uv_set_are_read() {
    let dir = tempfile::tempdir().unwrap();
    write_uvs(dir.path());
    let colours: [f32; 16] = [
        1.0, 0.0, 0.0, 1.0, 0.0, 1.0, 0.0, 1.0, 0.0, 0.0, 1.0, 0.5, 1.0, 1.0, 1.0, 0.25,
    ];
    let bytes: Vec<u8> = colours.iter().flat_map(|f| f.to_le_bytes()).collect();
    std::fs::write(dir.path().join("colour.bin"), bytes).unwrap();
    let mut doc = textured_document(
        json!([]),
        json!([{"name": "painted", "pbrMetallicRoughness": {"metallicFactor": 0.0}}]),
    );
    doc.as_object_mut().unwrap().remove("images");
    doc.as_object_mut().unwrap().remove("textures");
    doc["buffers"]
        .as_array_mut()
        .unwrap()
        .push(json!({"uri": "colour.bin", "byteLength": 64}));
    doc["bufferViews"]
        .as_array_mut()
        .unwrap()
        .push(json!({"buffer": 2, "byteOffset": 0, "byteLength": 64}));
    doc["accessors"]
        .as_array_mut()
        .unwrap()
        .push(json!({"bufferView": 3, "componentType": 5126, "count": 4, "type": "VEC4"}));
    doc["meshes"][0]["primitives"][0]["attributes"]["COLOR_0"] = json!(3);
    doc["meshes"][0]["primitives"][0]["attributes"]["TEXCOORD_1"] = json!(2);
    let loaded = load_scene(&write_gltf(dir.path(), "c.gltf", &doc)).unwrap();
    assert!(loaded.warnings.is_empty(), "{:?}", loaded.warnings);
    let scene = &loaded.scene;
    assert!(scene.materials[0].vertex_colours);
    let mesh = &scene.meshes[0];
    assert_eq!(mesh.colours.len(), 4);
    assert_eq!(mesh.colours[2], glam::Vec4::new(0.0, 0.0, 1.0, 0.5));
    assert_eq!(mesh.uvs.len(), 2);
    assert_eq!(mesh.uvs[1], mesh.uvs[0]);
}

/// `KHR_materials_specular`'s and `KHR_materials_sheen`'s textures are read: the strength
/// textures from the alpha channel, the colour textures as sRGB colours, each multiplying
/// its factor, with no warning.
#[test]
fn specular_and_sheen_textures_are_read() {
    let dir = tempfile::tempdir().unwrap();
    write_uvs(dir.path());
    std::fs::write(dir.path().join("t.png"), png()).unwrap();
    let mut doc = textured_document(
        json!([{"uri": "t.png"}]),
        json!([{
            "name": "velvet",
            "pbrMetallicRoughness": {"metallicFactor": 0.0},
            "extensions": {
                "KHR_materials_specular": {"specularFactor": 0.5, "specularTexture": {"index": 0},
                    "specularColorFactor": [1.0, 0.5, 0.5], "specularColorTexture": {"index": 1}},
                "KHR_materials_sheen": {"sheenColorFactor": [1.0, 1.0, 1.0], "sheenColorTexture": {"index": 0},
                    "sheenRoughnessFactor": 0.5, "sheenRoughnessTexture": {"index": 1}}
            }
        }]),
    );
    doc["extensionsUsed"] = json!(["KHR_materials_specular", "KHR_materials_sheen"]);
    let loaded = load_scene(&write_gltf(dir.path(), "t.gltf", &doc)).unwrap();
    assert!(loaded.warnings.is_empty(), "{:?}", loaded.warnings);
    let t = &loaded.scene.materials[0].textures;
    assert_eq!(t.specular.map(|c| c.channel), Some(3));
    assert_eq!(t.sheen_roughness.map(|c| c.channel), Some(3));
    assert_eq!(
        t.specular.unwrap().texture.texture,
        t.sheen_colour.unwrap().texture
    );
    assert!(t.specular_colour.is_some());
    assert_eq!(
        t.specular_colour.unwrap().texture,
        t.sheen_roughness.unwrap().texture.texture
    );
}
