//! USD (`.usda`, `.usdc`, `.usdz`) through the pure-Rust `openusd` crate: the composed stage
//! (references, payloads, variants as the crate composes them) is walked from its root
//! prims, and every renderable prim becomes scene data, named by its prim path.
//!
//! Units and axes: the stage's `upAxis` Z is turned to gridtrace's (and glTF's) Y-up with
//! (x, y, z) → (x, z, −y), and `metersPerUnit` scales to metres, so a Blender scene arrives
//! exactly as its glTF export does. Material mapping follows the glTF table (README):
//! `UsdPreviewSurface` `emissiveColor` → area light, `metallic` ≥ 0.5 → mirror, `opacity` <
//! 0.5 → glass with `ior`, else Lambertian `diffuseColor`.

use std::collections::HashMap;
use std::path::{Path, PathBuf};

use glam::{Mat4, Vec3};
use openusd::{sdf, usd};

mod camera;
mod crease;
mod implicit;
mod instancer;
mod light;
mod material;
mod mesh;
mod mtlx_layer;
mod mtlx_surface;
mod network;
mod probe;
mod resolver;
mod skel;
mod value;

use resolver::{ConfinedResolver, MAX_MISSING_LAYERS, Notes, Refusals, Skipped};
use value::{as_f64, as_token, value};

use super::{AssetRoots, LoadError, LoadOptions, Loaded};
use crate::record::Dependency;
use crate::scene::SceneBuilder;

/// Deepest prim hierarchy walked.
const MAX_DEPTH: usize = 256;

/// Segments of the polygon a `DiskLight` becomes.
const DISK_SEGMENTS: u32 = 48;

/// Composition errors warned about one by one; the rest are counted in one warning.
const SHOWN_COMPOSITION_ERRORS: usize = 10;

/// Loads a USD stage at its `startTimeCode` with default options; see [`load_with`].
pub fn load(path: &Path) -> Result<Loaded, LoadError> {
    load_with(path, &LoadOptions::default())
}

/// Loads a USD stage at time code `time` with default options; see [`load_with`].
pub fn load_at(path: &Path, time: Option<f64>) -> Result<Loaded, LoadError> {
    let options = LoadOptions {
        frame: time,
        ..LoadOptions::default()
    };
    load_with(path, &options)
}

/// Loads a USD stage as it is at time code `options.frame` (Blender writes frame
/// numbers), or at the stage's `startTimeCode` (0 if unauthored): every attribute with time
/// samples — transforms, points, camera and light settings — is evaluated there, held or
/// linearly interpolated as the stage says; attributes without samples read their default.
///
/// Every layer and texture is read through the file-access policy ([`AssetRoots`]); a
/// layer it refuses fails the load, naming the layer that asked and the path. The USD
/// reader is young third-party code: the whole composition is first read in a forked child
/// ([`probe::probe_stage`]), so an abort inside it becomes an error, and a panic inside it
/// becomes an error naming the file instead of taking the program down.
pub fn load_with(path: &Path, options: &LoadOptions) -> Result<Loaded, LoadError> {
    let roots = AssetRoots::for_scene(path, &options.asset_paths);
    let time = options.frame;
    crate::load::guard::catching_panics(|| {
        if !options.probed && probe::may_hold_binary_layers(path) {
            let times = std::iter::once(time).chain(options.probe_also_at.iter().map(|&t| Some(t)));
            probe::probe_stage(path, || {
                times
                    .into_iter()
                    .all(|t| read_stage(path, t, options, &roots).is_ok())
            })?;
        }
        read_stage(path, time, options, &roots)
    })
    .unwrap_or_else(|why| {
        Err(LoadError::Invalid {
            path: path.to_path_buf(),
            what: format!("the USD reader failed: {why}"),
        })
    })
}

