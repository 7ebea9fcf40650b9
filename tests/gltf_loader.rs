//! The glTF loader: hierarchy, instancing, cameras, the material table, extensions, errors.

#[path = "support/common/mod.rs"]
mod common;

use common::{quad_document, write_gltf, write_unchecked_gltf};
use glam::{Affine3A, Quat, Vec3};
use gridtrace::cli::choose_camera;
use gridtrace::load::{GltfLightUnits, LoadError, LoadOptions, load_scene, load_scene_with};
use gridtrace::scene::{LightKind, Pbr, Projection};
use serde_json::json;

fn approx(a: Vec3, b: Vec3) -> bool {
    (a - b).abs().max_element() < 1e-5
}

#[test]
fn node_transforms_compose_down_the_hierarchy() {
    let dir = tempfile::tempdir().unwrap();
    let mut doc = quad_document();
    // Parent: translate (1, 2, 3). Child: rotate 90° about Y, scale 2. Grandchild: a matrix
    // translating by (0, 0, 5), holding the mesh.
    let q = Quat::from_rotation_y(std::f32::consts::FRAC_PI_2);
    doc["nodes"] = json!([
        {"translation": [1.0, 2.0, 3.0], "children": [1]},
        {"rotation": [q.x, q.y, q.z, q.w], "scale": [2.0, 2.0, 2.0], "children": [2]},
        {"matrix": [1,0,0,0, 0,1,0,0, 0,0,1,0, 0,0,5,1], "mesh": 0}
    ]);
    let loaded = load_scene(&write_gltf(dir.path(), "h.gltf", &doc)).unwrap();
    let scene = &loaded.scene;
    assert_eq!(scene.instances.len(), 1);
    let expected = Affine3A::from_translation(Vec3::new(1.0, 2.0, 3.0))
        * Affine3A::from_scale_rotation_translation(Vec3::splat(2.0), q, Vec3::ZERO)
        * Affine3A::from_translation(Vec3::new(0.0, 0.0, 5.0));
    let got = scene.instances[0].world_from_object;
    for p in [Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::Z] {
        assert!(
            approx(got.transform_point3(p), expected.transform_point3(p)),
            "{p}"
        );
    }
    // The quad's corner (1, 1, 0): z=5 → rotate about Y maps (1,1,5) to (5,1,-1) → ×2 → + (1,2,3).
    assert!(approx(
        got.transform_point3(Vec3::new(1.0, 1.0, 0.0)),
        Vec3::new(11.0, 4.0, 1.0)
    ));
}

#[test]
fn a_mesh_used_by_many_nodes_is_stored_once() {
    let dir = tempfile::tempdir().unwrap();
    let mut doc = quad_document();
    doc["nodes"] = json!([
        {"mesh": 0, "name": "a"},
        {"mesh": 0, "name": "b", "translation": [3.0, 0.0, 0.0]},
        {"children": [3]},
        {"mesh": 0, "name": "c", "translation": [0.0, 3.0, 0.0]}
    ]);
    doc["scenes"] = json!([{"nodes": [0, 1, 2]}]);
    let scene = load_scene(&write_gltf(dir.path(), "i.gltf", &doc))
        .unwrap()
        .scene;
    assert_eq!(scene.meshes.len(), 1);
    assert_eq!(scene.instances.len(), 3);
    assert!(scene.instances.iter().all(|i| i.mesh == 0));
    assert_eq!(scene.instances[2].source, "node 3 'c'");
    assert_eq!(scene.instanced_triangle_count(), 6);
    assert!(approx(scene.bounds().max, Vec3::new(4.0, 4.0, 0.0)));
}

