//! MaterialX in USD: documents (`.mtlx`) a stage references, read as layers as USD's own
//! MaterialX plug-in reads them, and the OpenPBR, Standard Surface and glTF PBR surfaces
//! they (or Blender's USD export) describe, mapped onto the one material description.

use std::path::Path;

use glam::{Affine2, Vec2, Vec3};
use gridtrace::load::load_scene;
use gridtrace::scene::{Material, Pbr, Scene, SheenModel};

const STAGE: &str = "tests/data/scenes/third_party/usd_core_materialx.usda";

fn material<'a>(scene: &'a Scene, name: &str) -> &'a Material {
    scene
        .materials
        .iter()
        .find(|m| m.name == name)
        .unwrap_or_else(|| panic!("no material {name}"))
}

fn near(a: Vec3, b: Vec3) -> bool {
    a.abs_diff_eq(b, 1e-6)
}

/// A stage written by Pixar's library whose materials reference looks in a document
/// written by MaterialX's own library (tools/dev/make_third_party.py): each material has
/// the document's colour, metalness, roughness, coat and transmission.
#[test]
fn materials_referenced_from_a_materialx_document_have_its_values() {
    let loaded = load_scene(Path::new(STAGE)).unwrap();
    let scene = &loaded.scene;

    let gold = material(scene, "/Balls/Looks/Gold");
    assert!(
        near(gold.pbr.base_colour, Vec3::new(1.0, 0.766, 0.336)),
        "{:?}",
        gold.pbr
    );
    assert_eq!(gold.pbr.metallic, 1.0);
    assert!((gold.pbr.roughness - 0.3).abs() < 1e-6);
    assert!((gold.pbr.clearcoat - 0.4).abs() < 1e-6);
    assert!((gold.pbr.clearcoat_roughness - 0.05).abs() < 1e-6);
    // OpenPBR's fuzz is the microfibre layer; Standard Surface's sheen is Charlie's.
    assert_eq!(gold.pbr.sheen_model, SheenModel::Microfiber);

    // Standard Surface glass: its transmission colour tints it; the base weight (0.8 by
    // default) belongs to the diffuse base it replaces.
    let amber = material(scene, "/Balls/Looks/Amber");
    assert_eq!(amber.pbr.transmission, 1.0);
    assert!(
        near(amber.pbr.base_colour, Vec3::new(1.0, 0.6, 0.2)),
        "{:?}",
        amber.pbr
    );
    assert!((amber.pbr.ior - 1.52).abs() < 1e-6 && (amber.pbr.roughness - 0.05).abs() < 1e-6);
    assert_eq!(amber.pbr.metallic, 0.0);
    assert_eq!(amber.pbr.sheen_model, SheenModel::Charlie);

    // A tiled image through a node graph with a file prefix: the texture beside the
    // document, repeated 4 × 2 times (MaterialX's v runs up the image, as USD's st do).
    let brass = material(scene, "/Balls/Looks/Brass");
    let texture = brass.textures.base_colour.expect("brass colour texture");
    assert_eq!(brass.pbr.base_colour, Vec3::ONE);
    assert_eq!(brass.pbr.metallic, 1.0);
    let flip = Affine2::from_cols(Vec2::X, Vec2::NEG_Y, Vec2::Y);
    let tiling = flip * Affine2::from_scale(Vec2::new(4.0, 2.0)) * flip;
    assert!(
        texture.transform.abs_diff_eq(tiling, 1e-6),
        "{:?}",
        texture.transform
    );
    let file = &scene.textures[texture.texture].name;
    assert!(file.ends_with("materialx/textures/checker.png"), "{file}");

    // An unsupported node: one warning naming it, and the input's default.
    let noisy = material(scene, "/Balls/Looks/Noisy");
    assert!(near(noisy.pbr.base_colour, Vec3::splat(0.8)));
    let named: Vec<_> = loaded
        .warnings
        .iter()
        .filter(|w| w.contains("ND_noise2d_color3"))
        .collect();
    assert_eq!(named.len(), 1, "{:?}", loaded.warnings);
    assert_eq!(loaded.warnings.len(), 1, "{:?}", loaded.warnings);

    // The document is one of the files the render record lists.
    assert!(
        loaded
            .files
            .iter()
            .any(|f| f.path.ends_with("materialx/looks.mtlx")),
        "{:?}",
        loaded.files
    );
}

