//! The USD loader: Blender's USD export renders like its glTF export, and a hand-written
//! stage exercises transforms, units, axes, topology, materials, cameras and lights.

#[path = "support/image_stats/mod.rs"]
mod image_stats;
#[path = "support/world/mod.rs"]
mod world;

use std::path::Path;

use glam::Vec3;
use gridtrace::cli::choose_camera;
use gridtrace::load::{LoadError, load_scene};
use gridtrace::scene::{Filter, LightKind, Projection, Scene};
use image_stats::{check_agreement, render_halves, render_scene_halves};
use world::{close, source_triangles as world_triangles};

/// Blender's Cornell box through its USD exporter (Z-up, metres, UsdPreviewSurface) and
/// through its glTF exporter must be the same image within noise.
#[test]
fn blender_cornell_box_from_usdc_renders_like_the_glb() {
    let usd = render_halves(Path::new("assets/cornell_box.usdc"), 256, 11);
    let gltf = render_halves(Path::new("assets/cornell_box.glb"), 256, 21);
    check_agreement("cornell_box.usdc vs cornell_box.glb", &usd, &gltf);
}

/// Blender's point, spot and sun lights and an emissive panel through both exporters: the USD
/// intensities (W/π for points and spots, W/4 for the sun) must give the glTF ones' image.
#[test]
fn blender_lights_from_usdc_render_like_the_glb() {
    let usd = render_halves(Path::new("tests/data/scenes/punctual_lights.usdc"), 256, 11);
    let gltf = render_halves(Path::new("tests/data/scenes/punctual_lights.glb"), 256, 21);
    check_agreement("punctual_lights.usdc vs punctual_lights.glb", &usd, &gltf);
}

/// Blender's textures through its USD exporter (UsdUVTexture, UsdTransform2d, normal map,
/// opacity threshold, textures beside the file) against the same scene's glTF export. USD
/// has no filter setting and gridtrace filters USD textures bilinearly, so the glTF side is
/// switched from its nearest sampler to bilinear to compare like with like.
#[test]
fn blender_textures_from_usdc_render_like_the_glb() {
    let usd = render_halves(Path::new("tests/data/scenes/textured.usdc"), 256, 11);
    let mut gltf = load_scene(Path::new("tests/data/scenes/textured.glb"))
        .unwrap()
        .scene;
    for m in &mut gltf.materials {
        let t = &mut m.textures;
        for r in [&mut t.base_colour, &mut t.emissive, &mut t.normal]
            .into_iter()
            .flatten()
        {
            r.filter = Filter::Linear;
        }
    }
    let gltf = render_scene_halves(&gltf, 256, 21);
    check_agreement("textured.usdc vs textured.glb", &usd, &gltf);
}

const STAGE: &str = r#"#usda 1.0
(
    upAxis = "Z"
    metersPerUnit = 0.01
)