#[test]
fn cameras_are_listed_in_order_and_chosen_by_name_or_index() {
    let dir = tempfile::tempdir().unwrap();
    let mut doc = quad_document();
    doc["cameras"] = json!([
        {"name": "Main", "type": "perspective", "perspective": {"yfov": 0.5, "aspectRatio": 1.5, "znear": 0.1}},
        {"name": "Top", "type": "orthographic", "orthographic": {"xmag": 2.0, "ymag": 1.0, "znear": 0.01, "zfar": 100.0}}
    ]);
    doc["nodes"] = json!([
        {"mesh": 0},
        {"camera": 0, "name": "MainNode", "translation": [0.0, 0.0, 10.0]},
        {"camera": 1, "translation": [0.0, 10.0, 0.0], "rotation": [-0.70710677, 0.0, 0.0, 0.70710677]}
    ]);
    doc["scenes"] = json!([{"nodes": [0, 1, 2]}]);
    let scene = load_scene(&write_gltf(dir.path(), "c.gltf", &doc))
        .unwrap()
        .scene;
    assert_eq!(scene.cameras.len(), 2);
    let main = choose_camera(&scene, None, None, None).unwrap();
    assert_eq!(main.name, "Main");
    assert_eq!(
        main.projection,
        Projection::Perspective {
            yfov: 0.5,
            aspect_ratio: Some(1.5)
        }
    );
    assert_eq!(main.znear, 0.1);
    assert!(approx(
        main.world_from_camera.transform_point3(Vec3::ZERO),
        Vec3::new(0.0, 0.0, 10.0)
    ));
    let top = choose_camera(&scene, Some("Top"), None, None).unwrap();
    assert_eq!(
        top.projection,
        Projection::Orthographic {
            xmag: 2.0,
            ymag: 1.0
        }
    );
    // Rotated −90° about X: the camera's −Z view axis points down −Y.
    assert!(approx(
        top.world_from_camera.transform_vector3(-Vec3::Z),
        -Vec3::Y
    ));
    assert_eq!(
        choose_camera(&scene, Some("1"), None, None).unwrap().name,
        "Top"
    );
    assert_eq!(
        choose_camera(&scene, Some("MainNode"), None, None)
            .unwrap()
            .name,
        "Main"
    );
    let err = choose_camera(&scene, Some("Side"), None, None)
        .unwrap_err()
        .to_string();
    assert!(
        err.contains("Side") && err.contains("'Main'") && err.contains("'Top'"),
        "{err}"
    );
    assert!(choose_camera(&scene, Some("7"), None, None).is_err());
}

#[test]
fn without_a_camera_a_default_one_frames_the_scene() {
    let dir = tempfile::tempdir().unwrap();
    let scene = load_scene(&write_gltf(dir.path(), "n.gltf", &quad_document()))
        .unwrap()
        .scene;
    let camera = choose_camera(&scene, None, None, None).unwrap();
    let eye = camera.world_from_camera.transform_point3(Vec3::ZERO);
    // A three-quarter view: in front (+Z), to the right (+X) and above (+Y).
    assert!(eye.z > 1.0 && eye.x > 0.3 && eye.y > 0.3, "{eye}");
    // The quad's corners are inside the view.
    let Projection::Perspective { yfov, .. } = camera.projection else {
        panic!()
    };
    let camera_from_world = camera.world_from_camera.inverse();
    for x in [-1.0, 1.0] {
        for y in [-1.0, 1.0] {
            let d = camera_from_world.transform_point3(Vec3::new(x, y, 0.0));
            let half = (0.5 * yfov).tan();
            assert!(d.z < 0.0 && (d.y / -d.z).abs() < half && (d.x / -d.z).abs() < half);
        }
    }
}

