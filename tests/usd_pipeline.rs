//! USD as studios and Apple's tools write it, checked against the answers Pixar's own
//! library computes for the same stages (`tools/dev/make_usd_pipeline.py` writes both: the
//! stages under `tests/data/scenes/usd_pipeline/` and a JSON file of answers beside each).

#[path = "support/image_stats/mod.rs"]
mod image_stats;
#[path = "support/world/mod.rs"]
mod world;

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};

use gridtrace::load::{LoadOptions, Loaded, load_scene, load_scene_with};
use gridtrace::scene::{AlphaMode, Material, Scene};
use image_stats::{check_agreement, render_halves};
use serde_json::Value;
use world::{farthest, mesh_points};

const DIR: &str = "tests/data/scenes/usd_pipeline";

fn answers(name: &str) -> Value {
    let text = std::fs::read_to_string(Path::new(DIR).join(name)).unwrap();
    serde_json::from_str(&text).unwrap()
}

fn load_clean(path: &Path) -> Loaded {
    let loaded = load_scene(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    assert!(
        loaded.warnings.is_empty(),
        "{}: unexpected warnings {:#?}",
        path.display(),
        loaded.warnings
    );
    loaded
}

/// `body` as a Y-up, metre stage in a new temporary folder (kept while the folder lives).
fn write_stage(body: &str) -> (tempfile::TempDir, PathBuf) {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("stage.usda");
    let header = "#usda 1.0\n(\n    upAxis = \"Y\"\n    metersPerUnit = 1\n)\n";
    std::fs::write(&path, format!("{header}{body}")).unwrap();
    (dir, path)
}

/// The material of the mesh named `prim`, without the one-sided suffix in its name.
fn material_of<'a>(scene: &'a Scene, prim: &str) -> &'a Material {
    let mesh = scene
        .meshes
        .iter()
        .find(|m| m.name == prim)
        .unwrap_or_else(|| panic!("no mesh {prim}"));
    &scene.materials[mesh.material]
}

fn material_path(material: &Material) -> &str {
    material.name.trim_end_matches(" (one-sided)")
}

/// The first texel of the base-colour texture of `material`, 8-bit.
fn base_texel(scene: &Scene, material: &Material) -> [u8; 3] {
    let texture = material
        .textures
        .base_colour
        .as_ref()
        .unwrap_or_else(|| panic!("{} has no base-colour texture", material.name))
        .texture;
    let t = scene.textures[texture].texels[0];
    [0, 1, 2].map(|c| (t[c] / 257) as u8)
}

fn first_pixel(png: &Path) -> [u8; 3] {
    let image = image::open(png).unwrap().to_rgb8();
    image.get_pixel(0, 0).0
}

/// A texture named by a sublayer or a referenced layer in another folder is found beside
/// that layer (where `Sdf.ComputeAssetPathRelativeToLayer` puts it), not beside the root
/// stage, where decoys of another colour wait.
#[test]
fn asset_paths_resolve_against_the_layer_that_names_them() {
    let case = Path::new(DIR).join("assets");
    let loaded = load_clean(&case.join("shot.usda"));
    let expected = answers("assets/expected.json");
    let files: BTreeSet<PathBuf> = loaded
        .files
        .iter()
        .map(|d| d.path.canonicalize().unwrap())
        .collect();
    let textures = expected["textures"].as_object().unwrap();
    assert_eq!(textures.len(), 2);
    for (shader, answer) in textures {
        let anchored = case.join(answer["anchored"].as_str().unwrap());
        let resolved = case.join(answer["resolved"].as_str().unwrap());
        assert_eq!(anchored, resolved, "{shader}: USD's own two answers differ");
        assert!(
            files.contains(&resolved.canonicalize().unwrap()),
            "{shader}: {} not among the files read {files:#?}",
            resolved.display()
        );
        let material = shader.trim_end_matches("/Texture");
        let ours = loaded
            .scene
            .materials
            .iter()
            .find(|m| material_path(m) == material)
            .unwrap_or_else(|| panic!("no material {material}"));
        assert_eq!(
            base_texel(&loaded.scene, ours),
            first_pixel(&resolved),
            "{shader}: the texture read is not the one the authoring layer names"
        );
    }
}