fn read_stage(
    path: &Path,
    time: Option<f64>,
    options: &LoadOptions,
    roots: &AssetRoots,
) -> Result<Loaded, LoadError> {
    let invalid = |what: String| LoadError::Invalid {
        path: path.to_path_buf(),
        what,
    };
    let name = path
        .to_str()
        .ok_or_else(|| invalid("the path is not valid UTF-8".into()))?;
    if !path.is_file() {
        return Err(LoadError::Io {
            path: path.to_path_buf(),
            source: std::io::Error::new(std::io::ErrorKind::NotFound, "no such file"),
        });
    }
    let refused = Refusals::default();
    let skipped = Skipped::default();
    let notes = Notes::default();
    let refusal = |refused: &Refusals| {
        let first = refused.lock().ok()?.first().cloned()?;
        Some(invalid(first))
    };
    let stage = usd::Stage::builder()
        .resolver(ConfinedResolver::new(
            roots.clone(),
            refused.clone(),
            skipped.clone(),
            notes.clone(),
        ))
        .open(name)
        .map_err(|e| {
            refusal(&refused).unwrap_or_else(|| invalid(format!("cannot open USD stage: {e:#}")))
        })?;
    let time = usd::TimeCode::new(time.unwrap_or_else(|| stage.start_time_code()));
    let mut loader = UsdLoader {
        path: path.to_path_buf(),
        roots: roots.clone(),
        stage,
        time,
        subdivision_levels: options.subdivision_levels(),
        soft_falloff: !options.hard_falloff,
        builder: SceneBuilder::new(),
        materials: HashMap::new(),
        collections: HashMap::new(),
        collecting: None,
        placed_by_instancers: 0,
        default_material: None,
        one_sided: HashMap::new(),
        textures: HashMap::new(),
        texture_paths: Vec::new(),
        from_blender: false,
        warnings: Vec::new(),
        warned: std::collections::HashSet::new(),
    };
    // Blender signs its exports in the layer's `doc` ("Blender v5.0.1").
    loader.from_blender = loader
        .stage
        .stage_metadata("documentation")
        .ok()
        .flatten()
        .or_else(|| loader.stage.stage_metadata("doc").ok().flatten())
        .as_ref()
        .and_then(as_token)
        .is_some_and(|doc| doc.starts_with("Blender"));
    let root = loader.stage_correction();
    let roots = loader
        .stage
        .root_prims()
        .map_err(|e| invalid(format!("cannot list root prims: {e:#}")))?;
    for prim_name in roots {
        let prim = loader
            .stage
            .prim(format!("/{}", prim_name.as_str()).as_str());
        loader.visit(&prim, root, 0)?;
    }
    if let Some(error) = refusal(&refused) {
        return Err(error);
    }
    // Layers that could not be found or read drop their content: say so, the first few
    // one by one and the rest in one line.
    let errors = loader.stage.composition_errors();
    for error in errors.iter().take(SHOWN_COMPOSITION_ERRORS) {
        loader.warn(format!("{error}; its content is left out"));
    }
    if errors.len() > SHOWN_COMPOSITION_ERRORS {
        loader.warn(format!(
            "{} more composition errors like these; their content is left out",
            errors.len() - SHOWN_COMPOSITION_ERRORS
        ));
    }
    if let Ok(mut notes) = notes.lock() {
        for note in notes.drain(..) {
            loader.warnings.push(note);
        }
    }
    if let Ok(skipped) = skipped.lock()
        && let Some(first) = &skipped.first
    {
        loader.warn(format!(
            "{} more layers are missing past the first {MAX_MISSING_LAYERS} (the first of them @{first}@); they were not looked for and their content is left out",
            skipped.names.len()
        ));
    }
    // Layer identifiers are absolute; the stage's own file is not a dependency.
    let own = path.canonicalize().ok();
    let mut files: Vec<Dependency> = loader
        .stage
        .layer_identifiers()
        .into_iter()
        .map(|layer| PathBuf::from(mtlx_layer::document_of(&layer).unwrap_or(&layer)))
        .chain(loader.texture_paths)
        .filter(|file| file.is_file() && file.canonicalize().ok() != own)
        .map(Dependency::whole)
        .collect();
    files.sort();
    files.dedup();
    Ok(Loaded {
        scene: loader.builder.build(),
        warnings: loader.warnings,
        files,
        frame: Some(loader.time.value()),
    })
}