#[test]
fn materials_map_by_the_table() {
    let dir = tempfile::tempdir().unwrap();
    let mut doc = quad_document();
    doc["extensionsUsed"] = json!([
        "KHR_materials_emissive_strength",
        "KHR_materials_transmission",
        "KHR_materials_ior"
    ]);
    doc["materials"] = json!([
        {"name": "light", "emissiveFactor": [1.0, 0.5, 0.25],
         "extensions": {"KHR_materials_emissive_strength": {"emissiveStrength": 4.0}},
         "pbrMetallicRoughness": {"metallicFactor": 0.0}},
        {"name": "glass", "pbrMetallicRoughness": {"baseColorFactor": [0.9, 1.0, 0.9, 1.0], "metallicFactor": 1.0},
         "extensions": {"KHR_materials_transmission": {"transmissionFactor": 0.5}, "KHR_materials_ior": {"ior": 1.33}}},
        {"name": "metal", "pbrMetallicRoughness": {"baseColorFactor": [0.9, 0.6, 0.2, 1.0]}},
        {"name": "half metal", "pbrMetallicRoughness": {"metallicFactor": 0.49}},
        {"name": "plastic", "pbrMetallicRoughness": {"baseColorFactor": [0.1, 0.2, 0.3, 1.0], "metallicFactor": 0.0},
         "extensions": {"KHR_materials_transmission": {"transmissionFactor": 0.49}}},
        {"name": "glass default ior", "pbrMetallicRoughness": {"metallicFactor": 0.0},
         "extensions": {"KHR_materials_transmission": {"transmissionFactor": 1.0}}},
        {"name": "one-sided", "doubleSided": false, "pbrMetallicRoughness": {"metallicFactor": 0.0}}
    ]);
    let prim = |m: Option<usize>| match m {
        Some(m) => json!({"attributes": {"POSITION": 0}, "indices": 1, "material": m}),
        None => json!({"attributes": {"POSITION": 0}, "indices": 1}),
    };
    doc["meshes"] =
        json!([{"primitives": (0..7).map(Some).chain([None]).map(prim).collect::<Vec<_>>()}]);
    let loaded = load_scene(&write_gltf(dir.path(), "m.gltf", &doc)).unwrap();
    assert!(loaded.warnings.is_empty(), "{:?}", loaded.warnings);
    let m: Vec<Pbr> = loaded.scene.materials.iter().map(|m| m.pbr).collect();
    let materials = &loaded.scene.materials;
    assert_eq!(materials[0].emission, Vec3::new(4.0, 2.0, 1.0));
    // glTF's defaults: white, roughness 1, the full specular layer of IOR 1.5.
    assert_eq!(
        m[0],
        Pbr {
            metallic: 0.0,
            ..Pbr::default()
        }
    );
    // Metallic and transmission blend continuously; transmission only affects the dielectric.
    assert!(m[1].metallic == 1.0 && m[1].transmission == 0.5 && m[1].ior == 1.33);
    assert_eq!(m[1].base_colour, Vec3::new(0.9, 1.0, 0.9));
    // glTF's default metallicFactor is 1.
    assert!(m[2].metallic == 1.0 && m[2].base_colour == Vec3::new(0.9, 0.6, 0.2));
    assert_eq!(m[3].metallic, 0.49);
    assert!(m[4].transmission == 0.49 && m[4].base_colour == Vec3::new(0.1, 0.2, 0.3));
    assert!(m[5].transmission == 1.0 && m[5].ior == 1.5 && m[5].metallic == 0.0);
    // glTF's default is single-sided; Blender writes doubleSided: true. A transmitting
    // material is always two-sided: its back faces are the inside of the volume.
    assert!(!materials[6].double_sided && !materials[3].double_sided);
    assert!(materials[5].double_sided);
    // A primitive without a material gets grey plastic.
    let scene = &loaded.scene;
    assert_eq!(scene.meshes.len(), 8);
    let default = &materials[scene.meshes[7].material];
    assert_eq!(default.pbr.base_colour, Vec3::splat(0.8));
    assert!(default.pbr.metallic == 0.0 && default.pbr.roughness == 0.5);
    assert!(scene.has_emitters());
}