def Xform "World"
{
    double3 xformOp:translate = (100, 0, 0)
    uniform token[] xformOpOrder = ["xformOp:translate"]

    def Mesh "Tri"
    {
        int[] faceVertexCounts = [3]
        int[] faceVertexIndices = [0, 1, 2]
        point3f[] points = [(0, 0, 0), (100, 0, 0), (0, 100, 0)]
        uniform bool doubleSided = 1
        rel material:binding = </World/Looks/Red>
    }

    def Mesh "LeftHanded"
    {
        int[] faceVertexCounts = [3]
        int[] faceVertexIndices = [0, 1, 2]
        point3f[] points = [(0, 0, 0), (100, 0, 0), (0, 100, 0)]
        uniform token orientation = "leftHanded"
        rel material:binding = </World/Looks/Red>
    }

    def Mesh "Hidden"
    {
        token visibility = "invisible"
        int[] faceVertexCounts = [3]
        int[] faceVertexIndices = [0, 1, 2]
        point3f[] points = [(0, 0, 0), (1, 0, 0), (0, 1, 0)]
    }

    def Mesh "Guide"
    {
        uniform token purpose = "guide"
        int[] faceVertexCounts = [3]
        int[] faceVertexIndices = [0, 1, 2]
        point3f[] points = [(0, 0, 0), (1, 0, 0), (0, 1, 0)]
    }

    def Mesh "Concave"
    {
        int[] faceVertexCounts = [6]
        int[] faceVertexIndices = [0, 1, 2, 3, 4, 5]
        point3f[] points = [(1, 1, 0), (2, 1, 0), (2, 2, 0), (0, 2, 0), (0, 0, 0), (1, 0, 0)]
        normal3f[] primvars:normals = [(0, 0, 1)] (
            interpolation = "constant"
        )
        texCoord2f[] primvars:st = [(0, 0), (1, 0), (1, 1), (0, 1), (0, 0), (1, 0)] (
            interpolation = "faceVarying"
        )
        uniform token subdivisionScheme = "bilinear"
    }

    def Mesh "Subsets"
    {
        int[] faceVertexCounts = [4, 4]
        int[] faceVertexIndices = [0, 1, 2, 3, 1, 4, 5, 2]
        point3f[] points = [(0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0), (2, 0, 0), (2, 1, 0)]
        rel material:binding = </World/Looks/Red>

        def GeomSubset "Second"
        {
            uniform token elementType = "face"
            uniform token familyName = "materialBind"
            int[] indices = [1]
            rel material:binding = </World/Looks/Mirror>
        }
    }

    def Xform "Reset"
    {
        double3 xformOp:translate = (0, 0, 50)
        uniform token[] xformOpOrder = ["!resetXformStack!", "xformOp:translate"]

        def Mesh "Lifted"
        {
            int[] faceVertexCounts = [3]
            int[] faceVertexIndices = [0, 1, 2]
            point3f[] points = [(0, 0, 0), (1, 0, 0), (0, 1, 0)]
            rel material:binding = </World/Looks/Glass>
        }
    }

    def Xform "Ops"
    {
        float3 xformOp:rotateXYZ = (0, 0, 90)
        float3 xformOp:scale = (2, 2, 2)
        double3 xformOp:translate:offset = (10, 0, 0)
        uniform token[] xformOpOrder = ["xformOp:rotateXYZ", "xformOp:scale", "xformOp:translate:offset", "!invert!xformOp:translate:offset"]

        def Mesh "Turned"
        {
            int[] faceVertexCounts = [3]
            int[] faceVertexIndices = [0, 1, 2]
            point3f[] points = [(10, 0, 0), (10, 1, 0), (9, 0, 0)]
            rel material:binding = </World/Looks/Emit>
        }
    }

    def Camera "Cam"
    {
        float focalLength = 50
        float horizontalAperture = 36
        float verticalAperture = 24
        float2 clippingRange = (10, 10000)
    }

    def RectLight "Panel"
    {
        int karma:light:renderlightgeo = 1
        float inputs:intensity = 10
        float inputs:exposure = 1
        float inputs:width = 200
        float inputs:height = 100
        bool inputs:normalize = 1
    }

    def SphereLight "Bulb"
    {
        float inputs:intensity = 8
        color3f inputs:color = (1, 0.5, 0.25)
        float inputs:radius = 0
        bool treatAsPoint = 1
    }

    def DistantLight "Sun"
    {
        float inputs:intensity = 3
    }

    def SphereLight "Globe"
    {
        float inputs:intensity = 3
        bool inputs:normalize = 1
        float inputs:radius = 10
    }

    def DiskLight "Disk"
    {
        float inputs:intensity = 2
        float inputs:radius = 50
    }

    def SphereLight "WarmSpot" (
        prepend apiSchemas = ["ShapingAPI"]
    )
    {
        float inputs:intensity = 4
        bool inputs:normalize = 1
        float inputs:radius = 0
        bool inputs:enableColorTemperature = 1
        float inputs:colorTemperature = 3000
        float inputs:shaping:cone:angle = 30
        float inputs:shaping:cone:softness = 0.5
    }

    def Xform "Variant" (
        variants = {
            string size = "big"
        }
        prepend variantSets = "size"
    )
    {
        variantSet "size" = {
            "big" {
                def Mesh "Chosen"
                {
                    int[] faceVertexCounts = [3]
                    int[] faceVertexIndices = [0, 1, 2]
                    point3f[] points = [(0, 0, 0), (1, 0, 0), (0, 1, 0)]
                }
            }
            "small" {
                def Mesh "NotChosen"
                {
                    int[] faceVertexCounts = [3]
                    int[] faceVertexIndices = [0, 1, 2]
                    point3f[] points = [(0, 0, 0), (1, 0, 0), (0, 1, 0)]
                }
            }
        }
    }

    def Xform "Payloaded" (
        payload = @./part.usda@</Part>
    )
    {
    }

    def DomeLight "Sky"
    {
        float inputs:intensity = 0.5
        color3f inputs:color = (1, 0.5, 0.25)
    }

    def Sphere "Ball"
    {
    }

    def Scope "Looks"
    {
        def Material "Red"
        {
            token outputs:surface.connect = </World/Looks/Red/Surface.outputs:surface>
            def Shader "Surface"
            {
                uniform token info:id = "UsdPreviewSurface"
                color3f inputs:diffuseColor = (0.8, 0.1, 0.1)
                token outputs:surface
            }
        }
        def Material "Mirror"
        {
            token outputs:surface.connect = </World/Looks/Mirror/Surface.outputs:surface>
            def Shader "Surface"
            {
                uniform token info:id = "UsdPreviewSurface"
                color3f inputs:diffuseColor = (0.9, 0.9, 0.9)
                float inputs:metallic = 1
                float inputs:roughness = 0
                token outputs:surface
            }
        }
        def Material "Glass"
        {
            token outputs:surface.connect = </World/Looks/Glass/Surface.outputs:surface>
            def Shader "Surface"
            {
                uniform token info:id = "UsdPreviewSurface"
                color3f inputs:diffuseColor = (1, 1, 1)
                float inputs:opacity = 0.1
                float inputs:ior = 1.33
                float inputs:roughness = 0
                token outputs:surface
            }
        }
        def Material "Emit"
        {
            token outputs:surface.connect = </World/Looks/Emit/Surface.outputs:surface>
            def Shader "Surface"
            {
                uniform token info:id = "UsdPreviewSurface"
                color3f inputs:diffuseColor = (0, 0, 0)
                color3f inputs:emissiveColor = (5, 4, 3)
                token outputs:surface
            }
        }
    }
}
"#;

