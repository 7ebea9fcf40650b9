//! Scene loaders: each turns one file format into a [`Scene`].

pub(crate) mod access;
mod error;
pub mod gltf;
pub(crate) mod guard;
mod images;
pub(crate) mod motion;
pub mod ply;
mod polygon;
mod subdivision;
mod tangents;
pub mod usd;

pub use access::AssetRoots;
pub use error::LoadError;

use std::path::{Path, PathBuf};

use crate::geometry::is_degenerate;
use crate::record::Dependency;
use crate::scene::{Environment, EnvironmentMap, Scene, blender_world_rotation};

/// A loaded scene and the warnings met on the way (things skipped or approximated).
#[derive(Debug)]
pub struct Loaded {
    /// The scene.
    pub scene: Scene,
    /// One line each, already naming what they concern.
    pub warnings: Vec<String>,
    /// Other files the scene was read from (glTF buffers and images, USD layers and
    /// textures), so a render's record can say exactly what it rendered.
    pub files: Vec<Dependency>,
    /// The frame it was read at, when the file has a timeline and one was used (USD: the
    /// time code; glTF: `--frame`): motion blur reads it again around this frame.
    pub frame: Option<f64>,
}

/// How to read what a file leaves to convention.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct LoadOptions {
    /// Units of glTF punctual light intensities.
    pub gltf_light_units: GltfLightUnits,
    /// The frame to read an animated scene at: a USD time code; for glTF, the time
    /// frame ÷ [`LoadOptions::fps`] seconds, as Blender's exporter writes keyframe times.
    /// `None`: USD's `startTimeCode`, glTF's nodes as stored. PLY refuses it.
    pub frame: Option<f64>,
    /// Frames per second turning a frame into glTF time (`None`: 24, Blender's default).
    pub fps: Option<f64>,
    /// The glTF animation to evaluate, by name or index (`None`: the first).
    pub animation: Option<String>,
    /// The glTF material variant (`KHR_materials_variants`) to render, by name or index
    /// (`None`: the primitives' own materials).
    pub material_variant: Option<String>,
    /// Folders a scene may read besides its own (`--asset-path`); see [`access`].
    pub asset_paths: Vec<PathBuf>,
    /// Levels of Catmull–Clark refinement for USD meshes that ask for subdivision
    /// (`None`: [`DEFAULT_SUBDIVISION_LEVEL`]).
    pub subdivision_level: Option<u32>,
    /// More frames the USD crash probe reads the stage at, besides `frame`: a shutter's
    /// instants, so that one child process probes them all.
    pub probe_also_at: Vec<f64>,
    /// The stage has been probed at this frame already (by a probe given it in
    /// `probe_also_at`): read it without a child process.
    pub probed: bool,
    /// Lamps with a radius shine as balls even where the file's writer (Blender) means
    /// Soft Falloff, which makes them discs facing what they light (`--soft-falloff off`).
    pub hard_falloff: bool,
}

/// Levels a subdivision surface is refined to by default: Blender's Subdivision modifier
/// renders at level 2 unless told otherwise, and its USD export writes the cage.
pub const DEFAULT_SUBDIVISION_LEVEL: u32 = 2;

impl LoadOptions {
    /// Levels of refinement for subdivision surfaces.
    pub fn subdivision_levels(&self) -> u32 {
        self.subdivision_level.unwrap_or(DEFAULT_SUBDIVISION_LEVEL)
    }

    /// The frame rate turning frames into glTF seconds.
    pub fn frames_per_second(&self) -> f64 {
        self.fps.unwrap_or(24.0)
    }
}

/// What a glTF file's `KHR_lights_punctual` intensities mean. Blender's exporter offers all
/// three ("Lighting Mode"); each is converted to radiant intensity (W/sr) for point and spot
/// lights and irradiance (W/m²) for directional lights, which is what Blender's own watts
/// mean to Cycles, so exported lights keep their balance with emissive surfaces.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum GltfLightUnits {
    /// The glTF specification: candela and lux, at 683 lm/W (Blender's "Standard").
    #[default]
    Standard,
    /// Watts per steradian and W/m² as written (Blender's "Unitless").
    Unitless,
    /// Blender's "Raw": point and spot lights in watts of emitted power, directional in W/m².
    Raw,
}

impl GltfLightUnits {
    /// The name on the command line and in render records.
    pub fn name(self) -> &'static str {
        match self {
            GltfLightUnits::Standard => "standard",
            GltfLightUnits::Unitless => "unitless",
            GltfLightUnits::Raw => "raw",
        }
    }
}

/// Loads a scene with default options; see [`load_scene_with`].
pub fn load_scene(path: &Path) -> Result<Loaded, LoadError> {
    load_scene_with(path, &LoadOptions::default())
}