#[test]
fn unsupported_required_extensions_are_errors_and_used_ones_warnings() {
    let dir = tempfile::tempdir().unwrap();
    let mut doc = quad_document();
    doc["extensionsUsed"] = json!(["EXT_fancy_thing", "KHR_materials_iridescence"]);
    let loaded = load_scene(&write_gltf(dir.path(), "w.gltf", &doc)).unwrap();
    assert_eq!(loaded.warnings.len(), 1);
    assert!(
        loaded.warnings[0].contains("EXT_fancy_thing, KHR_materials_iridescence"),
        "{:?}",
        loaded.warnings
    );
    assert!(loaded.warnings[0].contains("w.gltf"));

    doc["extensionsRequired"] = json!(["EXT_fancy_thing"]);
    let path = write_gltf(dir.path(), "r.gltf", &doc);
    let err = load_scene(&path).unwrap_err();
    assert!(
        matches!(&err, LoadError::UnsupportedRequiredExtension { names, .. } if names == &["EXT_fancy_thing"])
    );
    let message = err.to_string();
    assert!(
        message.contains("r.gltf") && message.contains("EXT_fancy_thing"),
        "{message}"
    );
}

#[test]
fn strips_fans_and_unindexed_triangles_load_and_lines_are_skipped() {
    let dir = tempfile::tempdir().unwrap();
    let mut doc = quad_document();
    doc["meshes"] = json!([{"primitives": [
        {"attributes": {"POSITION": 0}, "mode": 4},
        {"attributes": {"POSITION": 0}, "mode": 5},
        {"attributes": {"POSITION": 0}, "mode": 6},
        {"attributes": {"POSITION": 0}, "mode": 1}
    ]}]);
    let loaded = load_scene(&write_gltf(dir.path(), "s.gltf", &doc)).unwrap();
    let counts: Vec<usize> = loaded
        .scene
        .meshes
        .iter()
        .map(|m| m.indices.len())
        .collect();
    assert_eq!(counts, vec![1, 2, 2]);
    // Both leftovers and the skipped line primitive are reported.
    assert_eq!(loaded.warnings.len(), 2, "{:?}", loaded.warnings);
    assert!(loaded.warnings.iter().any(|w| w.contains("Lines")));
    // Without NORMAL, glTF asks for flat shading: no vertex normals are kept, and the
    // renderer shades with each face's own normal.
    assert!(loaded.scene.meshes.iter().all(|m| m.normals.is_empty()));
}

#[test]
fn broken_files_give_one_clear_error_naming_the_file() {
    let dir = tempfile::tempdir().unwrap();
    let missing = dir.path().join("nope.glb");
    let err = load_scene(&missing).unwrap_err().to_string();
    assert!(err.contains("nope.glb"), "{err}");

    let mut doc = quad_document();
    doc["accessors"][1]["count"] = json!(600);
    let err = load_scene(&write_unchecked_gltf(dir.path(), "past.gltf", &doc))
        .unwrap_err()
        .to_string();
    assert!(
        err.contains("past.gltf") && err.contains("accessor 1"),
        "{err}"
    );

    let mut doc = quad_document();
    doc["meshes"][0]["primitives"][0]["material"] = json!(9);
    let err = load_scene(&write_unchecked_gltf(dir.path(), "idx.gltf", &doc))
        .unwrap_err()
        .to_string();
    assert!(
        err.contains("idx.gltf") && err.contains("material"),
        "{err}"
    );

    let path = dir.path().join("junk.gltf");
    std::fs::write(&path, b"{ not json").unwrap();
    let err = load_scene(&path).unwrap_err().to_string();
    assert!(
        err.contains("junk.gltf") && err.contains("invalid glTF"),
        "{err}"
    );

    let path = dir.path().join("scene.obj");
    std::fs::write(&path, b"v 0 0 0").unwrap();
    assert!(
        load_scene(&path)
            .unwrap_err()
            .to_string()
            .contains("unknown scene format")
    );
}

#[test]
fn out_of_range_vertex_indices_are_rejected() {
    let dir = tempfile::tempdir().unwrap();
    let mut buffer = common::quad_buffer();
    buffer[48..50].copy_from_slice(&7u16.to_le_bytes());
    let path = write_gltf(dir.path(), "oob.gltf", &quad_document());
    std::fs::write(dir.path().join("quad.bin"), buffer).unwrap();
    let err = load_scene(&path).unwrap_err().to_string();
    assert!(
        err.contains("oob.gltf") && err.contains("indices[0] is past the 4 vertices"),
        "{err}"
    );
}