/// A `.usdz` written by `UsdUtils.CreateNewUsdzPackage`, alone in a folder: its layers and
/// a texture two folders deep inside the archive are read from the archive.
#[test]
fn a_usdz_package_alone_reads_its_layers_and_textures_from_inside() {
    let dir = tempfile::tempdir().unwrap();
    let alone = dir.path().join("package.usdz");
    std::fs::copy(Path::new(DIR).join("package.usdz"), &alone).unwrap();
    let loaded = load_clean(&alone);
    let inside = answers("package.json")["texture_resolved_inside"]
        .as_str()
        .unwrap()
        .to_string();
    assert_eq!(inside, "[maps/deep/wood.png]");
    let material = material_of(&loaded.scene, "/Root/Top");
    assert_eq!(material_path(material), "/Root/Looks/Wood");
    assert_eq!(base_texel(&loaded.scene, material), [180, 120, 40]);
    // Everything came from the archive itself.
    assert!(loaded.files.is_empty(), "{:?}", loaded.files);
}

/// Every mesh gets the material `ComputeBoundMaterial` (full purpose) gives: inherited from
/// an ancestor, an ancestor's `strongerThanDescendants`, the full purpose over all-purpose
/// and never the preview one, a collection binding; and each material's surface is the
/// shader `ComputeSurfaceSource` finds, with the values its inputs' value-producing
/// attributes give (through a NodeGraph and the material's interface input).
#[test]
fn bound_materials_and_surfaces_are_the_ones_usd_computes() {
    let loaded = load_clean(&Path::new(DIR).join("materials.usda"));
    let expected = answers("materials.json");
    let bound = expected["bound"].as_object().unwrap();
    assert_eq!(bound.len(), 6);
    for (mesh, material) in bound {
        let material = material.as_str().unwrap();
        let ours = material_of(&loaded.scene, mesh);
        assert_eq!(material_path(ours), material, "{mesh}");
        let surface = &expected["surface"][material];
        let diffuse: Vec<f32> = surface["diffuse"]
            .as_array()
            .unwrap()
            .iter()
            .map(|v| v.as_f64().unwrap() as f32)
            .collect();
        assert_eq!(ours.pbr.base_colour.to_array().to_vec(), diffuse, "{mesh}");
        let roughness = surface["roughness"].as_f64().unwrap() as f32;
        assert_eq!(ours.pbr.roughness, roughness, "{mesh}");
    }
}

/// Without a bound material, `displayColor` (constant or per face) colours the surface and
/// `displayOpacity` below one makes it see-through, as Hydra's fallback does.
#[test]
fn display_colour_and_opacity_stand_in_for_a_missing_material() {
    let loaded = load_clean(&Path::new(DIR).join("materials.usda"));
    let expected = answers("materials.json");
    let display = expected["display"].as_object().unwrap();
    assert_eq!(display.len(), 3);
    for (prim, answer) in display {
        let colours: BTreeSet<[u32; 3]> = answer["colours"]
            .as_array()
            .unwrap()
            .iter()
            .map(|c| [0, 1, 2].map(|i| (c[i].as_f64().unwrap() * 1000.0).round() as u32))
            .collect();
        let opacity = answer["opacity"]
            .as_array()
            .map_or(1.0, |o| o[0].as_f64().unwrap() as f32);
        let mesh = loaded
            .scene
            .meshes
            .iter()
            .find(|m| &m.name == prim)
            .unwrap();
        let material = &loaded.scene.materials[mesh.material];
        assert!(material.vertex_colours, "{prim}");
        assert_eq!(material.pbr.base_colour.to_array(), [1.0; 3], "{prim}");
        let ours: BTreeSet<[u32; 3]> = mesh
            .colours
            .iter()
            .map(|c| [c.x, c.y, c.z].map(|v| (v * 1000.0).round() as u32))
            .collect();
        assert_eq!(ours, colours, "{prim}");
        assert!(mesh.colours.iter().all(|c| c.w == opacity), "{prim}");
        let blended = matches!(material.alpha_mode, AlphaMode::Blend);
        assert_eq!(blended, opacity < 1.0, "{prim}");
    }
    // Per-face colours stay with their faces: each triangle is one colour.
    let per_face = loaded
        .scene
        .meshes
        .iter()
        .find(|m| m.name == "/World/DisplayPerFace")
        .unwrap();
    for [a, b, c] in &per_face.indices {
        let [a, b, c] = [a, b, c].map(|&i| per_face.colours[i as usize]);
        assert!(a == b && b == c);
    }
}

