//! glTF 2.0 (`.gltf` with external or embedded buffers, and `.glb`) through the `gltf` crate.
//!
//! Materials become the one PBR description ([`crate::scene::Pbr`]) in `material.rs`.

use std::collections::{HashMap, HashSet};
use std::path::{Path, PathBuf};

use glam::{Affine2, Affine3A, Mat4, Vec2, Vec3};
use gltf::json::validation::Validate;

mod accessor;
mod animation;
mod deform;
mod draco;
mod files;
mod instancing;
mod material;
mod meshopt;
mod nodes;
mod pointer;
mod primitive;
mod spec_gloss;

use files::{SceneFiles, read_buffers};

use super::{AssetRoots, GltfLightUnits, LoadError, LoadOptions, Loaded};
use crate::scene::{Camera, Light, LightKind, Material, Projection, SceneBuilder};

/// How Blender's glTF exporter signs its files (`asset.generator`, "Khronos glTF Blender
/// I/O v5.0.21").
pub const BLENDER_GENERATOR: &str = "Khronos glTF Blender I/O";

/// Extensions whose meaning gridtrace implements.
pub const SUPPORTED_EXTENSIONS: &[&str] = &[
    "KHR_materials_emissive_strength",
    "KHR_materials_transmission",
    "KHR_materials_ior",
    "KHR_lights_punctual",
    "KHR_texture_transform",
    "KHR_materials_volume",
    "KHR_materials_specular",
    "KHR_materials_clearcoat",
    "KHR_materials_sheen",
    "KHR_mesh_quantization",
    "KHR_draco_mesh_compression",
    "EXT_meshopt_compression",
    "KHR_meshopt_compression",
    "EXT_texture_webp",
    "KHR_texture_basisu",
    "KHR_materials_unlit",
    "KHR_materials_variants",
    "KHR_materials_anisotropy",
    "EXT_mesh_gpu_instancing",
    "KHR_materials_pbrSpecularGlossiness",
];

/// Texture-coordinate sets read (`TEXCOORD_0` to `TEXCOORD_3`).
const MAX_UV_SETS: usize = 4;

/// Luminous efficacy the glTF specification's photometric units assume (lm/W).
const LUMENS_PER_WATT: f32 = 683.0;

/// Deepest node hierarchy accepted; deeper is treated as a cycle or an attack.
const MAX_NODE_DEPTH: usize = 256;
/// Most node visits in one scene (instancing through shared children multiplies visits).
const MAX_NODE_VISITS: usize = 1_000_000;

/// Loads a `.gltf` or `.glb` file with default options.
pub fn load(path: &Path) -> Result<Loaded, LoadError> {
    load_with(path, &LoadOptions::default())
}

/// Loads a `.gltf` or `.glb` file.
pub fn load_with(path: &Path, options: &LoadOptions) -> Result<Loaded, LoadError> {
    let bytes = std::fs::read(path).map_err(|source| LoadError::Io {
        path: path.to_path_buf(),
        source,
    })?;
    load_bytes_with(&bytes, path, options)
}

/// Loads glTF or GLB content already in memory with default options.
pub fn load_bytes(bytes: &[u8], path: &Path) -> Result<Loaded, LoadError> {
    load_bytes_with(bytes, path, &LoadOptions::default())
}

/// Loads glTF or GLB content already in memory; `path` names it in messages and locates
/// external buffers and images.
pub fn load_bytes_with(
    bytes: &[u8],
    path: &Path,
    options: &LoadOptions,
) -> Result<Loaded, LoadError> {
    let gltf_error = |message: String| LoadError::Gltf {
        path: path.to_path_buf(),
        message,
    };
    check_glb_header(bytes, path).map_err(gltf_error)?;
    let gltf::Gltf { document, blob } = pointer::parse(bytes).map_err(gltf_error)?;
    let mut warnings = Vec::new();
    check_extensions(path, &document, &mut warnings)?;
    validate(&document).map_err(gltf_error)?;
    let mut files = SceneFiles::new(path, AssetRoots::for_scene(path, &options.asset_paths));
    let (buffers, buffer_warnings) = read_buffers(&document, blob, &mut files)?;
    warnings.extend(buffer_warnings);
    let mut loader = GltfLoader {
        path: path.to_path_buf(),
        buffers,
        files,
        builder: SceneBuilder::new(),
        meshes: HashMap::new(),
        default_material: None,
        light_units: options.gltf_light_units,
        images: HashMap::new(),
        image_files: HashMap::new(),
        missing_images: HashSet::new(),
        normal_mapped: Vec::new(),
        coloured_materials: HashSet::new(),
        posed: HashMap::new(),
        posed_bytes: 0,
        time: options
            .frame
            .map(|frame| (frame / options.frames_per_second()) as f32),
        animation: options.animation.clone(),
        variant: None,
        from_blender: document
            .as_json()
            .asset
            .generator
            .as_deref()
            .is_some_and(|g| g.starts_with(BLENDER_GENERATOR)),
        warnings,
    };
    loader.variant = match &options.material_variant {
        Some(asked) => Some(loader.find_variant(&document, asked)?),
        None => None,
    };
    loader.warn_about_unreadable_images(&document);
    for material in document.materials() {
        let m = loader.convert_material(&document, &material);
        // Normal maps and anisotropy need tangents: from the normal map's coordinates,
        // else the anisotropy texture's, else the first set.
        let anisotropic = (m.pbr.anisotropy.strength > 0.0)
            .then(|| m.textures.anisotropy.map_or(0, |a| a.texcoord));
        loader.normal_mapped.push(
            m.textures
                .normal
                .or(m.textures.clearcoat_normal)
                .map(|n| n.texcoord)
                .or(anisotropic),
        );
        loader.builder.add_material(m);
    }
    loader.load_scene(&document)?;
    for &m in &loader.coloured_materials {
        loader.builder.material_mut(m).vertex_colours = true;
    }
    let mut files = loader.files.read;
    files.sort();
    Ok(Loaded {
        scene: loader.builder.build(),
        warnings: loader.warnings,
        files,
        frame: options.frame,
    })
}