#[test]
fn the_bundled_cornell_box_loads_as_blender_wrote_it() {
    let loaded = load_scene(std::path::Path::new("assets/cornell_box.glb")).unwrap();
    assert!(loaded.warnings.is_empty(), "{:?}", loaded.warnings);
    let scene = &loaded.scene;
    assert_eq!(scene.instances.len(), 8);
    assert_eq!(scene.cameras.len(), 1);
    let light = scene.materials.iter().find(|m| m.name == "Light").unwrap();
    // Blender: colour (1, 0.85, 0.6) at strength 12, through KHR_materials_emissive_strength.
    assert!(approx(light.emission, Vec3::new(12.0, 10.2, 7.2)));
    let red = scene.materials.iter().find(|m| m.name == "Red").unwrap();
    assert!(approx(red.pbr.base_colour, Vec3::new(0.63, 0.065, 0.05)) && red.pbr.metallic == 0.0);
    // Blender's Z-up box arrives Y-up: the floor at y = 0, the ceiling at y = 2.
    let b = scene.bounds();
    assert!(
        approx(b.min, Vec3::new(-1.0, 0.0, -1.0)) && approx(b.max, Vec3::new(1.0, 2.0, 1.0)),
        "{b:?}"
    );

    let spheres = load_scene(std::path::Path::new("assets/cornell_spheres.glb"))
        .unwrap()
        .scene;
    let kinds: Vec<_> = spheres
        .materials
        .iter()
        .map(|m| (m.name.as_str(), m.pbr))
        .collect();
    assert!(
        kinds
            .iter()
            .any(|(n, p)| *n == "Mirror" && p.metallic == 1.0 && p.roughness == 0.0),
        "{kinds:?}"
    );
    assert!(
        kinds
            .iter()
            .any(|(n, p)| *n == "Glass" && p.transmission == 1.0 && p.ior == 1.5),
        "{kinds:?}"
    );
}

/// `KHR_lights_punctual` in each of Blender's lighting modes: the values are what Blender
/// 5.0 writes for a 40 W point light, a 40 W spot and a 3 W/m² sun (Standard: 2174.06 cd and
/// 2049 lux; Unitless: 3.183 and 3; Raw: 40 and 3), and each must come back as Cycles'
/// 40/(4π) W/sr and 3 W/m².
#[test]
fn punctual_lights_load_in_each_of_blenders_units() {
    let dir = tempfile::tempdir().unwrap();
    let cases = [
        (GltfLightUnits::Standard, 2174.0565, 2049.0),
        (GltfLightUnits::Unitless, 3.183_098_8, 3.0),
        (GltfLightUnits::Raw, 40.0, 3.0),
    ];
    let expected_intensity = 40.0 / (4.0 * std::f32::consts::PI);
    for (units, point_value, sun_value) in cases {
        let mut doc = quad_document();
        doc["extensionsUsed"] = json!(["KHR_lights_punctual"]);
        doc["extensionsRequired"] = json!(["KHR_lights_punctual"]);
        doc["extensions"] = json!({"KHR_lights_punctual": {"lights": [
            {"type": "point", "intensity": point_value, "color": [1.0, 0.5, 0.25], "name": "bulb"},
            {"type": "spot", "intensity": point_value, "range": 10.0,
             "spot": {"innerConeAngle": 0.3, "outerConeAngle": 0.5}},
            {"type": "directional", "intensity": sun_value}
        ]}});
        // The spot is turned 90° about X: its −Z axis then points along +Y.
        let s = std::f32::consts::FRAC_1_SQRT_2;
        doc["nodes"] = json!([
            {"mesh": 0},
            {"translation": [1.0, 2.0, 3.0], "extensions": {"KHR_lights_punctual": {"light": 0}}},
            {"rotation": [s, 0.0, 0.0, s], "extensions": {"KHR_lights_punctual": {"light": 1}}},
            {"extensions": {"KHR_lights_punctual": {"light": 2}}}
        ]);
        doc["scenes"] = json!([{"nodes": [0, 1, 2, 3]}]);
        let path = write_gltf(dir.path(), "lights.gltf", &doc);
        let options = LoadOptions {
            gltf_light_units: units,
            ..LoadOptions::default()
        };
        let loaded = load_scene_with(&path, &options).unwrap();
        assert!(loaded.warnings.is_empty(), "{:?}", loaded.warnings);
        let lights = &loaded.scene.lights;
        assert_eq!(lights.len(), 3);
        assert_eq!(lights[0].name, "bulb");
        let close = |a: f32, b: f32| (a - b).abs() < 1e-4 * b.abs().max(1.0);
        match lights[0].kind {
            LightKind::Point {
                position,
                intensity,
                range,
            } => {
                assert!(approx(position, Vec3::new(1.0, 2.0, 3.0)));
                assert!(
                    close(intensity.x, expected_intensity),
                    "{units:?}: {intensity}"
                );
                assert!(close(intensity.y, 0.5 * expected_intensity));
                assert_eq!(range, None);
            }
            other => panic!("{other:?}"),
        }
        match lights[1].kind {
            LightKind::Spot {
                direction,
                intensity,
                cos_inner,
                cos_outer,
                range,
                ..
            } => {
                assert!(approx(direction, Vec3::Y), "{direction}");
                assert!(close(intensity.x, expected_intensity));
                assert!(close(cos_inner, 0.3f32.cos()) && close(cos_outer, 0.5f32.cos()));
                assert_eq!(range, Some(10.0));
            }
            other => panic!("{other:?}"),
        }
        match lights[2].kind {
            LightKind::Directional {
                direction,
                irradiance,
            } => {
                assert!(approx(direction, Vec3::NEG_Z));
                assert!(close(irradiance.x, 3.0), "{units:?}: {irradiance}");
            }
            other => panic!("{other:?}"),
        }
    }
}