/// `over` prims (a flattened stage's prototypes) and abstract `class` prims are not drawn;
/// a defined prim inheriting from a class is, with what it inherits: exactly the gprims
/// `Usd.PrimRange` visits with its default predicate.
#[test]
fn only_the_prims_usd_traverses_are_drawn() {
    let loaded = load_clean(&Path::new(DIR).join("prims.usda"));
    let expected: BTreeSet<String> = answers("prims.json")["drawn"]
        .as_array()
        .unwrap()
        .iter()
        .map(|p| p.as_str().unwrap().to_string())
        .collect();
    let drawn: BTreeSet<String> = loaded
        .scene
        .instances
        .iter()
        .map(|i| loaded.scene.meshes[i.mesh].name.clone())
        .collect();
    assert_eq!(drawn, expected);
}

/// Rows of a USD (row-vector) matrix as glam's column-vector matrix: the same numbers.
fn usd_matrix(rows: &Value) -> glam::Mat4 {
    let r: Vec<f32> = rows
        .as_array()
        .unwrap()
        .iter()
        .flat_map(|row| row.as_array().unwrap().iter())
        .map(|v| v.as_f64().unwrap() as f32)
        .collect();
    glam::Mat4::from_cols_slice(&r)
}

/// A PointInstancer at frame 4 (between position samples at 1 and 10) places each visible
/// instance of each prototype where `ComputeInstanceTransformsAtTime` (with the prototype's
/// own transform and the invisibleIds mask) times the instancer's world transform puts it,
/// and its instances share the prototype's meshes.
#[test]
fn point_instancer_places_instances_where_usd_computes() {
    let path = Path::new(DIR).join("instancer.usda");
    let expected = answers("instancer.json");
    let options = LoadOptions {
        frame: expected["frame"].as_f64(),
        ..LoadOptions::default()
    };
    let loaded = load_scene_with(&path, &options).unwrap();
    assert!(loaded.warnings.is_empty(), "{:#?}", loaded.warnings);
    let scene = &loaded.scene;
    let rock_from_slab = usd_matrix(&expected["rock_from_slab"]);
    let instances = expected["instances"].as_array().unwrap();
    assert_eq!(instances.len(), 5, "one of six is invisible");
    assert_eq!(scene.instances.len(), instances.len());
    for (i, instance) in instances.iter().enumerate() {
        let placed = usd_matrix(&instance["instancer_from_proto"]);
        let (mesh, world) = match instance["prototype"].as_str().unwrap() {
            "Ball" => ("/World/Scatter/Protos/Ball", placed),
            _ => ("/World/Scatter/Protos/Rock/Slab", placed * rock_from_slab),
        };
        let found = scene.instances.iter().any(|ours| {
            scene.meshes[ours.mesh].name == mesh
                && glam::Mat4::from(ours.world_from_object).abs_diff_eq(world, 1e-4)
        });
        assert!(found, "instance {i} of {mesh} not at\n{world}");
    }
    let meshes: BTreeSet<usize> = scene.instances.iter().map(|i| i.mesh).collect();
    assert_eq!(meshes.len(), 2, "instances copy their prototype's meshes");
}

