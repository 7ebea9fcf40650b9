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

use glam::{Affine2, Affine3A, Mat4, Vec2, Vec3};
use openusd::{sdf, usd};

mod probe;
mod resolver;

use resolver::{ConfinedResolver, Refusals};

use super::access::read_regular_file;
use super::images::decode_texture;
use super::polygon::triangulate;
use super::tangents::generate_tangents;
use super::{AssetRoots, LoadError, LoadOptions, Loaded};
use crate::limits::memory_budget;
use crate::record::Dependency;
use crate::scene::{
    AlphaMode, Camera, ColorSpace, Light, LightKind, Material, MaterialKind, MaterialTextures,
    Mesh, Projection, SceneBuilder, TextureRef, Wrap,
};

/// Deepest prim hierarchy walked.
const MAX_DEPTH: usize = 256;

/// Segments of the polygon a `DiskLight` becomes.
const DISK_SEGMENTS: u32 = 48;

/// Loads a USD stage at its `startTimeCode` with default options; see [`load_with`].
pub fn load(path: &Path) -> Result<Loaded, LoadError> {
    load_with(path, &LoadOptions::default())
}

/// Loads a USD stage at time code `time` with default options; see [`load_with`].
pub fn load_at(path: &Path, time: Option<f64>) -> Result<Loaded, LoadError> {
    let options = LoadOptions {
        usd_frame: time,
        ..LoadOptions::default()
    };
    load_with(path, &options)
}

/// Loads a USD stage as it is at time code `options.usd_frame` (Blender writes frame
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
    let time = options.usd_frame;
    std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
        if probe::may_hold_binary_layers(path) {
            probe::probe_stage(path, || read_stage(path, time, &roots).is_ok())?;
        }
        read_stage(path, time, &roots)
    }))
    .unwrap_or_else(|panic| {
        let why = panic
            .downcast_ref::<String>()
            .map(String::as_str)
            .or_else(|| panic.downcast_ref::<&str>().copied())
            .unwrap_or("unknown failure");
        Err(LoadError::Invalid {
            path: path.to_path_buf(),
            what: format!("the USD reader failed: {why}"),
        })
    })
}

fn read_stage(path: &Path, time: Option<f64>, roots: &AssetRoots) -> Result<Loaded, LoadError> {
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
    let refusal = |refused: &Refusals| {
        let first = refused.lock().ok()?.first().cloned()?;
        Some(invalid(first))
    };
    let stage = usd::Stage::builder()
        .resolver(ConfinedResolver::new(roots.clone(), refused.clone()))
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
        builder: SceneBuilder::new(),
        materials: HashMap::new(),
        default_material: None,
        one_sided: HashMap::new(),
        textures: HashMap::new(),
        texture_paths: Vec::new(),
        from_blender: false,
        warnings: Vec::new(),
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
    // Layers that could not be found or read drop their content: say so.
    for error in loader.stage.composition_errors() {
        loader.warn(format!("{error}; its content is left out"));
    }
    // Layer identifiers are absolute; the stage's own file is not a dependency.
    let own = path.canonicalize().ok();
    let mut files: Vec<Dependency> = loader
        .stage
        .layer_identifiers()
        .into_iter()
        .map(PathBuf::from)
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
    })
}