#[test]
fn bad_punctual_lights_are_skipped_with_a_warning() {
    let dir = tempfile::tempdir().unwrap();
    let mut doc = quad_document();
    doc["extensionsUsed"] = json!(["KHR_lights_punctual"]);
    doc["extensions"] = json!({"KHR_lights_punctual": {"lights": [
        {"type": "point", "intensity": -5.0, "name": "negative"}
    ]}});
    doc["nodes"] = json!([{"mesh": 0}, {"extensions": {"KHR_lights_punctual": {"light": 0}}}]);
    doc["scenes"] = json!([{"nodes": [0, 1]}]);
    let loaded = load_scene(&write_unchecked_gltf(dir.path(), "bad_light.gltf", &doc)).unwrap();
    assert!(loaded.scene.lights.is_empty());
    assert_eq!(loaded.warnings.len(), 1, "{:?}", loaded.warnings);
    assert!(
        loaded.warnings[0].contains("bad_light.gltf") && loaded.warnings[0].contains("negative"),
        "{:?}",
        loaded.warnings
    );
}

/// Blender's own export of point, spot and sun lights (tests/data/scenes/punctual_lights.glb):
/// all three arrive, at Cycles' strengths.
#[test]
fn blender_exported_lights_arrive_at_cycles_strengths() {
    let loaded = load_scene(std::path::Path::new(
        "tests/data/scenes/punctual_lights.glb",
    ))
    .unwrap();
    assert!(loaded.warnings.is_empty(), "{:?}", loaded.warnings);
    let lights = &loaded.scene.lights;
    assert_eq!(lights.len(), 3, "{lights:?}");
    let by_name = |n: &str| lights.iter().find(|l| l.name == n).unwrap().kind;
    let four_pi = 4.0 * std::f32::consts::PI;
    match by_name("Point") {
        // 60 W, colour (1, 0.8, 0.6); Blender (x, y, z) = (0.9, −0.6, 1.6) is glTF (x, z, −y).
        LightKind::Point {
            position,
            intensity,
            ..
        } => {
            assert!(approx(position, Vec3::new(0.9, 1.6, 0.6)), "{position}");
            assert!((intensity.x - 60.0 / four_pi).abs() < 1e-3, "{intensity}");
        }
        other => panic!("{other:?}"),
    }
    match by_name("Spot") {
        // 200 W pointing straight down, a 50° cone with no blend.
        LightKind::Spot {
            direction,
            intensity,
            cos_inner,
            cos_outer,
            ..
        } => {
            assert!(approx(direction, Vec3::NEG_Y), "{direction}");
            assert!((intensity.x - 200.0 / four_pi).abs() < 1e-3, "{intensity}");
            assert!((cos_outer - 25f32.to_radians().cos()).abs() < 1e-5);
            assert!((cos_inner - cos_outer).abs() < 1e-5);
        }
        other => panic!("{other:?}"),
    }
    match by_name("Sun") {
        LightKind::Directional { irradiance, .. } => {
            assert!((irradiance.x - 1.5 * 0.8).abs() < 1e-4, "{irradiance}");
        }
        other => panic!("{other:?}"),
    }
}