/// Sphere, Cube, Cylinder, Cone, Capsule and Plane prims are drawn, each filling the world
/// bounds `UsdGeom.BBoxCache` gives it, the sphere's vertices on the sphere and its area
/// that of the sphere.
#[test]
fn implicit_prims_fill_the_bounds_usd_computes() {
    let loaded = load_clean(&Path::new(DIR).join("implicit.usda"));
    let scene = &loaded.scene;
    let bounds = answers("implicit.json")["bounds"].clone();
    let bounds = bounds.as_object().unwrap();
    assert_eq!(bounds.len(), 6);
    for (prim, answer) in bounds {
        let corner = |i: usize| {
            let c = answer[i].as_array().unwrap();
            glam::Vec3::from_array([0, 1, 2].map(|k| c[k].as_f64().unwrap() as f32))
        };
        let instance = scene
            .instances
            .iter()
            .find(|i| &scene.meshes[i.mesh].name == prim)
            .unwrap_or_else(|| panic!("{prim} not drawn"));
        let mesh = &scene.meshes[instance.mesh];
        let world: Vec<glam::Vec3> = mesh
            .positions
            .iter()
            .map(|&p| instance.world_from_object.transform_point3(p))
            .collect();
        let min = world.iter().fold(glam::Vec3::INFINITY, |a, &p| a.min(p));
        let max = world
            .iter()
            .fold(glam::Vec3::NEG_INFINITY, |a, &p| a.max(p));
        assert!(
            min.abs_diff_eq(corner(0), 1e-4) && max.abs_diff_eq(corner(1), 1e-4),
            "{prim}: bounds {min}..{max}, USD says {}..{}",
            corner(0),
            corner(1)
        );
    }
    let sphere = scene
        .meshes
        .iter()
        .find(|m| m.name == "/World/Sphere")
        .unwrap();
    assert!(
        sphere
            .positions
            .iter()
            .all(|p| (p.length() - 0.5).abs() < 1e-6)
    );
    let area: f32 = sphere
        .indices
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|i| sphere.positions[i as usize]);
            0.5 * (b - a).cross(c - a).length()
        })
        .sum();
    let exact = 4.0 * std::f32::consts::PI * 0.25;
    assert!((area / exact - 1.0).abs() < 0.005, "area {area} vs {exact}");
}

/// Blender glass through the USD exporter with its MaterialX network on: the OpenPBR
/// surface's transmission reaches the material, which then equals the glTF export's glass
/// (whose render is compared with Cycles in `principled_references`).
#[test]
fn blender_glass_from_usd_with_materialx_is_the_gltf_glass() {
    let usd = load_scene(Path::new("tests/data/scenes/principled_glass.usdc")).unwrap();
    let gltf = load_scene(Path::new("tests/data/scenes/principled_glass.glb")).unwrap();
    let find = |scene: &Scene| {
        scene
            .materials
            .iter()
            .find(|m| m.name.contains("RoughGlass"))
            .cloned()
            .unwrap()
    };
    let (usd, gltf) = (find(&usd.scene), find(&gltf.scene));
    assert_eq!(usd.pbr.transmission, 1.0);
    for (name, a, b) in [
        ("transmission", usd.pbr.transmission, gltf.pbr.transmission),
        ("roughness", usd.pbr.roughness, gltf.pbr.roughness),
        ("ior", usd.pbr.ior, gltf.pbr.ior),
        ("metallic", usd.pbr.metallic, gltf.pbr.metallic),
    ] {
        assert!((a - b).abs() < 1e-6, "{name}: USD {a}, glTF {b}");
    }
    assert!(usd.pbr.base_colour.abs_diff_eq(gltf.pbr.base_colour, 1e-6));
}