/// A file other stages reference, pull in as a payload or instance.
const PART: &str = r#"#usda 1.0
(
    upAxis = "Y"
    metersPerUnit = 1
)
def Xform "Part"
{
    def Mesh "Tri"
    {
        int[] faceVertexCounts = [3]
        int[] faceVertexIndices = [0, 1, 2]
        point3f[] points = [(0, 0, 0), (1, 0, 0), (0, 1, 0)]
        uniform bool doubleSided = 1
    }
}
"#;

/// World-space corners of each instanced triangle of the instance named `source`.

#[test]
fn a_hand_written_stage_loads_as_usd_defines_it() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("stage.usda");
    std::fs::write(&path, STAGE).unwrap();
    std::fs::write(dir.path().join("part.usda"), PART).unwrap();
    let loaded = load_scene(&path).unwrap();
    let scene = &loaded.scene;
    // Everything in the stage is read: no warnings.
    assert!(loaded.warnings.is_empty(), "{:#?}", loaded.warnings);

    // Z-up centimetres become Y-up metres: stage (x, y, z) cm → (x, z, −y) / 100.
    let tri = world_triangles(scene, "/World/Tri");
    assert_eq!(tri.len(), 1);
    assert!(close(tri[0][0], Vec3::new(1.0, 0.0, 0.0)), "{:?}", tri[0]);
    assert!(close(tri[0][1], Vec3::new(2.0, 0.0, 0.0)), "{:?}", tri[0]);
    assert!(close(tri[0][2], Vec3::new(1.0, 0.0, -1.0)), "{:?}", tri[0]);
    // Counter-clockwise about stage +Z, which is world +Y.
    let n = (tri[0][1] - tri[0][0]).cross(tri[0][2] - tri[0][0]);
    assert!(n.y > 0.0, "{n}");
    // leftHanded reverses the winding.
    let left = world_triangles(scene, "/World/LeftHanded");
    let n = (left[0][1] - left[0][0]).cross(left[0][2] - left[0][0]);
    assert!(n.y < 0.0, "{n}");
    // Invisible and guide prims are skipped; the Sphere gprim (radius 1 cm by default) is
    // drawn (`usd_pipeline` checks implicit prims against USD's bounds).
    assert!(world_triangles(scene, "/World/Hidden").is_empty());
    assert!(world_triangles(scene, "/World/Guide").is_empty());
    let ball = world_triangles(scene, "/World/Ball");
    assert!(!ball.is_empty());
    assert!(
        ball.iter()
            .flatten()
            .all(|p| (p.distance(Vec3::X) - 0.01).abs() < 1e-6),
        "the ball is not the unit sphere in centimetres"
    );

    // A concave hexagon (an L of area 3 cm²) becomes four triangles covering it exactly.
    let concave = world_triangles(scene, "/World/Concave");
    assert_eq!(concave.len(), 4);
    let area: f32 = concave
        .iter()
        .map(|t| 0.5 * (t[1] - t[0]).cross(t[2] - t[0]).length())
        .sum();
    assert!((area - 3e-4).abs() < 1e-8, "{area}");
    let mesh = scene
        .meshes
        .iter()
        .find(|m| m.name == "/World/Concave")
        .unwrap();
    assert_eq!(mesh.uvs.len(), 1);
    assert!(mesh.normals.iter().all(|n| *n == Vec3::Z));

    // GeomSubsets split the mesh by material.
    let subset_materials: Vec<&str> = scene
        .instances
        .iter()
        .filter(|i| i.source == "/World/Subsets")
        .map(|i| scene.materials[scene.meshes[i.mesh].material].name.as_str())
        .collect();
    assert_eq!(
        subset_materials,
        [
            "/World/Looks/Red (one-sided)",
            "/World/Looks/Mirror (one-sided)"
        ],
        "unauthored doubleSided is false in USD: one-sided copies of the materials"
    );
    let tri_mesh = scene
        .instances
        .iter()
        .find(|i| i.source == "/World/Tri")
        .unwrap()
        .mesh;
    let tri_material = &scene.materials[scene.meshes[tri_mesh].material];
    assert!(tri_material.double_sided && tri_material.name == "/World/Looks/Red");

    // !resetXformStack! ignores the parent's translate; the stage correction still applies.
    let lifted = world_triangles(scene, "/World/Reset/Lifted");
    assert!(
        close(lifted[0][0], Vec3::new(0.0, 0.5, 0.0)),
        "{:?}",
        lifted[0]
    );
    // rotateXYZ, scale, then a translate and its !invert! (which cancel): a stage point
    // (10, 0, 0) is scaled to (20, 0, 0) and turned 90° about Z to (0, 20, 0), then the
    // parent's translate adds (100, 0, 0): (100, 20, 0) cm → (1, 0, −0.2) m.
    let turned = world_triangles(scene, "/World/Ops/Turned");
    assert!(
        close(turned[0][0], Vec3::new(1.0, 0.0, -0.2)),
        "{:?}",
        turned[0]
    );

    // Materials map as glTF's do.
    let kind = |name: &str| {
        scene
            .materials
            .iter()
            .find(|m| m.name == name)
            .unwrap_or_else(|| panic!("{name}"))
            .clone()
    };
    let red = kind("/World/Looks/Red").pbr;
    assert_eq!(red.base_colour, Vec3::new(0.8, 0.1, 0.1));
    assert!(red.metallic == 0.0 && red.transmission == 0.0 && red.specular == 1.0);
    assert_eq!(kind("/World/Looks/Mirror").pbr.metallic, 1.0);
    let glass = kind("/World/Looks/Glass").pbr;
    // UsdPreviewSurface refracts with its ior below full opacity: opacity 0.1 transmits 0.9.
    assert!((glass.transmission - 0.9).abs() < 1e-6 && glass.ior == 1.33);
    assert_eq!(kind("/World/Looks/Emit").emission, Vec3::new(5.0, 4.0, 3.0));

    // Camera: 50 mm over a 24 mm aperture, near plane 10 cm.
    let camera = &scene.cameras[0];
    match camera.projection {
        Projection::Perspective { yfov, aspect_ratio } => {
            assert!((yfov - 2.0 * (12.0f32 / 50.0).atan()).abs() < 1e-6);
            assert_eq!(aspect_ratio, Some(1.5));
        }
        other => panic!("{other:?}"),
    }
    assert!((camera.znear - 0.1).abs() < 1e-6);
    assert_eq!(camera.name, "/World/Cam");

    // Lights. The rect light is an emitter of radiance intensity × 2^exposure / area
    // (normalized), 2 m × 1 m after the unit change.
    let panel = scene
        .materials
        .iter()
        .find(|m| m.name == "/World/Panel")
        .unwrap();
    assert!(
        close(panel.emission, Vec3::splat(10.0 * 2.0 / 2.0)),
        "{}",
        panel.emission
    );
    assert!(!panel.double_sided);
    let bulb = scene
        .lights
        .iter()
        .find(|l| l.name == "/World/Bulb")
        .unwrap();
    match bulb.kind {
        // Normalized sphere: intensity / 4 per steradian.
        LightKind::Point {
            position,
            intensity,
            ..
        } => {
            assert!(close(position, Vec3::new(1.0, 0.0, 0.0)));
            assert!(close(intensity, Vec3::new(2.0, 1.0, 0.5)), "{intensity}");
        }
        other => panic!("{other:?}"),
    }
    let sun = scene
        .lights
        .iter()
        .find(|l| l.name == "/World/Sun")
        .unwrap();
    match sun.kind {
        // −Z of a Z-up stage is world −Y: straight down.
        LightKind::Directional {
            direction,
            irradiance,
        } => {
            assert!(close(direction, Vec3::NEG_Y), "{direction}");
            assert!(close(irradiance, Vec3::splat(3.0)));
        }
        other => panic!("{other:?}"),
    }
    let environment = scene.environment.as_ref().expect("the dome light");
    assert!(environment.map.is_none());
    assert!(
        close(environment.tint, Vec3::new(0.5, 0.25, 0.125)),
        "{}",
        environment.tint
    );
    // A disk of radius 50 cm, not normalized: radiance = intensity over a disc of π/4 m²;
    // the inscribed polygon (a little smaller) emits the disc's power.
    let disk = world_triangles(scene, "/World/Disk");
    let area: f32 = disk
        .iter()
        .map(|t| 0.5 * (t[1] - t[0]).cross(t[2] - t[0]).length())
        .sum();
    assert!((area - std::f32::consts::PI / 4.0).abs() < 0.01, "{area}");
    let disk_material = scene
        .materials
        .iter()
        .find(|m| m.name == "/World/Disk")
        .unwrap();
    let power = disk_material.emission * area;
    assert!(
        close(power, Vec3::splat(2.0 * std::f32::consts::PI / 4.0)),
        "{power}"
    );
    let warm = scene
        .lights
        .iter()
        .find(|l| l.name == "/World/WarmSpot")
        .unwrap();
    match warm.kind {
        // Softness 0.5 of a 30° cone: full inside 15°; 3000 K is warm.
        LightKind::Spot {
            intensity,
            cos_inner,
            cos_outer,
            ..
        } => {
            assert!((cos_outer - 30f32.to_radians().cos()).abs() < 1e-6);
            assert!((cos_inner - 15f32.to_radians().cos()).abs() < 1e-6);
            assert!(
                intensity.x > intensity.y && intensity.y > intensity.z,
                "{intensity}"
            );
        }
        other => panic!("{other:?}"),
    }
    // A sphere light with a radius is a sphere lamp (radius 10 cm after the unit change):
    // normalized, its radiance is intensity over its area.
    let globe = scene
        .lights
        .iter()
        .find(|l| l.name == "/World/Globe")
        .unwrap();
    let LightKind::Sphere {
        radius,
        radiance,
        spot,
        camera_visible,
        ..
    } = globe.kind
    else {
        panic!("{:?}", globe.kind)
    };
    assert!((radius - 0.1).abs() < 1e-6, "{radius}");
    let expected = 3.0 / (4.0 * std::f32::consts::PI * 0.01);
    assert!((radiance.x / expected - 1.0).abs() < 1e-4, "{radiance}");
    assert!(spot.is_none());
    // Lamps are not seen by camera rays unless the file says so (the panel does).
    assert!(!camera_visible);
    assert!(panel.camera_visible);
    // `--camera` finds a USD camera by its prim path.
    let chosen = choose_camera(scene, Some("/World/Cam"), None, None).unwrap();
    assert_eq!(chosen.name, "/World/Cam");
    // The selected variant and the payload are composed in; the other variant is not.
    assert_eq!(world_triangles(scene, "/World/Variant/Chosen").len(), 1);
    assert!(world_triangles(scene, "/World/Variant/NotChosen").is_empty());
    assert_eq!(world_triangles(scene, "/World/Payloaded/Tri").len(), 1);
}