#[test]
fn the_files_beside_a_gltf_are_listed() {
    let dir = tempfile::tempdir().unwrap();
    let mut document = common::quad_document();
    // An image that exists and one that does not (the latter only warns).
    std::fs::write(dir.path().join("wood.png"), b"not decoded here").unwrap();
    document["images"] = serde_json::json!([{"uri": "wood.png"}, {"uri": "gone%20missing.png"}]);
    let path = write_unchecked_gltf(dir.path(), "scene.gltf", &document);
    let loaded = load_scene(&path).unwrap();
    let names: Vec<_> = loaded
        .files
        .iter()
        .map(|f| f.path.file_name().unwrap().to_string_lossy().into_owned())
        .collect();
    assert_eq!(names, ["quad.bin", "wood.png"]);
}

/// The KHR material extensions Blender writes for Principled inputs land in the material
/// description; a texture they name that does not exist is one warning.
#[test]
fn principled_extensions_are_read() {
    let dir = tempfile::tempdir().unwrap();
    let mut doc = quad_document();
    doc["extensionsUsed"] = json!([
        "KHR_materials_specular",
        "KHR_materials_clearcoat",
        "KHR_materials_sheen"
    ]);
    doc["materials"] = json!([
        {"name": "car paint", "pbrMetallicRoughness": {"metallicFactor": 0.2, "roughnessFactor": 0.35},
         "extensions": {
            "KHR_materials_specular": {"specularFactor": 0.5, "specularColorFactor": [2.0, 1.0, 1.0]},
            "KHR_materials_clearcoat": {"clearcoatFactor": 0.7, "clearcoatRoughnessFactor": 0.1,
                                        "clearcoatNormalTexture": {"index": 0}},
            "KHR_materials_sheen": {"sheenColorFactor": [1.0, 0.5, 0.2], "sheenRoughnessFactor": 0.4}
         }}
    ]);
    doc["meshes"][0]["primitives"][0]["material"] = json!(0);
    let loaded = load_scene(&write_unchecked_gltf(dir.path(), "p.gltf", &doc)).unwrap();
    assert_eq!(loaded.warnings.len(), 1, "{:?}", loaded.warnings);
    assert!(
        loaded.warnings[0].contains("texture 0 does not exist"),
        "{:?}",
        loaded.warnings
    );
    let p = loaded.scene.materials[0].pbr;
    assert_eq!((p.metallic, p.roughness), (0.2, 0.35));
    assert_eq!(
        (p.specular, p.specular_colour),
        (0.5, Vec3::new(2.0, 1.0, 1.0))
    );
    assert!((p.clearcoat - 0.7).abs() < 1e-6 && (p.clearcoat_roughness - 0.1).abs() < 1e-6);
    assert!(p.sheen_colour == Vec3::new(1.0, 0.5, 0.2) && (p.sheen_roughness - 0.4).abs() < 1e-6);
}