struct UsdLoader {
    path: PathBuf,
    /// The folders its layers and textures may be read from.
    roots: AssetRoots,
    stage: usd::Stage,
    /// When every attribute is read.
    time: usd::TimeCode,
    /// Levels subdivision surfaces are refined to.
    subdivision_levels: u32,
    /// `LoadOptions::soft_falloff`: sphere lamps of a Blender file shine as Cycles'
    /// Soft Falloff makes them.
    soft_falloff: bool,
    builder: SceneBuilder,
    /// Our material index for each bound USD material prim path.
    materials: HashMap<String, usize>,
    /// Meshes and transforms relative to a PointInstancer prototype's root, while one is
    /// being collected ([`UsdLoader::place`] puts them here instead of into the scene).
    collecting: Option<Vec<(usize, Mat4)>>,
    /// Instances point instancers have placed so far, held to the memory budget.
    placed_by_instancers: u64,
    /// Collection membership, computed once per collection.
    collections: network::Collections,
    default_material: Option<usize>,
    /// One-sided copies of materials, by the original's index.
    one_sided: HashMap<usize, usize>,
    /// Our texture for each image file tried (`None`: unreadable).
    textures: HashMap<String, Option<usize>>,
    /// The image files tried, as paths.
    texture_paths: Vec<PathBuf>,
    /// True for files Blender wrote, whose sun strengths follow Blender's convention.
    from_blender: bool,
    warnings: Vec<String>,
    /// Warnings given once however often their cause is met.
    warned: std::collections::HashSet<String>,
}

/// Any prim seen through the `Xformable` schema, whose `xformOpOrder` composition the crate
/// implements; a prim without ops gives the identity.
struct AnyXformable(usd::Prim);

impl usd::SchemaBase for AnyXformable {
    const KIND: usd::SchemaKind = usd::SchemaKind::ConcreteTyped;

    fn prim(&self) -> &usd::Prim {
        &self.0
    }
}

impl openusd::schemas::geom::Imageable for AnyXformable {}

impl openusd::schemas::geom::Xformable for AnyXformable {}

impl UsdLoader {
    fn warn(&mut self, what: String) {
        self.warnings
            .push(format!("{}: {what}", self.path.display()));
    }

    fn warn_once(&mut self, what: String) {
        if self.warned.insert(what.clone()) {
            self.warn(what);
        }
    }

    fn invalid(&self, what: String) -> LoadError {
        LoadError::Invalid {
            path: self.path.clone(),
            what,
        }
    }

    fn get(&self, prim: &sdf::Path, name: &str) -> Option<sdf::Value> {
        value(&self.stage, prim, name, self.time)
    }

    fn get_f32(&self, prim: &sdf::Path, name: &str) -> Option<f32> {
        self.get(prim, name)
            .as_ref()
            .and_then(as_f64)
            .map(|v| v as f32)
    }

    fn get_token(&self, prim: &sdf::Path, name: &str) -> Option<String> {
        self.get(prim, name).as_ref().and_then(as_token)
    }

    /// True when the stage says its up axis is Z.
    fn stage_up_is_z(&self) -> bool {
        self.stage
            .stage_metadata("upAxis")
            .ok()
            .flatten()
            .as_ref()
            .and_then(as_token)
            .is_some_and(|up| up == "Z")
    }

    /// The transform from stage space to gridtrace's: Y up, metres.
    fn stage_correction(&mut self) -> Mat4 {
        let up = self
            .stage
            .stage_metadata("upAxis")
            .ok()
            .flatten()
            .as_ref()
            .and_then(as_token)
            .unwrap_or_else(|| "Y".into());
        let meters = self
            .stage
            .stage_metadata("metersPerUnit")
            .ok()
            .flatten()
            .as_ref()
            .and_then(as_f64)
            .filter(|m| m.is_finite() && *m > 0.0)
            .unwrap_or(0.01) as f32;
        let axes = match up.as_str() {
            "Z" => Mat4::from_rotation_x(-std::f32::consts::FRAC_PI_2),
            "Y" => Mat4::IDENTITY,
            other => {
                self.warn(format!("upAxis '{other}' is not Y or Z; treating it as Y"));
                Mat4::IDENTITY
            }
        };
        Mat4::from_scale(Vec3::splat(meters)) * axes
    }