#[test]
fn broken_usd_files_give_one_clear_error() {
    let dir = tempfile::tempdir().unwrap();
    let garbage = dir.path().join("garbage.usda");
    std::fs::write(
        &garbage,
        "#usda 1.0\ndef Mesh \"M\" { int[] faceVertexCounts = [3 }",
    )
    .unwrap();
    let err = load_scene(&garbage).unwrap_err().to_string();
    assert!(err.contains("garbage.usda"), "{err}");

    let bad_index = dir.path().join("bad_index.usda");
    std::fs::write(
        &bad_index,
        "#usda 1.0\ndef Mesh \"M\"\n{\n    int[] faceVertexCounts = [3]\n    int[] faceVertexIndices = [0, 1, 7]\n    point3f[] points = [(0, 0, 0), (1, 0, 0), (0, 1, 0)]\n}\n",
    )
    .unwrap();
    let err = load_scene(&bad_index).unwrap_err();
    assert!(matches!(err, LoadError::Invalid { .. }), "{err}");
    let message = err.to_string();
    assert!(
        message.contains("bad_index.usda") && message.contains("/M") && message.contains("7"),
        "{message}"
    );

    let missing = load_scene(&dir.path().join("missing.usdc"))
        .unwrap_err()
        .to_string();
    assert!(missing.contains("missing.usdc"), "{missing}");
}