/// Loads a scene, choosing the loader by file extension; refuses materials no physics
/// allows (an index of refraction that is not a positive number), and warns about
/// triangles that will never be hit (no area, or non-finite corners) and instances whose
/// transform flattens them to nothing (a zero scale).
pub fn load_scene_with(path: &Path, options: &LoadOptions) -> Result<Loaded, LoadError> {
    let mut loaded = load_by_format(path, options)?;
    for material in &loaded.scene.materials {
        let ior = material.pbr.ior;
        if !(ior.is_finite() && ior > 0.0) {
            return Err(LoadError::Invalid {
                path: path.to_path_buf(),
                what: format!(
                    "material '{}': index of refraction {ior} is not a positive number",
                    material.name
                ),
            });
        }
    }
    for instance in &loaded.scene.instances {
        let m = instance.world_from_object;
        let finite = m.matrix3.is_finite() && m.translation.is_finite();
        // A zero scale along one axis may leave a visible flat mesh; along more, nothing.
        let flattened = finite
            && m.matrix3.determinant() == 0.0
            && loaded.scene.meshes.get(instance.mesh).is_some_and(|mesh| {
                mesh.indices.iter().all(|t| {
                    let [a, b, c] = t.map(|i| m.transform_point3(mesh.positions[i as usize]));
                    is_degenerate(a, b - a, c - a)
                })
            });
        if !finite || flattened {
            loaded.warnings.push(format!(
                "{}: {}: its transform is not finite or scales it to nothing; it can never be hit",
                path.display(),
                instance.source
            ));
        }
    }
    for mesh in &loaded.scene.meshes {
        let (mut non_finite, mut zero_area) = (0usize, 0usize);
        for &[a, b, c] in &mesh.indices {
            let [p0, p1, p2] = [a, b, c].map(|i| mesh.positions[i as usize]);
            if !(p0.is_finite() && p1.is_finite() && p2.is_finite()) {
                non_finite += 1;
            } else if is_degenerate(p0, p1 - p0, p2 - p0) {
                zero_area += 1;
            }
        }
        let reasons: Vec<String> = [
            (non_finite, "NaN or infinite corners"),
            (zero_area, "no area"),
        ]
        .iter()
        .filter(|(n, _)| *n > 0)
        .map(|(n, why)| format!("{n} triangle(s) with {why}"))
        .collect();
        if !reasons.is_empty() {
            loaded.warnings.push(format!(
                "{}: {}: skipping {} (they can never be hit)",
                path.display(),
                mesh.name,
                reasons.join(" and ")
            ));
        }
    }
    Ok(loaded)
}

fn load_by_format(path: &Path, options: &LoadOptions) -> Result<Loaded, LoadError> {
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().to_ascii_lowercase())
        .unwrap_or_default();
    let is_usd = [".usd", ".usda", ".usdc", ".usdz"]
        .iter()
        .any(|e| name.ends_with(e));
    let is_gltf = name.ends_with(".gltf") || name.ends_with(".glb");
    if options.frame.is_some() && !is_usd && !is_gltf {
        return Err(LoadError::Invalid {
            path: path.to_path_buf(),
            what: "a frame was asked for, but this format holds no animation".into(),
        });
    }
    if name.ends_with(".gltf") || name.ends_with(".glb") {
        gltf::load_with(path, options)
    } else if is_usd {
        usd::load_with(path, options)
    } else if name.ends_with(".ply") || name.ends_with(".ply.gz") {
        ply::load(path)
    } else {
        Err(LoadError::UnknownFormat {
            path: path.to_path_buf(),
        })
    }
}

/// The environment of a latitude–longitude map file named on the command line, oriented as
/// Blender's world shows it (see [`blender_world_rotation`]).
pub fn load_environment(path: &Path) -> Result<Environment, LoadError> {
    let map = load_environment_map(path)?;
    Ok(Environment::from_map(
        map,
        glam::Vec3::ONE,
        blender_world_rotation(0.0),
        format!("--environment {}", path.display()),
    ))
}

/// Reads a latitude–longitude environment map (`.hdr`, `.exr`, or an 8-bit image taken as
/// sRGB), within the memory budget.
pub fn load_environment_map(path: &Path) -> Result<EnvironmentMap, LoadError> {
    let name = path.display().to_string();
    let bytes =
        access::read_regular_file(path, &name, crate::limits::memory_left()).map_err(|e| {
            LoadError::Invalid {
                path: path.to_path_buf(),
                what: e.to_string(),
            }
        })?;
    images::decode_environment(name, &bytes).map_err(|why| LoadError::Invalid {
        path: path.to_path_buf(),
        what: format!("environment map {why}"),
    })
}