/// `KHR_texture_transform`'s T · R · S. The rotation turns UVs clockwise in (u, v), i.e.
/// uv' = (u·cos + v·sin, −u·sin + v·cos): the extension's example (offset (0, 1), rotation
/// π/2, scale ½ picks the lower-left quadrant) needs that sign, and Cycles renders Blender's
/// exports with it (tests/reference_images.rs).
pub fn texture_transform(offset: Vec2, rotation: f32, scale: Vec2) -> Affine2 {
    Affine2::from_scale_angle_translation(scale, -rotation, offset)
}

/// The GLB container's 12-byte header (glTF 2.0 §4.4.2), checked before parsing so a
/// wrong or truncated file gets a precise message.
fn check_glb_header(bytes: &[u8], path: &Path) -> Result<(), String> {
    let is_glb = path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("glb"));
    if !is_glb && !bytes.starts_with(b"glTF") {
        return Ok(());
    }
    if bytes.len() < 12 || !bytes.starts_with(b"glTF") {
        return Err("not a GLB file (it does not start with the bytes 'glTF')".into());
    }
    let word = |i: usize| u32::from_le_bytes([bytes[i], bytes[i + 1], bytes[i + 2], bytes[i + 3]]);
    if word(4) != 2 {
        return Err(format!("GLB version {} is not supported (only 2)", word(4)));
    }
    let declared = word(8) as usize;
    if declared > bytes.len() {
        return Err(format!(
            "truncated GLB: the header says {declared} bytes, the file has {}",
            bytes.len()
        ));
    }
    Ok(())
}

fn check_extensions(
    path: &Path,
    document: &gltf::Document,
    warnings: &mut Vec<String>,
) -> Result<(), LoadError> {
    let unsupported = |name: &&str| !SUPPORTED_EXTENSIONS.contains(name);
    let required: Vec<String> = document
        .extensions_required()
        .filter(unsupported)
        .map(String::from)
        .collect();
    if !required.is_empty() {
        return Err(LoadError::UnsupportedRequiredExtension {
            path: path.to_path_buf(),
            names: required,
        });
    }
    let ignored: Vec<&str> = document.extensions_used().filter(unsupported).collect();
    if !ignored.is_empty() {
        warnings.push(format!(
            "{}: ignoring unsupported glTF extension(s): {}",
            path.display(),
            ignored.join(", ")
        ));
    }
    Ok(())
}