/// Blender's Subdivision modifier exported as its cage (`catmullClark`, `edgeOnly`
/// boundaries) is refined by gridtrace to the surface Blender itself exports with the
/// modifier applied at its render level: every point of either within 1 mm of a point of
/// the other, on closed objects a metre across (a cube, a capped 8-sided cylinder; measured:
/// 1.2 × 10⁻⁷ m, float precision — the limit positions are Blender's). On a
/// grid with an open boundary the points beside its corners were measured 1.6 mm off (the
/// limit mask used assumes interior neighbours; OpenSubdiv evaluates boundary patches), so
/// that object is held to 2 mm, a bound set after that measurement. A cube with Blender's
/// creases — edges creased 1 round its top face (sharpness 10, infinite), one vertical
/// edge 0.5 (sharpness 2.5, still semi-sharp after two levels) and one vertex 1 — is held
/// to 1 mm too (measured: 1.8 × 10⁻⁷ m).
#[test]
fn blender_subdivision_cage_refines_to_blenders_own_surface() {
    let cage = load_clean(&Path::new(DIR).join("subdivision_cage.usda"));
    let applied = load_clean(&Path::new(DIR).join("subdivision_applied.usda"));
    for (object, mesh, tolerance) in [
        ("Cube", "Cube", 1e-3),
        ("Cylinder", "Cylinder", 1e-3),
        ("Grid", "Grid", 2e-3),
        ("CreasedCube", "Cube_001", 1e-3),
    ] {
        let prim = format!("/root/{object}/{mesh}");
        let ours = mesh_points(&cage.scene, &prim);
        let blender = mesh_points(&applied.scene, &prim);
        assert!(!ours.is_empty() && !blender.is_empty(), "{prim}");
        let (there, back) = (farthest(&blender, &ours), farthest(&ours, &blender));
        assert!(
            there < tolerance && back < tolerance,
            "{prim}: Blender's points up to {there} m from ours, ours up to {back} m from Blender's"
        );
    }
    // The cage alone is far from the surface: the comparison can fail.
    let options = LoadOptions {
        subdivision_level: Some(0),
        ..LoadOptions::default()
    };
    let unrefined =
        load_scene_with(&Path::new(DIR).join("subdivision_cage.usda"), &options).unwrap();
    let cube = "/root/Cube/Cube";
    let far = farthest(
        &mesh_points(&unrefined.scene, cube),
        &mesh_points(&applied.scene, cube),
    );
    assert!(far > 0.05, "{far}");
}

/// USD's Z-up stage coordinates as gridtrace's Y-up world (metres per unit 1).
fn y_up(p: &Value) -> glam::Vec3 {
    let c = |i: usize| p[i].as_f64().unwrap() as f32;
    glam::Vec3::new(c(0), c(2), -c(1))
}

/// Blender's armature animation exported with its skeleton (UsdSkel) is skinned at each
/// `--frame` to where usd-core's `UsdSkel.BakeSkinning` puts every point (within 0.1 mm),
/// and to the mesh Blender itself deforms at that frame (within 1 mm), on a column 2 m
/// tall bending at two joints. Frame 1 is the rest pose; at 9 and 17 the bind pose is far
/// off, so the comparison can fail.
#[test]
fn blender_armature_animation_is_skinned_as_usd_and_blender_pose_it() {
    let baked = answers("skinned_baked.json");
    let prim = "/root/Rig/Column/Cylinder";
    let unposed = load_scene_with(
        &Path::new(DIR).join("skinned.usdc"),
        &LoadOptions {
            frame: Some(1.0),
            ..LoadOptions::default()
        },
    )
    .unwrap();
    for frame in [1, 9, 17] {
        let options = LoadOptions {
            frame: Some(frame as f64),
            ..LoadOptions::default()
        };
        let loaded = load_scene_with(&Path::new(DIR).join("skinned.usdc"), &options).unwrap();
        assert!(loaded.warnings.is_empty(), "{:#?}", loaded.warnings);
        let ours = mesh_points(&loaded.scene, prim);
        let usd: Vec<glam::Vec3> = baked[prim][frame.to_string()]
            .as_array()
            .unwrap()
            .iter()
            .map(y_up)
            .collect();
        let (there, back) = (farthest(&usd, &ours), farthest(&ours, &usd));
        assert!(
            there < 1e-4 && back < 1e-4,
            "frame {frame}: usd-core's baked points up to {there} m from ours, ours {back} m"
        );
        let blender = load_clean(&Path::new(DIR).join(format!("skinned_frame_{frame}.usdc")));
        let blender = mesh_points(&blender.scene, prim);
        let (there, back) = (farthest(&blender, &ours), farthest(&ours, &blender));
        assert!(
            there < 1e-3 && back < 1e-3,
            "frame {frame}: Blender's posed points up to {there} m from ours, ours {back} m"
        );
        if frame != 1 {
            let rest = mesh_points(&unposed.scene, prim);
            assert!(farthest(&ours, &rest) > 0.1, "frame {frame} is not posed");
        }
    }
}