struct UsdLoader {
    path: PathBuf,
    /// The folders its layers and textures may be read from.
    roots: AssetRoots,
    stage: usd::Stage,
    /// When every attribute is read.
    time: usd::TimeCode,
    builder: SceneBuilder,
    /// Our material index for each bound USD material prim path.
    materials: HashMap<String, usize>,
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

/// A value read from the stage at `time`, whatever its precision.
fn value(
    stage: &usd::Stage,
    prim: &sdf::Path,
    name: &str,
    time: usd::TimeCode,
) -> Option<sdf::Value> {
    let path = prim.append_property(name).ok()?;
    stage
        .attribute(path)
        .get_at::<sdf::Value>(time)
        .ok()
        .flatten()
}

/// A scalar as f64. Whole numbers count: openusd 0.6 reads a `.usda` time sample written
/// `50` as an Int64 whatever the attribute's declared type.
fn as_f64(v: &sdf::Value) -> Option<f64> {
    match v {
        sdf::Value::Double(d) => Some(*d),
        sdf::Value::Float(f) => Some(*f as f64),
        sdf::Value::Half(h) => Some(h.to_f32() as f64),
        sdf::Value::Int(i) => Some(*i as f64),
        sdf::Value::Int64(i) => Some(*i as f64),
        _ => None,
    }
}

fn as_vec3(v: &sdf::Value) -> Option<Vec3> {
    match v {
        sdf::Value::Vec3f(a) => Some(Vec3::new(a.x, a.y, a.z)),
        sdf::Value::Vec3d(a) => Some(Vec3::new(a.x as f32, a.y as f32, a.z as f32)),
        sdf::Value::Vec3h(a) => Some(Vec3::new(a.x.to_f32(), a.y.to_f32(), a.z.to_f32())),
        _ => None,
    }
}

fn as_vec3s(v: &sdf::Value) -> Option<Vec<Vec3>> {
    match v {
        sdf::Value::Vec3fVec(a) => Some(a.iter().map(|a| Vec3::new(a.x, a.y, a.z)).collect()),
        sdf::Value::Vec3dVec(a) => Some(
            a.iter()
                .map(|a| Vec3::new(a.x as f32, a.y as f32, a.z as f32))
                .collect(),
        ),
        sdf::Value::Vec3hVec(a) => Some(
            a.iter()
                .map(|a| Vec3::new(a.x.to_f32(), a.y.to_f32(), a.z.to_f32()))
                .collect(),
        ),
        _ => None,
    }
}

fn as_vec2s(v: &sdf::Value) -> Option<Vec<Vec2>> {
    match v {
        sdf::Value::Vec2fVec(a) => Some(a.iter().map(|a| Vec2::new(a.x, a.y)).collect()),
        sdf::Value::Vec2dVec(a) => Some(
            a.iter()
                .map(|a| Vec2::new(a.x as f32, a.y as f32))
                .collect(),
        ),
        _ => None,
    }
}

fn as_ints(v: &sdf::Value) -> Option<Vec<i64>> {
    match v {
        sdf::Value::IntVec(a) => Some(a.iter().map(|&i| i as i64).collect()),
        sdf::Value::Int64Vec(a) => Some(a.clone()),
        sdf::Value::UintVec(a) => Some(a.iter().map(|&i| i as i64).collect()),
        _ => None,
    }
}

fn as_token(v: &sdf::Value) -> Option<String> {
    match v {
        sdf::Value::Token(t) => Some(t.as_str().to_string()),
        sdf::Value::String(s) => Some(s.clone()),
        _ => None,
    }
}

fn as_bool(v: &sdf::Value) -> Option<bool> {
    match v {
        sdf::Value::Bool(b) => Some(*b),
        sdf::Value::Int(i) => Some(*i != 0),
        _ => None,
    }
}

/// How a primvar's values map onto a mesh (UsdGeom primvar interpolation).
#[derive(Clone, Copy, Debug, PartialEq)]
enum Interpolation {
    /// One value for the whole mesh.
    Constant,
    /// One value per face.
    Uniform,
    /// One value per point.
    Vertex,
    /// One value per face corner.
    FaceVarying,
}

impl UsdLoader {
    fn warn(&mut self, what: String) {
        self.warnings
            .push(format!("{}: {what}", self.path.display()));
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

    fn visit(&mut self, prim: &usd::Prim, parent: Mat4, depth: usize) -> Result<(), LoadError> {
        let path = prim.path().clone();
        let where_ = path.as_str().to_string();
        if depth > MAX_DEPTH {
            return Err(self.invalid(format!("{where_}: prim hierarchy deeper than {MAX_DEPTH}")));
        }
        if !prim.is_active().unwrap_or(true) {
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
        match type_name.as_str() {
            "Mesh" => self.add_mesh(prim, world)?,
            "Camera" => self.add_camera(&path, world),
            "RectLight" | "DiskLight" | "SphereLight" | "DistantLight" => {
                self.add_light(&path, &type_name, world)
            }
            "DomeLight" => self.add_dome(&path),
            "" | "Xform" | "Scope" | "SkelRoot" => {}
            "Sphere" | "Cube" | "Cylinder" | "Cone" | "Capsule" | "Plane" | "Points"
            | "BasisCurves" | "NurbsCurves" | "NurbsPatch" | "PointInstancer" | "Volume" => self
                .warn(format!(
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

    /// A primvar (or the `normals` attribute) and its interpolation.
    fn primvar<T>(
        &self,
        prim: &sdf::Path,
        name: &str,
        convert: impl Fn(&sdf::Value) -> Option<Vec<T>>,
        default: Interpolation,
    ) -> Option<(Vec<T>, Interpolation)>
    where
        T: Copy,
    {
        let attr_path = prim.append_property(name).ok()?;
        let attribute = self.stage.attribute(attr_path);
        let raw = attribute.get_at::<sdf::Value>(self.time).ok().flatten()?;
        let mut values = convert(&raw)?;
        // Indexed primvars: values[indices[i]].
        if let Some(indices) = self
            .get(prim, &format!("{name}:indices"))
            .as_ref()
            .and_then(as_ints)
        {
            let mut expanded = Vec::with_capacity(indices.len());
            for i in indices {
                expanded.push(*values.get(usize::try_from(i).ok()?)?);
            }
            values = expanded;
        }
        let interpolation = match attribute
            .get_metadata::<sdf::Value>("interpolation")
            .ok()
            .flatten()
            .as_ref()
            .and_then(as_token)
            .as_deref()
        {
            Some("constant") => Interpolation::Constant,
            Some("uniform") => Interpolation::Uniform,
            Some("vertex") | Some("varying") => Interpolation::Vertex,
            Some("faceVarying") => Interpolation::FaceVarying,
            _ => default,
        };
        Some((values, interpolation))
    }

    fn add_mesh(&mut self, prim: &usd::Prim, world: Mat4) -> Result<(), LoadError> {
        let path = prim.path().clone();
        let where_ = path.as_str().to_string();
        let points = self
            .get(&path, "points")
            .as_ref()
            .and_then(as_vec3s)
            .unwrap_or_default();
        let counts = self
            .get(&path, "faceVertexCounts")
            .as_ref()
            .and_then(as_ints)
            .unwrap_or_default();
        let indices = self
            .get(&path, "faceVertexIndices")
            .as_ref()
            .and_then(as_ints)
            .unwrap_or_default();
        if points.is_empty() || counts.is_empty() {
            return Ok(());
        }
        if let Some((face, &count)) = counts.iter().enumerate().find(|(_, c)| **c < 0) {
            return Err(self.invalid(format!(
                "{where_}: faceVertexCounts[{face}] is {count}, a negative corner count"
            )));
        }
        let total: i128 = counts.iter().map(|&c| i128::from(c)).sum();
        if total != indices.len() as i128 {
            return Err(self.invalid(format!(
                "{where_}: faceVertexCounts add up to {total} but there are {} faceVertexIndices",
                indices.len()
            )));
        }
        if let Some(&bad) = indices
            .iter()
            .find(|&&i| i < 0 || i as usize >= points.len())
        {
            return Err(self.invalid(format!(
                "{where_}: face vertex index {bad} is outside the {} points",
                points.len()
            )));
        }
        if let Some(scheme) = self.get_token(&path, "subdivisionScheme")
            && scheme != "none"
        {
            self.warn(format!(
                "{where_}: subdivisionScheme '{scheme}' is rendered as its control cage (no subdivision)"
            ));
        }
        let left_handed = self.get_token(&path, "orientation").as_deref() == Some("leftHanded");
        let double_sided = self
            .get(&path, "doubleSided")
            .as_ref()
            .and_then(as_bool)
            .unwrap_or(false);
        let normals = self
            .primvar(&path, "primvars:normals", as_vec3s, Interpolation::Vertex)
            .or_else(|| self.primvar(&path, "normals", as_vec3s, Interpolation::Vertex));
        let uvs = self.primvar(&path, "primvars:st", as_vec2s, Interpolation::FaceVarying);

        // Each face's first corner (into faceVertexIndices) and corner count.
        let mut face_start = Vec::with_capacity(counts.len());
        let mut start = 0usize;
        for &c in &counts {
            face_start.push(start);
            start += c as usize;
        }
        // Which material each face uses: GeomSubsets of the materialBind family override the
        // mesh's own binding.
        let mesh_material = self.bound_material(&path);
        let mut face_material = vec![mesh_material; counts.len()];
        for child in prim
            .children()
            .map_err(|e| self.invalid(format!("{where_}: {e:#}")))?
        {
            let child_path = child.path().clone();
            let is_subset = child
                .type_name()
                .ok()
                .flatten()
                .is_some_and(|t| t.as_str() == "GeomSubset");
            if !is_subset
                || self.get_token(&child_path, "familyName").as_deref() != Some("materialBind")
            {
                continue;
            }
            let material = self.bound_material(&child_path);
            for face in self
                .get(&child_path, "indices")
                .as_ref()
                .and_then(as_ints)
                .unwrap_or_default()
            {
                if let Some(slot) = usize::try_from(face)
                    .ok()
                    .and_then(|f| face_material.get_mut(f))
                {
                    *slot = material;
                }
            }
        }

        // Triangulate each face into corners (indices into faceVertexIndices).
        let mut by_material: HashMap<usize, Vec<[usize; 3]>> = HashMap::new();
        for (face, &count) in counts.iter().enumerate() {
            let first = face_start[face];
            let corners: Vec<usize> = (first..first + count as usize).collect();
            let polygon: Vec<Vec3> = corners
                .iter()
                .map(|&c| points[indices[c] as usize])
                .collect();
            for [a, b, c] in triangulate(&polygon) {
                let tri = [corners[a], corners[b], corners[c]];
                let tri = if left_handed {
                    [tri[0], tri[2], tri[1]]
                } else {
                    tri
                };
                by_material
                    .entry(face_material[face])
                    .or_default()
                    .push(tri);
            }
        }
        let corner_face: Vec<usize> = counts
            .iter()
            .enumerate()
            .flat_map(|(f, &c)| std::iter::repeat_n(f, c as usize))
            .collect();
        // The value a primvar gives face corner `corner`.
        fn pick<T: Copy>(
            values: &[T],
            interpolation: Interpolation,
            corner: usize,
            face: usize,
            point: usize,
        ) -> Option<T> {
            match interpolation {
                Interpolation::Constant => values.first().copied(),
                Interpolation::Uniform => values.get(face).copied(),
                Interpolation::Vertex => values.get(point).copied(),
                Interpolation::FaceVarying => values.get(corner).copied(),
            }
        }
        let transform = Affine3A::from_mat4(world);
        let mut materials: Vec<(usize, Vec<[usize; 3]>)> = by_material.into_iter().collect();
        materials.sort_by_key(|(m, _)| *m);
        for (material, triangles) in materials {
            // One vertex per triangle corner: normals and UVs may differ at every corner.
            let mut mesh = Mesh {
                name: where_.clone(),
                material,
                ..Mesh::default()
            };
            let mut normals_ok = normals.is_some();
            let mut st = Vec::new();
            for (t, tri) in triangles.iter().enumerate() {
                for &corner in tri {
                    let (face, point) = (corner_face[corner], indices[corner] as usize);
                    mesh.positions.push(points[point]);
                    if let Some((values, interpolation)) = &normals {
                        match pick(values, *interpolation, corner, face, point) {
                            Some(n) => mesh.normals.push(n.normalize_or_zero()),
                            None => normals_ok = false,
                        }
                    }
                    if let Some((values, interpolation)) = &uvs {
                        let v = pick(values, *interpolation, corner, face, point);
                        // USD's st has v up the image; glTF's (and ours) runs down.
                        st.push(v.map_or(Vec2::ZERO, |v| Vec2::new(v.x, 1.0 - v.y)));
                    }
                }
                let base = 3 * t as u32;
                mesh.indices.push([base, base + 1, base + 2]);
            }
            if !normals_ok || mesh.normals.contains(&Vec3::ZERO) {
                mesh.normals.clear();
            }
            if !st.is_empty() {
                mesh.uvs = vec![st];
            }
            if !double_sided {
                mesh.material = self.one_sided(material);
            }
            if self
                .builder
                .material_mut(material)
                .textures
                .normal
                .is_some()
                && !generate_tangents(&mut mesh, 0)
            {
                self.warn(format!(
                    "{where_}: a normal map needs primvars:st, which is missing; ignored here"
                ));
            }
            let index = self.builder.add_full_mesh(mesh);
            self.builder.add_instance(index, transform, where_.clone());
        }
        Ok(())
    }

    /// The one-sided variant of material `index`, made once. UsdGeom's `doubleSided` (false
    /// by default; Blender writes true) belongs to the mesh, gridtrace's to the material:
    /// one-sided means what it does for glTF (a black back face), except for glass, whose
    /// back faces are the inside of its volume.
    fn one_sided(&mut self, index: usize) -> usize {
        if let Some(&variant) = self.one_sided.get(&index) {
            return variant;
        }
        let mut material = self.builder.material_mut(index).clone();
        let variant = if matches!(material.kind, MaterialKind::Glass { .. }) {
            index
        } else {
            material.double_sided = false;
            material.name = format!("{} (one-sided)", material.name);
            self.builder.add_material(material)
        };
        self.one_sided.insert(index, variant);
        variant
    }

    /// The material bound to `prim` (`material:binding`), converted once per material.
    fn bound_material(&mut self, prim: &sdf::Path) -> usize {
        let target = prim
            .append_property("material:binding")
            .ok()
            .and_then(|rel| self.stage.relationship(rel).targets().ok())
            .and_then(|t| t.into_iter().next());
        let Some(target) = target else {
            return self.default_material();
        };
        let key = target.as_str().to_string();
        if let Some(&m) = self.materials.get(&key) {
            return m;
        }
        let material = self.convert_material(&target);
        let index = self.builder.add_material(material);
        self.materials.insert(key, index);
        index
    }

    fn default_material(&mut self) -> usize {
        if let Some(m) = self.default_material {
            return m;
        }
        let m = self
            .builder
            .add_material(Material::diffuse("default", Vec3::splat(0.8)));
        self.default_material = Some(m);
        m
    }

    /// A `UsdPreviewSurface` material, mapped as glTF's are.
    fn convert_material(&mut self, material: &sdf::Path) -> Material {
        let name = material.as_str().to_string();
        let surface = self.connected_prim(material, "outputs:surface");
        let Some(shader) = surface else {
            self.warn(format!(
                "{name}: material has no surface shader; using grey diffuse"
            ));
            return Material::diffuse(name, Vec3::splat(0.8));
        };
        let id = self.get_token(&shader, "info:id").unwrap_or_default();
        if id != "UsdPreviewSurface" {
            self.warn(format!(
                "{name}: surface shader '{id}' is not UsdPreviewSurface; using grey diffuse"
            ));
            return Material::diffuse(name, Vec3::splat(0.8));
        }
        let mut textures = MaterialTextures {
            metallic_factor: 0.0,
            normal_scale: 1.0,
            ..MaterialTextures::default()
        };
        // A connected input is a texture (its scale as the factor); else a constant.
        let diffuse =
            match self.texture_input(&shader, "inputs:diffuseColor", ColorSpace::Srgb, &name) {
                Some((r, scale)) => {
                    textures.base_colour = Some(r);
                    scale
                }
                None => self.constant_colour(&shader, "inputs:diffuseColor", Vec3::splat(0.18)),
            };
        let emission =
            match self.texture_input(&shader, "inputs:emissiveColor", ColorSpace::Srgb, &name) {
                Some((r, scale)) => {
                    textures.emissive = Some(r);
                    scale
                }
                None => self.constant_colour(&shader, "inputs:emissiveColor", Vec3::ZERO),
            };
        if let Some((r, _)) =
            self.texture_input(&shader, "inputs:normal", ColorSpace::Linear, &name)
        {
            textures.normal = Some(r);
        }
        let mut alpha_mode = AlphaMode::Opaque;
        let mut opacity = self.get_f32(&shader, "inputs:opacity").unwrap_or(1.0);
        if let Some((r, _)) =
            self.texture_input(&shader, "inputs:opacity", ColorSpace::Linear, &name)
        {
            // Opacity from a texture's alpha (Blender's wiring) cuts out at the threshold,
            // or blends without one. The base-colour texture carries that alpha here.
            if textures.base_colour.is_none_or(|b| b.texture == r.texture) {
                textures.base_colour.get_or_insert(r);
                let threshold = self
                    .get_f32(&shader, "inputs:opacityThreshold")
                    .unwrap_or(0.0);
                alpha_mode = if threshold > 0.0 {
                    AlphaMode::Mask { cutoff: threshold }
                } else {
                    AlphaMode::Blend
                };
            } else {
                self.warn(format!(
                    "{name}: opacity from a texture other than the diffuse one is not supported"
                ));
            }
            opacity = 1.0;
        }
        let metallic = self.constant_scalar(&shader, "inputs:metallic", 0.0, &name);
        let ior = self.constant_scalar(&shader, "inputs:ior", 1.5, &name);
        let roughness = self.constant_scalar(&shader, "inputs:roughness", 0.5, &name);
        let kind = if opacity < 0.5 {
            MaterialKind::Glass { ior, tint: diffuse }
        } else if metallic >= 0.5 {
            MaterialKind::Mirror {
                reflectance: diffuse,
            }
        } else {
            MaterialKind::Diffuse { albedo: diffuse }
        };
        if !matches!(kind, MaterialKind::Diffuse { .. }) && roughness > 0.05 {
            self.warn(format!(
                "{name}: roughness {roughness} is rendered as perfectly smooth (gridtrace's mirror and glass are ideal)"
            ));
        }
        Material {
            emission,
            textures,
            alpha_mode,
            ..Material::new(name, kind)
        }
    }

    fn constant_colour(&mut self, shader: &sdf::Path, input: &str, default: Vec3) -> Vec3 {
        self.get(shader, input)
            .as_ref()
            .and_then(as_vec3)
            .unwrap_or(default)
    }

    fn constant_scalar(
        &mut self,
        shader: &sdf::Path,
        input: &str,
        default: f32,
        material: &str,
    ) -> f32 {
        self.warn_if_connected(shader, input, material);
        self.get_f32(shader, input).unwrap_or(default)
    }

    /// The `UsdUVTexture` feeding `input`, as a texture reference and the colour factor its
    /// `scale` gives; `None` when the input is not connected (or cannot be used, with a
    /// warning). The texture's `st` may pass through a `UsdTransform2d` and comes from a
    /// `UsdPrimvarReader_float2` of `st` (the set the loader reads).
    fn texture_input(
        &mut self,
        shader: &sdf::Path,
        input: &str,
        space: ColorSpace,
        material: &str,
    ) -> Option<(TextureRef, Vec3)> {
        let node = self.connected_prim(shader, input)?;
        if self.get_token(&node, "info:id").as_deref() != Some("UsdUVTexture") {
            self.warn(format!(
                "{material}: {input} is connected to something other than a UsdUVTexture; ignored"
            ));
            return None;
        }
        let file = match self.get(&node, "inputs:file") {
            Some(sdf::Value::AssetPath(a)) => a.authored_path.clone(),
            _ => {
                self.warn(format!(
                    "{material}: {input}'s texture has no file; ignored"
                ));
                return None;
            }
        };
        let texture = self.texture_file(&file, material)?;
        if matches!(space, ColorSpace::Srgb)
            && self.get_token(&node, "inputs:sourceColorSpace").as_deref() == Some("raw")
        {
            self.warn(format!(
                "{material}: {input} reads '{file}' as raw data; treated as sRGB colour"
            ));
        }
        let scale = match self.get(&node, "inputs:scale") {
            Some(sdf::Value::Vec4f(v)) => Vec3::new(v.x, v.y, v.z),
            _ => Vec3::ONE,
        };
        let wrap = |mode: Option<String>| match mode.as_deref() {
            Some("clamp") => Wrap::ClampToEdge,
            Some("mirror") => Wrap::MirroredRepeat,
            _ => Wrap::Repeat,
        };
        let mut reference = TextureRef::new(texture);
        reference.wrap_u = wrap(self.get_token(&node, "inputs:wrapS"));
        reference.wrap_v = wrap(self.get_token(&node, "inputs:wrapT"));
        // USD's st has v up the image, ours down: uv → st → UsdTransform2d → uv.
        let flip = Affine2::from_cols(Vec2::X, Vec2::NEG_Y, Vec2::Y);
        let st = self.connected_prim(&node, "inputs:st");
        if let Some(st) = st
            && self.get_token(&st, "info:id").as_deref() == Some("UsdTransform2d")
        {
            let scale = match self.get(&st, "inputs:scale") {
                Some(sdf::Value::Vec2f(v)) => Vec2::new(v.x, v.y),
                _ => Vec2::ONE,
            };
            let translation = match self.get(&st, "inputs:translation") {
                Some(sdf::Value::Vec2f(v)) => Vec2::new(v.x, v.y),
                _ => Vec2::ZERO,
            };
            let rotation = self
                .get_f32(&st, "inputs:rotation")
                .unwrap_or(0.0)
                .to_radians();
            let transform = Affine2::from_scale_angle_translation(scale, rotation, translation);
            reference.transform = flip * transform * flip;
        }
        let factor = if matches!(space, ColorSpace::Srgb) {
            scale
        } else {
            Vec3::ONE
        };
        Some((reference, factor))
    }

    /// The scene texture of an image file relative to the stage, decoded once.
    fn texture_file(&mut self, file: &str, material: &str) -> Option<usize> {
        if let Some(&known) = self.textures.get(file) {
            return known;
        }
        let base = self.path.parent().unwrap_or(Path::new("."));
        let bytes = self.roots.resolve(base, file).and_then(|full| {
            self.texture_paths.push(full.clone());
            read_regular_file(&full, file, memory_budget())
        });
        let decoded = match bytes.map_err(|e| e.to_string()).and_then(|bytes| {
            decode_texture(file.to_string(), &bytes).map_err(|e| format!("'{file}' {e}"))
        }) {
            Ok(texture) => Some(self.builder.add_texture(texture)),
            Err(why) => {
                self.warn(format!(
                    "{material}: texture {why}; using a neutral texture"
                ));
                None
            }
        };
        self.textures.insert(file.to_string(), decoded);
        decoded
    }

    /// The prim whose output feeds `property` of `prim` (its first connection), if any.
    fn connected_prim(&self, prim: &sdf::Path, property: &str) -> Option<sdf::Path> {
        let attribute = self.stage.attribute(prim.append_property(property).ok()?);
        let source = attribute.connections().ok()?.into_iter().next()?;
        Some(source.prim_path())
    }

    /// Networks feeding a scalar input are not read: say so.
    fn warn_if_connected(&mut self, shader: &sdf::Path, input: &str, material: &str) {
        if self.connected_prim(shader, input).is_some() {
            self.warn(format!(
                "{material}: {input} is connected to a shader network (textures are not read from USD yet); using its constant value"
            ));
        }
    }

    /// A UsdLux light's `intensity × 2^exposure × color`, tinted by its colour temperature
    /// when enabled.
    fn light_strength(&self, prim: &sdf::Path) -> Vec3 {
        let intensity = self.get_f32(prim, "inputs:intensity").unwrap_or(1.0);
        let exposure = self.get_f32(prim, "inputs:exposure").unwrap_or(0.0);
        let colour = self
            .get(prim, "inputs:color")
            .as_ref()
            .and_then(as_vec3)
            .unwrap_or(Vec3::ONE);
        // Colour temperature tints relative to 6500 K, USD's default white point, which
        // Blender writes on every light and Cycles renders white.
        let enabled = self
            .get(prim, "inputs:enableColorTemperature")
            .as_ref()
            .and_then(as_bool);
        let colour = if enabled == Some(true) {
            let kelvin = self
                .get_f32(prim, "inputs:colorTemperature")
                .unwrap_or(6500.0);
            colour * blackbody_tint(kelvin)
        } else {
            colour
        };
        colour * intensity * exposure.exp2()
    }

    /// A `DomeLight` of constant colour: radiance intensity × 2^exposure × color from every
    /// direction the scene leaves open. A texture (an environment map) is not read.
    fn add_dome(&mut self, prim: &sdf::Path) {
        let where_ = prim.as_str();
        let radiance = self.light_strength(prim);
        if self.get(prim, "inputs:texture:file").is_some() {
            self.warn(format!(
                "{where_}: DomeLight texture maps are not supported; using its constant colour"
            ));
        }
        if radiance.is_finite() && radiance.min_element() >= 0.0 {
            self.builder.add_environment(radiance);
        } else {
            self.warn(format!(
                "{where_}: negative or non-finite dome light; skipped"
            ));
        }
    }

    fn add_camera(&mut self, prim: &sdf::Path, world: Mat4) {
        let where_ = prim.as_str().to_string();
        // Apertures and focal length share a unit (tenths of a scene unit), so their ratio
        // is the field of view; the defaults are USD's.
        let focal = self.get_f32(prim, "focalLength").unwrap_or(50.0);
        let horizontal = self.get_f32(prim, "horizontalAperture").unwrap_or(20.955);
        let vertical = self.get_f32(prim, "verticalAperture").unwrap_or(15.2908);
        let znear = match self.get(prim, "clippingRange") {
            Some(sdf::Value::Vec2f(r)) => r.x,
            Some(sdf::Value::Vec2d(r)) => r.x as f32,
            _ => 1.0,
        };
        let (scale, rotation, translation) = world.to_scale_rotation_translation();
        let projection = if self.get_token(prim, "projection").as_deref() == Some("orthographic") {
            // Apertures in tenths of a scene unit, here after the stage's scale.
            Projection::Orthographic {
                xmag: 0.05 * horizontal * scale.x,
                ymag: 0.05 * vertical * scale.y,
            }
        } else {
            if !(focal > 0.0 && vertical > 0.0 && horizontal > 0.0) {
                self.warn(format!(
                    "{where_}: camera with zero focal length or aperture; skipped"
                ));
                return;
            }
            Projection::Perspective {
                yfov: 2.0 * (0.5 * vertical / focal).atan(),
                aspect_ratio: Some(horizontal / vertical),
            }
        };
        self.builder.add_camera(Camera {
            name: where_.clone(),
            world_from_camera: Affine3A::from_rotation_translation(
                rotation.normalize(),
                translation,
            ),
            projection,
            znear: znear * scale.y,
            source: where_,
        });
    }

    /// UsdLux lights. Radiance (area lights) or radiant intensity (points) is
    /// `intensity × 2^exposure × color`; `normalize` divides by the light's area, so that
    /// the power (π × radiance × area) stays `π × intensity` whatever its size — which is
    /// how Blender writes watts (intensity = W/π).
    fn add_light(&mut self, prim: &sdf::Path, kind: &str, world: Mat4) {
        let where_ = prim.as_str().to_string();
        let normalize = self
            .get(prim, "inputs:normalize")
            .as_ref()
            .and_then(as_bool)
            .unwrap_or(false);
        let strength = self.light_strength(prim);
        if !strength.is_finite() || strength.min_element() < 0.0 {
            self.warn(format!(
                "{where_}: negative or non-finite light strength; skipped"
            ));
            return;
        }
        let transform = Affine3A::from_mat4(world);
        // World-space area scale of the light's local XY plane.
        let area_scale = transform
            .matrix3
            .x_axis
            .cross(transform.matrix3.y_axis)
            .length();
        let emitter =
            |loader: &mut UsdLoader, positions: Vec<Vec3>, indices: Vec<[u32; 3]>, area: f32| {
                let radiance = if normalize {
                    strength / (area * area_scale).max(f32::MIN_POSITIVE)
                } else {
                    strength
                };
                let material = loader.builder.add_material(Material {
                    double_sided: false,
                    ..Material::diffuse(where_.clone(), Vec3::ZERO).with_emission(radiance)
                });
                let mesh = loader
                    .builder
                    .add_mesh(where_.clone(), positions, indices, material);
                loader.builder.add_instance(mesh, transform, where_.clone());
            };
        match kind {
            "RectLight" => {
                let w = 0.5 * self.get_f32(prim, "inputs:width").unwrap_or(1.0);
                let h = 0.5 * self.get_f32(prim, "inputs:height").unwrap_or(1.0);
                // In the XY plane, emitting towards −Z: wound clockwise seen from +Z.
                let positions = vec![
                    Vec3::new(-w, -h, 0.0),
                    Vec3::new(-w, h, 0.0),
                    Vec3::new(w, h, 0.0),
                    Vec3::new(w, -h, 0.0),
                ];
                emitter(self, positions, vec![[0, 1, 2], [0, 2, 3]], 4.0 * w * h);
            }
            "DiskLight" => {
                let r = self.get_f32(prim, "inputs:radius").unwrap_or(0.5);
                let mut positions = vec![Vec3::ZERO];
                positions.extend((0..DISK_SEGMENTS).map(|i| {
                    let a = -std::f32::consts::TAU * i as f32 / DISK_SEGMENTS as f32;
                    Vec3::new(r * a.cos(), r * a.sin(), 0.0)
                }));
                let indices = (0..DISK_SEGMENTS)
                    .map(|i| [0, 1 + i, 1 + (i + 1) % DISK_SEGMENTS])
                    .collect();
                let area = 0.5
                    * DISK_SEGMENTS as f32
                    * r
                    * r
                    * (std::f32::consts::TAU / DISK_SEGMENTS as f32).sin();
                emitter(self, positions, indices, area);
            }
            "SphereLight" => {
                let local_radius = self.get_f32(prim, "inputs:radius").unwrap_or(0.5);
                let r = local_radius * area_scale.sqrt();
                let shaped = self
                    .get_f32(prim, "inputs:shaping:cone:angle")
                    .is_some_and(|a| a < 180.0);
                let as_point =
                    self.get(prim, "treatAsPoint").as_ref().and_then(as_bool) == Some(true);
                if !as_point && !shaped && r > 0.0 {
                    // A real sphere: an emitter of radiance L over its surface (one-sided,
                    // outwards), as Cycles renders a point light with a radius.
                    let (positions, indices) = uv_sphere(local_radius);
                    let area = 4.0 * std::f32::consts::PI * local_radius * local_radius;
                    emitter(self, positions, indices, area);
                    return;
                }
                // A sphere of radiance L emits π·L·4πr² in all, i.e. L·πr² per steradian;
                // normalized, L = intensity / 4πr², so intensity / 4 per steradian.
                let per_steradian = if normalize || r == 0.0 {
                    strength / 4.0
                } else {
                    strength * std::f32::consts::PI * r * r
                };
                if shaped && !as_point && r > 0.0 {
                    self.warn(format!(
                        "{where_}: shaped SphereLight of radius {r} is rendered as a point spot light"
                    ));
                }
                let position = transform.transform_point3(Vec3::ZERO);
                let kind = match self.get_f32(prim, "inputs:shaping:cone:angle") {
                    Some(angle) if angle < 180.0 => {
                        let softness = self
                            .get_f32(prim, "inputs:shaping:cone:softness")
                            .unwrap_or(0.0)
                            .clamp(0.0, 1.0);
                        let outer = angle.to_radians().min(std::f32::consts::FRAC_PI_2);
                        LightKind::Spot {
                            position,
                            direction: transform.transform_vector3(Vec3::NEG_Z).normalize_or_zero(),
                            intensity: per_steradian,
                            cos_inner: (outer * (1.0 - softness)).cos(),
                            cos_outer: outer.cos(),
                            range: None,
                        }
                    }
                    _ => LightKind::Point {
                        position,
                        intensity: per_steradian,
                        range: None,
                    },
                };
                self.builder.add_light(Light {
                    name: where_.clone(),
                    kind,
                    source: where_,
                });
            }
            "DistantLight" => {
                let direction = transform.transform_vector3(Vec3::NEG_Z).normalize_or_zero();
                // Irradiance is intensity × 2^exposure × colour, except from Blender, whose
                // exporter writes a sun of S W/m² as intensity S/4 (and reads it back × 4).
                let irradiance = if self.from_blender {
                    4.0 * strength
                } else {
                    strength
                };
                self.builder.add_light(Light {
                    name: where_.clone(),
                    kind: LightKind::Directional {
                        direction,
                        irradiance,
                    },
                    source: where_,
                });
            }
            _ => {}
        }
    }
}

/// A UV sphere of `radius` about the origin, wound outwards.
fn uv_sphere(radius: f32) -> (Vec<Vec3>, Vec<[u32; 3]>) {
    let (rings, segments) = (16u32, 32u32);
    let mut positions = Vec::new();
    for ring in 0..=rings {
        let theta = std::f32::consts::PI * ring as f32 / rings as f32;
        for segment in 0..=segments {
            let phi = std::f32::consts::TAU * segment as f32 / segments as f32;
            positions.push(
                radius
                    * Vec3::new(
                        theta.sin() * phi.cos(),
                        theta.sin() * phi.sin(),
                        theta.cos(),
                    ),
            );
        }
    }
    let row = segments + 1;
    let mut indices = Vec::new();
    for ring in 0..rings {
        for segment in 0..segments {
            let (a, b) = (ring * row + segment, (ring + 1) * row + segment);
            indices.push([a, b, b + 1]);
            indices.push([a, b + 1, a + 1]);
        }
    }
    (positions, indices)
}

/// The colour of a blackbody at `kelvin` (clamped to 1667–25000 K) relative to one at
/// 6500 K, in linear sRGB: the Planckian locus approximation of Kim et al. (2002) gives its
/// chromaticity, the sRGB matrix (IEC 61966-2-1) its colour at unit luminance.
fn blackbody_tint(kelvin: f32) -> Vec3 {
    fn rgb(kelvin: f64) -> Vec3 {
        let t = kelvin.clamp(1667.0, 25000.0);
        let (t2, t3) = (t * t, t * t * t);
        let x = if t <= 4000.0 {
            -0.2661239e9 / t3 - 0.2343589e6 / t2 + 0.8776956e3 / t + 0.179910
        } else {
            -3.0258469e9 / t3 + 2.1070379e6 / t2 + 0.2226347e3 / t + 0.240390
        };
        let y = if t <= 2222.0 {
            -1.1063814 * x * x * x - 1.34811020 * x * x + 2.18555832 * x - 0.20219683
        } else if t <= 4000.0 {
            -0.9549476 * x * x * x - 1.37418593 * x * x + 2.09137015 * x - 0.16748867
        } else {
            3.0817580 * x * x * x - 5.87338670 * x * x + 3.75112997 * x - 0.37001483
        };
        let (cx, cy, cz) = (x / y, 1.0, (1.0 - x - y) / y);
        Vec3::new(
            (3.2404542 * cx - 1.5371385 * cy - 0.4985314 * cz) as f32,
            (-0.9692660 * cx + 1.8760108 * cy + 0.0415560 * cz) as f32,
            (0.0556434 * cx - 0.2040259 * cy + 1.0572252 * cz) as f32,
        )
        .max(Vec3::ZERO)
    }
    if !kelvin.is_finite() {
        return Vec3::ONE;
    }
    rgb(kelvin as f64) / rgb(6500.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sphere_lights_are_wound_outwards() {
        let (positions, indices) = uv_sphere(2.0);
        // Each non-degenerate triangle's normal points away from the centre.
        for t in &indices {
            let [a, b, c] = t.map(|i| positions[i as usize]);
            let n = (b - a).cross(c - a);
            if n.length() > 1e-6 {
                assert!(n.dot(a + b + c) > 0.0, "{t:?}");
            }
        }
    }

    #[test]
    fn colour_temperature_is_warm_below_and_cool_above_6500_kelvin() {
        assert!((blackbody_tint(6500.0) - Vec3::ONE).abs().max_element() < 1e-6);
        let candle = blackbody_tint(2000.0);
        assert!(candle.x > 1.0 && candle.z < 0.3 * candle.x, "{candle}");
        let sky = blackbody_tint(12000.0);
        assert!(sky.z > sky.x, "{sky}");
    }
}