/// The glTF schema checks (index ranges, required fields), reported with their JSON paths.
fn validate(document: &gltf::Document) -> Result<(), String> {
    let root = document.as_json();
    // gltf-json's own check of POSITION's min/max indexes the accessor list before the
    // index itself is checked, and panics on an index past it (found by fuzzing).
    for (m, mesh) in root.meshes.iter().enumerate() {
        for (p, primitive) in mesh.primitives.iter().enumerate() {
            for (semantic, accessor) in &primitive.attributes {
                if accessor.value() >= root.accessors.len() {
                    return Err(format!(
                        "meshes[{m}].primitives[{p}].attributes[{semantic:?}]: accessor {} does not exist ({} accessors)",
                        accessor.value(),
                        root.accessors.len()
                    ));
                }
            }
        }
    }
    // The gltf crate unwraps an image's uri, or its mimeType beside a bufferView (found by
    // fuzzing); the specification requires them (glTF 2.0 §5.17).
    for (i, image) in root.images.iter().enumerate() {
        match (&image.uri, &image.buffer_view, &image.mime_type) {
            (None, None, _) => return Err(format!("images[{i}]: neither uri nor bufferView")),
            (_, Some(_), None) => {
                return Err(format!("images[{i}]: a bufferView image needs a mimeType"));
            }
            _ => {}
        }
    }
    // gltf-json checks a channel's sampler index but not its target's node, which the gltf
    // crate unwraps when the animation is played.
    for (a, animation) in root.animations.iter().enumerate() {
        for (c, channel) in animation.channels.iter().enumerate() {
            let node = channel.target.node.value();
            if node >= root.nodes.len() {
                return Err(format!(
                    "animations[{a}].channels[{c}].target: node {node} does not exist ({} nodes)",
                    root.nodes.len()
                ));
            }
        }
    }
    let mut errors = Vec::new();
    root.validate(root, gltf::json::Path::new, &mut |path, error| {
        let path = path().to_string();
        // gltf-json requires a bufferView without `sparse`, but an accessor without one is
        // all zeros, which an extension (Draco) may fill (glTF 2.0 §3.6.2.3).
        let zeros = path.starts_with("accessors[") && path.ends_with("].bufferView");
        let zeros = zeros && matches!(error, gltf::json::validation::Error::Missing);
        // Required extensions were checked against ours above; gltf-json knows fewer.
        if !zeros && !path.starts_with("extensionsRequired[") {
            errors.push(format!("{path}: {error}"));
        }
    });
    match errors.len() {
        0 => Ok(()),
        1 => Err(errors.remove(0)),
        n => Err(format!("{} (and {} more problems)", errors[0], n - 1)),
    }
}

struct GltfLoader {
    path: PathBuf,
    buffers: Vec<gltf::buffer::Data>,
    /// External files: what may be read, and what was.
    files: SceneFiles,
    builder: SceneBuilder,
    /// Our mesh indices for each glTF mesh, one per triangle primitive, made on first use.
    meshes: HashMap<usize, Vec<usize>>,
    default_material: Option<usize>,
    light_units: GltfLightUnits,
    /// Our texture index for each glTF image tried so far (`None`: unusable).
    images: HashMap<usize, Option<usize>>,
    /// The same for each image file, by its canonical path.
    image_files: HashMap<PathBuf, Option<usize>>,
    /// Images whose external file cannot be read (already warned about).
    missing_images: HashSet<usize>,
    /// For each glTF material: the texture-coordinate set its normal map uses, if any.
    normal_mapped: Vec<Option<usize>>,
    /// Scene materials (glTF materials and the default one) used by a primitive with vertex
    /// colours.
    coloured_materials: HashSet<usize>,
    /// Our meshes for each posed (skinned or morphed) node, made on its first visit.
    posed: HashMap<usize, Vec<usize>>,
    /// Bytes of vertex data in posed copies so far, held to the memory budget: a few bytes
    /// of JSON may name a large skinned mesh from many nodes.
    posed_bytes: u64,
    /// The time (seconds) to pose animated nodes at; `None`: as stored.
    time: Option<f32>,
    /// The animation asked for by name or index (`None`: the first).
    animation: Option<String>,
    /// The material variant rendered, by index (`None`: the primitives' own materials).
    variant: Option<u32>,
    /// True for files Blender's exporter wrote (`asset.generator`), whose anisotropy
    /// strength is Blender's Anisotropic, rendered as Cycles does.
    from_blender: bool,
    warnings: Vec<String>,
}

impl GltfLoader {
    fn invalid(&self, what: String) -> LoadError {
        LoadError::Invalid {
            path: self.path.clone(),
            what,
        }
    }

    fn warn(&mut self, what: String) {
        self.warnings
            .push(format!("{}: {what}", self.path.display()));
    }

    /// The variant named or numbered `asked`, or an error listing the file's variants.
    fn find_variant(&self, document: &gltf::Document, asked: &str) -> Result<u32, LoadError> {
        let names: Vec<&str> = document
            .variants()
            .map(|v| v.map(|v| v.name()).collect())
            .unwrap_or_default();
        let found = names
            .iter()
            .position(|n| *n == asked)
            .or_else(|| asked.parse::<usize>().ok().filter(|&i| i < names.len()));
        match found {
            Some(i) => Ok(i as u32),
            None if names.is_empty() => Err(self.invalid(format!(
                "--material-variant {asked}: the file has no material variants (KHR_materials_variants)"
            ))),
            None => Err(self.invalid(format!(
                "--material-variant {asked}: no such variant; the file has {}",
                names
                    .iter()
                    .enumerate()
                    .map(|(i, n)| format!("{i} '{n}'"))
                    .collect::<Vec<_>>()
                    .join(", ")
            ))),
        }
    }