    /// The prim's local-to-parent transform (its `xformOpOrder` stack), or `None` when the
    /// stack resets the parent's.
    fn local_transform(&mut self, prim: &usd::Prim) -> Result<(Mat4, bool), LoadError> {
        use openusd::schemas::geom::Xformable;
        let xform = AnyXformable(prim.clone());
        let m = xform
            .local_to_parent_transform(self.time)
            .map_err(|e| self.invalid(format!("{}: {e:#}", prim.path().as_str())))?;
        let resets = xform.resets_xform_stack().unwrap_or(false);
        // USD's row-vector matrices, stored row by row, are glam's column-vector matrices
        // stored column by column.
        let local = Mat4::from_cols_array(&m.0.map(|v| v as f32));
        Ok((local, resets))
    }

    pub(super) fn visit(
        &mut self,
        prim: &usd::Prim,
        parent: Mat4,
        depth: usize,
    ) -> Result<(), LoadError> {
        let path = prim.path().clone();
        let where_ = path.as_str().to_string();
        if depth > MAX_DEPTH {
            // The path itself would be hundreds of names long: show its ends.
            let names: Vec<&str> = where_.split('/').filter(|n| !n.is_empty()).collect();
            let short = format!("/{}/…/{}", names[0], names[names.len() - 1]);
            return Err(self.invalid(format!("{short}: prim hierarchy deeper than {MAX_DEPTH}")));
        }
        // Only defined, concrete prims are drawn: an `over` (a flattened stage's
        // prototypes) and an abstract `class` are not, with their subtrees, as
        // `Usd.PrimRange`'s default predicate has it.
        if !prim.is_active().unwrap_or(true)
            || (!prim.is_defined().unwrap_or(true) && self.collecting.is_none())
            || prim.is_abstract().unwrap_or(false)
        {
            return Ok(());
        }
        if self.get_token(&path, "visibility").as_deref() == Some("invisible") {
            return Ok(());
        }
        if matches!(
            self.get_token(&path, "purpose").as_deref(),
            Some("proxy" | "guide")
        ) {
            return Ok(());
        }
        let type_name = prim
            .type_name()
            .ok()
            .flatten()
            .map(|t| t.as_str().to_string())
            .unwrap_or_default();
        if matches!(
            type_name.as_str(),
            "Material" | "Shader" | "NodeGraph" | "GeomSubset"
        ) {
            return Ok(());
        }
        let (local, resets) = self.local_transform(prim)?;
        let world = if resets {
            self.stage_correction() * local
        } else {
            parent * local
        };
        if !world.is_finite() {
            return Err(self.invalid(format!("{where_}: non-finite transform")));
        }
        let in_prototype = self.collecting.is_some();
        match type_name.as_str() {
            "Mesh" => self.add_mesh(prim, world)?,
            "Sphere" | "Cube" | "Cylinder" | "Cylinder_1" | "Cone" | "Capsule" | "Capsule_1"
            | "Plane" => {
                if let Some(polygons) = self.read_implicit(prim, &type_name) {
                    let meshes = self.emit(&where_, &polygons);
                    self.place(&meshes, world, &where_);
                }
            }
            "PointInstancer" => {
                // Its children are prototypes, drawn only where it places them.
                return self.add_instancer(prim, world, depth);
            }
            "Camera" | "RectLight" | "DiskLight" | "SphereLight" | "DistantLight" | "DomeLight"
            | "DomeLight_1"
                if in_prototype =>
            {
                self.warn(format!(
                    "{where_}: {type_name} inside a PointInstancer prototype is not instanced; skipped"
                ))
            }
            "Camera" => self.add_camera(&path, world),
            "RectLight" | "DiskLight" | "SphereLight" | "DistantLight" => {
                self.add_light(&path, &type_name, world)
            }
            "DomeLight" | "DomeLight_1" => self.add_dome(&path, world),
            "" | "Xform" | "Scope" | "SkelRoot" => {}
            "Points" | "BasisCurves" | "NurbsCurves" | "NurbsPatch" | "HermiteCurves"
            | "TetMesh" | "Volume" => self.warn(format!(
                "{where_}: {type_name} prims are not supported; skipped"
            )),
            _ => {}
        }
        let children = prim
            .children()
            .map_err(|e| self.invalid(format!("{where_}: {e:#}")))?;
        for child in children {
            self.visit(&child, world, depth + 1)?;
        }
        Ok(())
    }
}