/// A triangle mesh with `subdivisionScheme = "loop"` is Loop-subdivided to the level asked
/// for (four times the triangles per level), and a quad mesh asking for Loop stays its
/// cage with a warning naming it.
#[test]
fn loop_subdivision_refines_triangle_meshes_to_the_level_asked_for() {
    let (_dir, path) = write_stage(
        r#"def Mesh "Tetra"
{
    int[] faceVertexCounts = [3, 3, 3, 3]
    int[] faceVertexIndices = [0, 2, 1, 0, 1, 3, 1, 2, 3, 0, 3, 2]
    point3f[] points = [(1, 1, 1), (1, -1, -1), (-1, 1, -1), (-1, -1, 1)]
    uniform token subdivisionScheme = "loop"
}
def Mesh "Quad"
{
    int[] faceVertexCounts = [4]
    int[] faceVertexIndices = [0, 1, 2, 3]
    point3f[] points = [(3, 0, 0), (4, 0, 0), (4, 1, 0), (3, 1, 0)]
    uniform token subdivisionScheme = "loop"
}
"#,
    );
    for levels in [0u32, 1, 3] {
        let options = LoadOptions {
            subdivision_level: Some(levels),
            ..LoadOptions::default()
        };
        let loaded = load_scene_with(&path, &options).unwrap();
        let tetra = loaded
            .scene
            .meshes
            .iter()
            .find(|m| m.name == "/Tetra")
            .unwrap();
        assert_eq!(tetra.indices.len(), 4 * 4usize.pow(levels));
        let warned = loaded
            .warnings
            .iter()
            .any(|w| w.contains("/Quad: Loop subdivision needs triangles"));
        assert_eq!(warned, levels > 0, "{:#?}", loaded.warnings);
        if levels > 0 {
            // The refined surface lies strictly inside the cage's bounding cube.
            assert!(tetra.positions.iter().all(|p| p.abs().max_element() < 1.0));
        }
    }
}

/// Crease data that does not fit its mesh is left out with a warning naming the mesh and
/// what is wrong, and the surface refines smooth there: an index outside the points,
/// lengths that do not add up, a sharpness count that fits neither creases nor edges, and
/// corner sharpnesses missing. A sharpness that is not a number counts as smooth; creases
/// on a Loop surface are named as not applied.
#[test]
fn malformed_creases_are_left_out_with_a_warning() {
    let quad = |name: &str, creases: &str| {
        format!(
            r#"def Mesh "{name}"
{{
    int[] faceVertexCounts = [4, 4]
    int[] faceVertexIndices = [0, 1, 2, 3, 1, 4, 5, 2]
    point3f[] points = [(0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0), (2, 0, 0), (2, 1, 0)]
    uniform token subdivisionScheme = "catmullClark"
    {creases}
}}
"#
        )
    };
    let cases = [
        (
            "Outside",
            "int[] creaseIndices = [1, 9]\n int[] creaseLengths = [2]\n float[] creaseSharpnesses = [3]",
            "point index 9 is outside the 6 points",
        ),
        (
            "Lengths",
            "int[] creaseIndices = [1, 2]\n int[] creaseLengths = [3]\n float[] creaseSharpnesses = [3]",
            "creaseLengths add up to 3",
        ),
        (
            "Count",
            "int[] creaseIndices = [0, 1, 2]\n int[] creaseLengths = [3]\n float[] creaseSharpnesses = [1, 2, 3]",
            "3 creaseSharpnesses for 1 creases of 2 edges",
        ),
        (
            "Corners",
            "int[] cornerIndices = [0, 4]\n float[] cornerSharpnesses = [10]",
            "1 cornerSharpnesses for 2 cornerIndices",
        ),
    ];
    let stage: String = cases
        .iter()
        .map(|(name, creases, _)| quad(name, creases))
        .chain([quad("NotANumber", "int[] creaseIndices = [1, 2]\n int[] creaseLengths = [2]\n float[] creaseSharpnesses = [nan]")])
        .collect();
    let (_dir, path) = write_stage(&stage);
    let loaded = load_scene(&path).unwrap();
    for (name, _, why) in cases {
        assert!(
            loaded
                .warnings
                .iter()
                .any(|w| w.contains(&format!("/{name}: ")) && w.contains(why)),
            "{name}: {:#?}",
            loaded.warnings
        );
    }
    assert_eq!(loaded.warnings.len(), cases.len(), "{:#?}", loaded.warnings);
    assert_eq!(loaded.scene.meshes.len(), cases.len() + 1);
}