    /// The material index of `primitive` in the variant rendered: the mapping that lists
    /// the variant, else the primitive's own material (`KHR_materials_variants`).
    fn material_index(&self, primitive: &gltf::Primitive) -> Option<usize> {
        let mapped = self.variant.and_then(|v| {
            primitive
                .mappings()
                .find(|m| m.variants().contains(&v))
                .map(|m| m.material().index())
        });
        mapped.unwrap_or_else(|| primitive.material().index())
    }

    fn material_for(&mut self, primitive: &gltf::Primitive) -> usize {
        if let Some(i) = self.material_index(primitive) {
            return i;
        }
        *self
            .default_material
            .get_or_insert_with(|| self.builder.add_material(Material::default_grey("default")))
    }

    /// A `KHR_lights_punctual` light: at the node's origin, shining down its −Z axis,
    /// converted to radiometric units by [`GltfLightUnits`].
    fn add_light(&mut self, light: &gltf::khr_lights_punctual::Light, world: Mat4, source: &str) {
        use gltf::khr_lights_punctual::Kind;
        let name = light
            .name()
            .map_or_else(|| format!("light {}", light.index()), String::from);
        let colour = Vec3::from(light.color());
        let value = light.intensity();
        if !value.is_finite() || value < 0.0 || !colour.is_finite() || colour.min_element() < 0.0 {
            self.warn(format!(
                "{source}: light '{name}' has a negative or non-finite intensity or colour; skipping it"
            ));
            return;
        }
        let directional = matches!(light.kind(), Kind::Directional);
        let strength = match (self.light_units, directional) {
            (GltfLightUnits::Standard, _) => value / LUMENS_PER_WATT,
            (GltfLightUnits::Unitless, _) | (GltfLightUnits::Raw, true) => value,
            (GltfLightUnits::Raw, false) => value / (4.0 * std::f32::consts::PI),
        };
        let position = world.transform_point3(Vec3::ZERO);
        let direction = world.transform_vector3(Vec3::NEG_Z).normalize_or_zero();
        let range = light.range().filter(|r| r.is_finite() && *r > 0.0);
        if direction == Vec3::ZERO && !matches!(light.kind(), Kind::Point) {
            self.warn(format!(
                "{source}: light '{name}' has no direction (degenerate transform); skipping it"
            ));
            return;
        }
        let kind = match light.kind() {
            Kind::Point => LightKind::Point {
                position,
                intensity: colour * strength,
                range,
            },
            Kind::Spot {
                inner_cone_angle,
                outer_cone_angle,
            } => {
                // The specification's bounds: 0 ≤ inner < outer ≤ π/2.
                let outer = outer_cone_angle.clamp(0.0, std::f32::consts::FRAC_PI_2);
                let inner = inner_cone_angle.clamp(0.0, outer);
                LightKind::Spot {
                    position,
                    direction,
                    intensity: colour * strength,
                    cos_inner: inner.cos(),
                    cos_outer: outer.cos(),
                    range,
                }
            }
            Kind::Directional => LightKind::Directional {
                direction,
                irradiance: colour * strength,
            },
        };
        self.builder.add_light(Light {
            name,
            kind,
            source: source.to_string(),
        });
    }

    fn add_camera(&mut self, camera: &gltf::Camera, world: Mat4, source: &str) {
        // Scale in a camera's node would distort distances; keep rotation and translation.
        let (_, rotation, translation) = world.to_scale_rotation_translation();
        let (projection, znear, zfar) = match camera.projection() {
            gltf::camera::Projection::Perspective(p) => (
                Projection::Perspective {
                    yfov: p.yfov(),
                    aspect_ratio: p.aspect_ratio(),
                },
                p.znear(),
                p.zfar(),
            ),
            gltf::camera::Projection::Orthographic(o) => (
                Projection::Orthographic {
                    xmag: o.xmag().abs(),
                    ymag: o.ymag().abs(),
                },
                o.znear(),
                Some(o.zfar()),
            ),
        };
        // glTF requires zfar > znear (§5.13.1); a reversed pair would clip everything.
        let znear = match zfar {
            Some(zfar) if zfar < znear => {
                self.warn(format!(
                    "{source}: camera {}: znear {znear} is beyond zfar {zfar}; clipping from {zfar} instead",
                    camera.index()
                ));
                zfar
            }
            _ => znear,
        };
        self.builder.add_camera(Camera {
            name: camera.name().unwrap_or_default().to_string(),
            world_from_camera: Affine3A::from_rotation_translation(
                rotation.normalize(),
                translation,
            ),
            projection,
            znear,
            lens: None,
            focal_length: None,
            shutter: None,
            motion: None,
            source: source.to_string(),
        });
    }
}