/// The MaterialX material is the material the same values give through a
/// UsdPreviewSurface, so the one BSDF it becomes renders both alike (but for the model of
/// a sheen neither has: OpenPBR's is the microfibre layer).
#[test]
fn an_open_pbr_look_is_the_preview_surface_of_the_same_values() {
    let dir = tempfile::tempdir().unwrap();
    let stage = dir.path().join("preview.usda");
    std::fs::write(
        &stage,
        r#"#usda 1.0
def Xform "Balls"
{
    def Material "Gold"
    {
        token outputs:surface.connect = </Balls/Gold/Surface.outputs:surface>
        def Shader "Surface"
        {
            uniform token info:id = "UsdPreviewSurface"
            color3f inputs:diffuseColor = (1, 0.766, 0.336)
            float inputs:metallic = 1
            float inputs:roughness = 0.3
            float inputs:clearcoat = 0.4
            float inputs:clearcoatRoughness = 0.05
            token outputs:surface
        }
    }
    def Sphere "Ball" (prepend apiSchemas = ["MaterialBindingAPI"])
    {
        rel material:binding = </Balls/Gold>
    }
}
"#,
    )
    .unwrap();
    let preview = load_scene(&stage).unwrap();
    let looks = load_scene(Path::new(STAGE)).unwrap();
    let a = material(&preview.scene, "/Balls/Gold");
    let b = material(&looks.scene, "/Balls/Looks/Gold");
    assert_eq!(b.pbr.sheen_colour, Vec3::ZERO);
    let b_pbr = Pbr {
        sheen_model: a.pbr.sheen_model,
        ..b.pbr
    };
    assert_eq!(a.pbr, b_pbr);
    assert_eq!(a.emission, b.emission);
}

/// Blender's USD export with its MaterialX option writes an OpenPBR surface beside its
/// preview surface; gridtrace reads the OpenPBR one, and every material of Blender's glass
/// and velvet scenes then equals the glTF export's (glass and sheen included, which the
/// preview surface lacks; both files, being Blender's, take Cycles' microfibre sheen).
#[test]
fn blenders_open_pbr_network_gives_the_gltf_materials() {
    for scene in ["principled_glass_tints", "principled_sheen"] {
        same_materials_in_usd_and_gltf(scene);
    }
}

fn same_materials_in_usd_and_gltf(scene: &str) {
    let usd = load_scene(Path::new(&format!("tests/data/scenes/{scene}.usdc"))).unwrap();
    let gltf = load_scene(Path::new(&format!("tests/data/scenes/{scene}.glb"))).unwrap();
    assert!(usd.warnings.is_empty(), "{:?}", usd.warnings);
    for m in &gltf.scene.materials {
        let u = material(&usd.scene, &format!("/root/_materials/{}", m.name));
        assert_eq!(u.pbr.transmission, m.pbr.transmission, "{}", m.name);
        assert!(
            near(u.pbr.base_colour, m.pbr.base_colour),
            "{}: {:?} vs {:?}",
            m.name,
            u.pbr,
            m.pbr
        );
        for (what, a, b) in [
            ("metallic", u.pbr.metallic, m.pbr.metallic),
            ("roughness", u.pbr.roughness, m.pbr.roughness),
            ("ior", u.pbr.ior, m.pbr.ior),
            ("specular", u.pbr.specular, m.pbr.specular),
            (
                "sheen roughness",
                u.pbr.sheen_roughness,
                m.pbr.sheen_roughness,
            ),
        ] {
            assert!((a - b).abs() < 1e-6, "{}: {what} {a} vs {b}", m.name);
        }
        assert!(near(u.emission, m.emission), "{}", m.name);
        assert!(near(u.pbr.sheen_colour, m.pbr.sheen_colour), "{}", m.name);
        if m.pbr.sheen_colour != Vec3::ZERO {
            assert_eq!(m.pbr.sheen_model, SheenModel::Microfiber, "{}", m.name);
            assert_eq!(u.pbr.sheen_model, SheenModel::Microfiber, "{}", m.name);
        }
        assert_eq!(
            u.textures.metallic.is_some(),
            m.textures.metallic.is_some(),
            "{}",
            m.name
        );
    }
}