/// The same two exports rendered (default camera and studio light, 64 samples per pixel in
/// each of two halves): the refined cage and Blender's refinement give one image within
/// noise, by the block z-test every reference comparison uses.
#[test]
fn blender_subdivision_cage_renders_like_blenders_own_surface() {
    let ours = render_halves(&Path::new(DIR).join("subdivision_cage.usda"), 64, 11);
    let blender = render_halves(&Path::new(DIR).join("subdivision_applied.usda"), 64, 21);
    check_agreement(
        "subdivision_cage.usda vs subdivision_applied.usda",
        &ours,
        &blender,
    );
}

/// A subdivision surface keeps its display colours: per-point colours become per face (each
/// refined face takes its cage face's first corner's colour), so every triangle is one of
/// the authored colours throughout.
#[test]
fn subdivided_display_colours_follow_their_cage_faces() {
    let (_dir, path) = write_stage(
        r#"def Mesh "Box"
{
    int[] faceVertexCounts = [4, 4, 4, 4, 4, 4]
    int[] faceVertexIndices = [0, 4, 6, 2, 1, 3, 7, 5, 0, 1, 5, 4, 2, 6, 7, 3, 0, 2, 3, 1, 4, 5, 7, 6]
    point3f[] points = [(-1, -1, -1), (1, -1, -1), (-1, 1, -1), (1, 1, -1), (-1, -1, 1), (1, -1, 1), (-1, 1, 1), (1, 1, 1)]
    color3f[] primvars:displayColor = [(1, 0, 0), (0, 1, 0), (0, 0, 1), (1, 1, 0), (0, 1, 1), (1, 0, 1), (1, 1, 1), (0, 0, 0)] (
        interpolation = "vertex"
    )
    uniform token subdivisionScheme = "catmullClark"
}
"#,
    );
    let loaded = load_clean(&path);
    let mesh = loaded
        .scene
        .meshes
        .iter()
        .find(|m| m.name == "/Box")
        .unwrap();
    assert_eq!(mesh.indices.len(), 6 * 16 * 2);
    let authored: BTreeSet<[u32; 3]> = [
        [1, 0, 0],
        [0, 1, 0],
        [0, 0, 1],
        [1, 1, 0],
        [0, 1, 1],
        [1, 0, 1],
        [1, 1, 1],
        [0, 0, 0],
    ]
    .into_iter()
    .collect();
    let mut seen = BTreeSet::new();
    for t in &mesh.indices {
        let [a, b, c] = t.map(|i| mesh.colours[i as usize]);
        assert!(a == b && b == c);
        seen.insert([a.x, a.y, a.z].map(|v| v as u32));
    }
    // The first corners of the six faces: points 0, 1, 0, 2, 0, 4.
    let firsts: BTreeSet<[u32; 3]> = [[1, 0, 0], [0, 1, 0], [0, 0, 1], [0, 1, 1]]
        .into_iter()
        .collect();
    assert_eq!(seen, firsts);
    assert!(seen.is_subset(&authored));
}