/// The same Blender export packaged as `.usdz` loads the same scene.
#[test]
fn usdz_packages_load_like_their_usdc() {
    let usdz = load_scene(Path::new("tests/data/scenes/cornell_box.usdz")).unwrap();
    let usdc = load_scene(Path::new("assets/cornell_box.usdc")).unwrap();
    assert!(usdz.warnings.is_empty(), "{:?}", usdz.warnings);
    assert_eq!(
        usdz.scene.instanced_triangle_count(),
        usdc.scene.instanced_triangle_count()
    );
    assert_eq!(usdz.scene.bounds(), usdc.scene.bounds());
    let sorted = |scene: &Scene| {
        let mut m = scene.materials.clone();
        m.sort_by(|a, b| a.name.cmp(&b.name));
        m
    };
    assert_eq!(sorted(&usdz.scene), sorted(&usdc.scene));
    assert_eq!(usdz.scene.cameras.len(), 1);
}

/// References pull a prim in from another file; an instanceable reference shares its
/// prototype: both place the referenced triangle under their own transform.
#[test]
fn references_and_instances_are_composed() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("part.usda"), PART).unwrap();
    let main = dir.path().join("main.usda");
    std::fs::write(
        &main,
        "#usda 1.0\n(\n    upAxis = \"Y\"\n    metersPerUnit = 1\n)\n\
         def Xform \"A\" (\n    references = @./part.usda@</Part>\n)\n{\n    \
         double3 xformOp:translate = (5, 0, 0)\n    uniform token[] xformOpOrder = [\"xformOp:translate\"]\n}\n\
         def Xform \"B\" (\n    instanceable = true\n    references = @./part.usda@</Part>\n)\n{\n    \
         double3 xformOp:translate = (0, 7, 0)\n    uniform token[] xformOpOrder = [\"xformOp:translate\"]\n}\n",
    )
    .unwrap();
    let loaded = load_scene(&main).unwrap();
    assert!(loaded.warnings.is_empty(), "{:?}", loaded.warnings);
    // The referenced layer is a file the scene was read from; the stage itself is not.
    let files: Vec<_> = loaded
        .files
        .iter()
        .map(|f| f.path.file_name().unwrap())
        .collect();
    assert_eq!(files, ["part.usda"], "{:?}", loaded.files);
    let scene = &loaded.scene;
    let mut origins: Vec<Vec3> = scene
        .instances
        .iter()
        .map(|i| {
            i.world_from_object
                .transform_point3(scene.meshes[i.mesh].positions[0])
        })
        .collect();
    origins.sort_by(|a, b| a.x.total_cmp(&b.x));
    assert_eq!(
        origins,
        vec![Vec3::new(0.0, 7.0, 0.0), Vec3::new(5.0, 0.0, 0.0)]
    );
}