/// A stage beside `document` (written as `looks.mtlx`) whose one material references
/// `/MaterialX/Materials/Look` in it.
fn stage_with_document(document: &str) -> (tempfile::TempDir, std::path::PathBuf) {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("looks.mtlx"), document).unwrap();
    let stage = dir.path().join("stage.usda");
    std::fs::write(
        &stage,
        r#"#usda 1.0
def Material "Look" (references = @./looks.mtlx@</MaterialX/Materials/Look>) {}
def Sphere "Ball" (prepend apiSchemas = ["MaterialBindingAPI"])
{
    rel material:binding = </Look>
}
"#,
    )
    .unwrap();
    (dir, stage)
}

/// Broken and hostile documents end in a warning naming the document (the material is then
/// grey), quickly and within memory: not XML, an entity expansion bomb (DTDs are refused),
/// nesting 100,000 deep, and a few kilobytes whose materials name a million node copies.
#[test]
fn broken_and_hostile_documents_give_a_warning_naming_them() {
    let deep = format!(
        "<materialx>{}{}</materialx>",
        "<a>".repeat(100_000),
        "</a>".repeat(100_000)
    );
    let bomb = concat!(
        "<?xml version=\"1.0\"?><!DOCTYPE m [<!ENTITY a \"aaaaaaaaaa\">",
        "<!ENTITY b \"&a;&a;&a;&a;&a;&a;&a;&a;&a;&a;\"><!ENTITY c \"&b;&b;&b;&b;&b;&b;&b;&b;&b;&b;\">]>",
        "<materialx>&c;</materialx>"
    );
    let mut copies = String::from("<materialx version=\"1.39\"><nodegraph name=\"G\">");
    for i in 0..1000 {
        copies.push_str(&format!("<constant name=\"c{i}\" type=\"float\"/>"));
    }
    copies.push_str("</nodegraph>");
    for i in 0..1000 {
        copies.push_str(&format!(
            "<open_pbr_surface name=\"S{i}\" type=\"surfaceshader\"><input name=\"base_weight\" type=\"float\" nodegraph=\"G\"/></open_pbr_surface><surfacematerial name=\"M{i}\" type=\"material\"><input name=\"surfaceshader\" type=\"surfaceshader\" nodename=\"S{i}\"/></surfacematerial>"
        ));
    }
    copies.push_str("</materialx>");
    for (case, document) in [
        ("not XML", "<materialx><open_pbr_surface".to_string()),
        ("entity bomb", bomb.to_string()),
        ("deep nesting", deep),
        ("node copies", copies),
    ] {
        let (_dir, stage) = stage_with_document(&document);
        let started = std::time::Instant::now();
        let loaded = load_scene(&stage).unwrap_or_else(|e| panic!("{case}: {e}"));
        assert!(
            started.elapsed().as_secs() < 20,
            "{case}: took {:?}",
            started.elapsed()
        );
        assert!(
            loaded.warnings.iter().any(|w| w.contains("looks.mtlx")),
            "{case}: {:?}",
            loaded.warnings
        );
        assert!(loaded.warnings.len() <= 3, "{case}: {:?}", loaded.warnings);
        assert!(loaded.warnings.iter().all(|w| !w.contains('\n')), "{case}");
    }
}

/// A document outside the scene's folders is refused like any layer there.
#[test]
fn a_document_outside_the_scenes_folders_is_refused() {
    let outside = tempfile::tempdir().unwrap();
    std::fs::write(outside.path().join("looks.mtlx"), "<materialx/>").unwrap();
    let dir = tempfile::tempdir().unwrap();
    let stage = dir.path().join("stage.usda");
    std::fs::write(
        &stage,
        format!(
            "#usda 1.0\ndef Material \"Look\" (references = @{}@</MaterialX/Materials/Look>) {{}}\n",
            outside.path().join("looks.mtlx").display()
        ),
    )
    .unwrap();
    let error = load_scene(&stage).unwrap_err().to_string();
    assert!(error.contains("looks.mtlx"), "{error}");
}