/// UsdPreviewSurface inputs as docs/manual/materials.md's table maps them: the specular
/// workflow's F0, Blender's `specular` level, clear coat, and scalar inputs read from one
/// channel of a texture with that channel's `scale`.
#[test]
fn preview_surface_inputs_map_to_the_material_description() {
    let dir = tempfile::tempdir().unwrap();
    image::RgbaImage::from_pixel(2, 2, image::Rgba([255, 128, 0, 255]))
        .save(dir.path().join("packed.png"))
        .unwrap();
    let material = |name: &str, inputs: &str| {
        format!(
            r#"
        def Material "{name}"
        {{
            token outputs:surface.connect = </World/Looks/{name}/Surface.outputs:surface>
            def Shader "Surface"
            {{
                uniform token info:id = "UsdPreviewSurface"
                {inputs}
                token outputs:surface
            }}
            def Shader "Packed"
            {{
                uniform token info:id = "UsdUVTexture"
                asset inputs:file = @packed.png@
                float4 inputs:scale = (1, 0.5, 1, 1)
                float outputs:g
                float outputs:b
            }}
        }}"#
        )
    };
    let mesh = |name: &str, look: &str, x: i32| {
        format!(
            r#"
    def Mesh "{name}"
    {{
        int[] faceVertexCounts = [3]
        int[] faceVertexIndices = [0, 1, 2]
        point3f[] points = [({x}, 0, 0), ({x}.5, 0, 0), ({x}, 1, 0)]
        rel material:binding = </World/Looks/{look}>
    }}"#
        )
    };
    let stage = format!(
        "#usda 1.0\n(\n    defaultPrim = \"World\"\n    upAxis = \"Y\"\n    metersPerUnit = 1\n)\n\
         def Xform \"World\"\n{{{}{}{}\n    def Scope \"Looks\"\n    {{{}{}{}\n    }}\n}}\n",
        mesh("A", "Specular", 0),
        mesh("B", "Blender", 2),
        mesh("C", "Textured", 4),
        material(
            "Specular",
            "int inputs:useSpecularWorkflow = 1\n                color3f inputs:specularColor = (0.1, 0.2, 0.3)\n                float inputs:clearcoat = 0.5\n                float inputs:clearcoatRoughness = 0.2"
        ),
        material(
            "Blender",
            "float inputs:specular = 0.25\n                float inputs:metallic = 0.3"
        ),
        material(
            "Textured",
            "float inputs:roughness.connect = </World/Looks/Textured/Packed.outputs:g>\n                float inputs:metallic.connect = </World/Looks/Textured/Packed.outputs:b>"
        ),
    );
    let path = dir.path().join("looks.usda");
    std::fs::write(&path, stage).unwrap();
    let loaded = load_scene(&path).unwrap();
    assert!(loaded.warnings.is_empty(), "{:?}", loaded.warnings);
    let find = |name: &str| {
        loaded
            .scene
            .materials
            .iter()
            .find(|m| m.name == format!("/World/Looks/{name}"))
            .unwrap_or_else(|| panic!("{name}"))
            .clone()
    };
    let specular = find("Specular").pbr;
    // F0 = min(F0(ior)·specularColour, 1)·specular is the authored specularColor.
    let f0 =
        gridtrace::scene::f0_of_ior(specular.ior) * specular.specular_colour * specular.specular;
    assert!(
        (f0 - Vec3::new(0.1, 0.2, 0.3)).abs().max_element() < 1e-5,
        "{f0}"
    );
    assert_eq!(specular.metallic, 0.0);
    assert!(specular.clearcoat == 0.5 && (specular.clearcoat_roughness - 0.2).abs() < 1e-6);
    // Blender's level 0.25 halves F0: specular 0.5 with an untinted colour.
    let blender = find("Blender").pbr;
    assert!((blender.specular - 0.5).abs() < 1e-6 && blender.specular_colour == Vec3::ONE);
    assert!((blender.metallic - 0.3).abs() < 1e-6);
    // Texture channels: roughness from green with its scale 0.5, metallic from blue.
    let textured = find("Textured");
    let roughness = textured.textures.roughness.expect("roughness texture");
    let metallic = textured.textures.metallic.expect("metallic texture");
    assert_eq!((roughness.channel, metallic.channel), (1, 2));
    assert!((textured.pbr.roughness - 0.5).abs() < 1e-6 && textured.pbr.metallic == 1.0);
}

/// A UsdPreviewSurface whose diffuseColor reads `displayColor` through a
/// `UsdPrimvarReader_float3` (written by Pixar's USD library, tools/dev/make_third_party.py)
/// takes the mesh's own per-vertex colours: red corners stay red, blue ones blue.
#[test]
fn diffuse_colour_read_from_display_colour_takes_the_vertex_colours() {
    let path = Path::new("tests/data/scenes/third_party/usd_core_primvar_colour.usda");
    let loaded = load_scene(path).unwrap();
    assert!(loaded.warnings.is_empty(), "{:?}", loaded.warnings);
    let scene = loaded.scene;
    let mesh = &scene.meshes[0];
    let material = &scene.materials[mesh.material];
    assert!(material.vertex_colours && material.pbr.base_colour == Vec3::ONE);
    assert_eq!(mesh.colours.len(), mesh.positions.len());
    for (p, c) in mesh.positions.iter().zip(&mesh.colours) {
        let want = if p.x < 0.0 {
            Vec3::new(0.8, 0.05, 0.05)
        } else {
            Vec3::new(0.05, 0.05, 0.8)
        };
        assert!(close(c.truncate(), want), "at {p}: {c}");
    }
}
