//! UsdGeom meshes: topology checks, primvars and per-face materials read into
//! [`Polygons`], which meshes, implicit prims and refined or skinned meshes all become
//! before they are triangulated into scene meshes ([`UsdLoader::emit`]).

use std::collections::HashMap;

use glam::{Affine3A, Mat4, Vec2, Vec3};
use openusd::{sdf, usd};

use super::UsdLoader;
use super::value::{Interpolation, as_bool, as_f64s, as_ints, as_token, as_vec2s, as_vec3s};
use crate::limits::check_memory;
use crate::load::LoadError;
use crate::load::polygon::{MAX_EAR_CLIPPED_CORNERS, fan, triangulate};
use crate::load::subdivision::{Boundary, Cage, catmull_clark, loop_subdivision, refined_faces};
use crate::load::tangents::generate_tangents;
use crate::scene::{AlphaMode, Material, Mesh};

/// A polygon mesh as UsdGeom describes one, before triangulation.
#[derive(Clone, Debug, Default)]
pub(super) struct Polygons {
    pub points: Vec<Vec3>,
    /// Corners of each face.
    pub counts: Vec<usize>,
    /// Point of each face corner, face after face.
    pub indices: Vec<usize>,
    pub normals: Option<(Vec<Vec3>, Interpolation)>,
    pub uvs: Option<(Vec<Vec2>, Interpolation)>,
    /// `primvars:displayColor` and `primvars:displayOpacity`, used where no material is bound.
    pub display_colour: Option<(Vec<Vec3>, Interpolation)>,
    pub display_opacity: Option<(Vec<f32>, Interpolation)>,
    /// The bound material of each face; `None` where nothing is bound.
    pub face_material: Vec<Option<usize>>,
    pub left_handed: bool,
    pub double_sided: bool,
}

/// Newell's normal of a polygon (its area vector), robust for non-planar faces.
fn face_normal(points: &[Vec3], corners: &[usize]) -> Vec3 {
    let n = corners.len();
    (0..n)
        .map(|i| points[corners[i]].cross(points[corners[(i + 1) % n]]))
        .sum()
}

/// Authored normals carried from `polygons`' points to `posed`: each face's corner normals
/// turned by the rotation that takes the face's normal to its posed normal, which is
/// exact for faces a joint moves rigidly and keeps hard edges hard.
fn repose_normals(polygons: &mut Polygons, posed: &[Vec3]) {
    let Some(normals) = polygons.normals.take() else {
        return;
    };
    let mut turned = Vec::with_capacity(polygons.indices.len());
    let mut start = 0;
    for (face, &count) in polygons.counts.iter().enumerate() {
        let corners = &polygons.indices[start..start + count];
        let before = face_normal(&polygons.points, corners).normalize_or_zero();
        let after = face_normal(posed, corners).normalize_or_zero();
        let rotation = if before == Vec3::ZERO || after == Vec3::ZERO {
            glam::Quat::IDENTITY
        } else {
            glam::Quat::from_rotation_arc(before, after)
        };
        for (i, &point) in corners.iter().enumerate() {
            let n = pick(&normals, start + i, face, point).unwrap_or(before);
            turned.push(rotation * n);
        }
        start += count;
    }
    polygons.normals = Some((turned, Interpolation::FaceVarying));
}

/// Point normals of a polygon mesh, each face's normal weighted by its corner angle at the
/// point (Thürmer & Wüthrich 1998; what Blender computes for smooth-shaded meshes).
fn smooth_normals(polygons: &Polygons) -> Vec<Vec3> {
    let mut normals = vec![Vec3::ZERO; polygons.points.len()];
    let mut start = 0;
    for &count in &polygons.counts {
        let corners = &polygons.indices[start..start + count];
        let face = face_normal(&polygons.points, corners).normalize_or_zero();
        for i in 0..count {
            let [a, b, c] = [
                corners[(i + count - 1) % count],
                corners[i],
                corners[(i + 1) % count],
            ];
            let p = &polygons.points;
            normals[b] += face * (p[c] - p[b]).angle_between(p[a] - p[b]);
        }
        start += count;
    }
    let sign = if polygons.left_handed { -1.0 } else { 1.0 };
    normals
        .into_iter()
        .map(|n| sign * n.normalize_or_zero())
        .collect()
}

/// The value a primvar gives face corner `corner` of face `face` at point `point`.
pub(super) fn pick<T: Copy>(
    (values, interpolation): &(Vec<T>, Interpolation),
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

/// The vertices and triangles of `mesh` from the face-corner `triangles` of `polygons`.
/// When every attribute is per point (or constant), corners of one point share a vertex, as
/// the file does; otherwise each corner is its own vertex, since normals, texture
/// coordinates or colours may differ at every corner.
fn fill_vertices(
    mesh: &mut Mesh,
    polygons: &Polygons,
    triangles: &[[usize; 3]],
    corner_face: &[usize],
    colours: bool,
) {
    let per_point = |i: Option<Interpolation>| {
        i.is_none_or(|i| matches!(i, Interpolation::Constant | Interpolation::Vertex))
    };
    let shared = per_point(polygons.normals.as_ref().map(|n| n.1))
        && per_point(polygons.uvs.as_ref().map(|n| n.1))
        && (!colours
            || per_point(polygons.display_colour.as_ref().map(|n| n.1))
                && per_point(polygons.display_opacity.as_ref().map(|n| n.1)));
    let mut normals_ok = polygons.normals.is_some();
    let mut st = Vec::new();
    let mut vertex_of = vec![u32::MAX; if shared { polygons.points.len() } else { 0 }];
    for tri in triangles {
        let mut triangle = [0u32; 3];
        for (k, &corner) in tri.iter().enumerate() {
            let (face, point) = (corner_face[corner], polygons.indices[corner]);
            if shared && vertex_of[point] != u32::MAX {
                triangle[k] = vertex_of[point];
                continue;
            }
            triangle[k] = mesh.positions.len() as u32;
            if shared {
                vertex_of[point] = triangle[k];
            }
            mesh.positions.push(polygons.points[point]);
            if let Some(normals) = &polygons.normals {
                match pick(normals, corner, face, point) {
                    Some(n) => mesh.normals.push(n.normalize_or_zero()),
                    None => normals_ok = false,
                }
            }
            if let Some(uvs) = &polygons.uvs {
                let v = pick(uvs, corner, face, point);
                // USD's st has v up the image; glTF's (and ours) runs down.
                st.push(v.map_or(Vec2::ZERO, |v| Vec2::new(v.x, 1.0 - v.y)));
            }
            if colours {
                let rgb = polygons
                    .display_colour
                    .as_ref()
                    .and_then(|c| pick(c, corner, face, point))
                    .unwrap_or(Vec3::ONE);
                let alpha = polygons
                    .display_opacity
                    .as_ref()
                    .and_then(|o| pick(o, corner, face, point))
                    .unwrap_or(1.0);
                mesh.colours.push(rgb.extend(alpha));
            }
        }
        mesh.indices.push(triangle);
    }
    if !normals_ok || mesh.normals.contains(&Vec3::ZERO) {
        mesh.normals.clear();
    }
    if !st.is_empty() {
        mesh.uvs = vec![st];
    }
}

/// Bytes a face of a subdivision surface costs by the time it is rendered: its corners,
/// points and texture coordinates, the levels before it, its triangles, normals and its
/// share of the grid. Measured as the peak of a whole render of a 1,024-quad cage at level
/// 6 (4.19 M faces, 3.15 GB: 750 bytes a face; `/usr/bin/time -f %M`).
const BYTES_PER_REFINED_FACE: u64 = 768;

impl UsdLoader {
    /// A primvar (or the `normals` attribute) and its interpolation.
    pub(super) fn primvar<T>(
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

    /// Reads a `Mesh` prim into polygons; `None` for an empty mesh.
    pub(super) fn read_mesh(&mut self, prim: &usd::Prim) -> Result<Option<Polygons>, LoadError> {
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
            return Ok(None);
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
        let counts: Vec<usize> = counts.into_iter().map(|c| c as usize).collect();
        let mut polygons = Polygons {
            points,
            indices: indices.into_iter().map(|i| i as usize).collect(),
            left_handed: self.get_token(&path, "orientation").as_deref() == Some("leftHanded"),
            double_sided: self
                .get(&path, "doubleSided")
                .as_ref()
                .and_then(as_bool)
                .unwrap_or(false),
            normals: self
                .primvar(&path, "primvars:normals", as_vec3s, Interpolation::Vertex)
                .or_else(|| self.primvar(&path, "normals", as_vec3s, Interpolation::Vertex)),
            uvs: self.primvar(&path, "primvars:st", as_vec2s, Interpolation::FaceVarying),
            face_material: self.face_materials(prim, counts.len())?,
            counts,
            ..Polygons::default()
        };
        self.read_display(&path, &mut polygons);
        Ok(Some(polygons))
    }

    /// `primvars:displayColor` and `primvars:displayOpacity` of any gprim.
    pub(super) fn read_display(&self, path: &sdf::Path, polygons: &mut Polygons) {
        polygons.display_colour = self.primvar(
            path,
            "primvars:displayColor",
            as_vec3s,
            Interpolation::Constant,
        );
        polygons.display_opacity = self.primvar(
            path,
            "primvars:displayOpacity",
            |v| as_f64s(v).map(|a| a.into_iter().map(|x| x as f32).collect()),
            Interpolation::Constant,
        );
    }

    /// Which material each face uses: GeomSubsets of the `materialBind` family override
    /// the mesh's own binding.
    fn face_materials(
        &mut self,
        prim: &usd::Prim,
        faces: usize,
    ) -> Result<Vec<Option<usize>>, LoadError> {
        let path = prim.path().clone();
        let mut face_material = vec![self.bound_material(&path); faces];
        let children = prim
            .children()
            .map_err(|e| self.invalid(format!("{}: {e:#}", path.as_str())))?;
        for child in children {
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
        Ok(face_material)
    }

    /// The material standing in where nothing is bound: white modulated by the vertex
    /// colours `displayColor` gives, blended when `displayOpacity` is below one; grey
    /// without either.
    fn display_material(&mut self, polygons: &Polygons) -> usize {
        if polygons.display_colour.is_none() && polygons.display_opacity.is_none() {
            return self.default_material();
        }
        let blended = polygons
            .display_opacity
            .as_ref()
            .is_some_and(|(o, _)| o.iter().any(|&o| o < 1.0));
        let key = if blended {
            "displayColor (blended)"
        } else {
            "displayColor"
        };
        if let Some(&m) = self.materials.get(key) {
            return m;
        }
        let mut material = Material::default_grey(key);
        material.pbr.base_colour = Vec3::ONE;
        material.vertex_colours = true;
        if blended {
            material.alpha_mode = AlphaMode::Blend;
        }
        let m = self.builder.add_material(material);
        self.materials.insert(key.to_string(), m);
        m
    }

    /// Triangulates `polygons` into scene meshes, one per material, named `where_`.
    pub(super) fn emit(&mut self, where_: &str, polygons: &Polygons) -> Vec<usize> {
        let display = self.display_material(polygons);
        let mut materials: Vec<(usize, Vec<[usize; 3]>)> = self
            .triangles_by_material(where_, polygons, display)
            .into_iter()
            .collect();
        materials.sort_by_key(|(m, _)| *m);
        let corner_face: Vec<usize> = polygons
            .counts
            .iter()
            .enumerate()
            .flat_map(|(f, &c)| std::iter::repeat_n(f, c))
            .collect();
        let mut meshes = Vec::new();
        for (material, triangles) in materials {
            let mut mesh = Mesh {
                name: where_.to_string(),
                material,
                ..Mesh::default()
            };
            // The display material, or a bound one whose colour reads displayColor.
            let reads_colours =
                material == display || self.builder.material_mut(material).vertex_colours;
            let colours = reads_colours
                && (polygons.display_colour.is_some() || polygons.display_opacity.is_some());
            fill_vertices(&mut mesh, polygons, &triangles, &corner_face, colours);
            if !polygons.double_sided {
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
            meshes.push(self.builder.add_full_mesh(mesh));
        }
        meshes
    }

    /// The faces of `polygons` as triangles of face corners, by material (`display` for
    /// faces no subset binds). Triangles need no triangulation; a polygon is triangulated
    /// by its shape.
    fn triangles_by_material(
        &mut self,
        where_: &str,
        polygons: &Polygons,
        display: usize,
    ) -> HashMap<usize, Vec<[usize; 3]>> {
        let Polygons {
            points,
            counts,
            indices,
            ..
        } = polygons;
        let mut by_material: HashMap<usize, Vec<[usize; 3]>> = HashMap::new();
        let mut first = 0;
        for (face, &count) in counts.iter().enumerate() {
            let material = polygons.face_material[face].unwrap_or(display);
            let out = by_material.entry(material).or_default();
            let mut push = |[a, b, c]: [usize; 3]| {
                let tri = [first + a, first + b, first + c];
                out.push(if polygons.left_handed {
                    [tri[0], tri[2], tri[1]]
                } else {
                    tri
                });
            };
            if count == 3 {
                push([0, 1, 2]);
            } else {
                let polygon: Vec<Vec3> =
                    (first..first + count).map(|c| points[indices[c]]).collect();
                let triangles = triangulate(&polygon).unwrap_or_else(|| {
                    self.warn(format!(
                        "{where_}: face {face} is a concave polygon of {count} corners, more \
                         than {MAX_EAR_CLIPPED_CORNERS} are ear-clipped; covered by a fan, \
                         which may overlap itself"
                    ));
                    fan(polygon.len())
                });
                triangles.into_iter().for_each(&mut push);
            }
            first += count;
        }
        by_material
    }

    /// Puts `meshes` into the scene at `world`, or into the prototype being collected.
    pub(super) fn place(&mut self, meshes: &[usize], world: Mat4, name: &str) {
        for &mesh in meshes {
            match &mut self.collecting {
                Some(parts) => parts.push((mesh, world)),
                None => {
                    self.builder
                        .add_instance(mesh, Affine3A::from_mat4(world), name.to_string());
                }
            }
        }
    }

    /// `polygons` refined as a Catmull–Clark surface ([`catmull_clark`]), or a Loop one
    /// ([`loop_subdivision`]) when all are triangles and the scheme says `loop`. Authored normals
    /// do not apply to a subdivision surface (UsdGeomMesh); the refined mesh gets smooth
    /// vertex normals. Face-varying texture coordinates are interpolated linearly, per-face
    /// data follows the face it came from, and other display colours become per face.
    fn subdivide(&mut self, path: &sdf::Path, polygons: Polygons) -> Result<Polygons, LoadError> {
        let where_ = path.as_str();
        let scheme = self.get_token(path, "subdivisionScheme");
        let is_loop = scheme.as_deref() == Some("loop");
        let cost = |levels: u32| {
            let faces = if is_loop {
                (polygons.counts.len() as u64).saturating_mul(4u64.saturating_pow(levels))
            } else {
                refined_faces(&polygons.counts, levels)
            };
            faces.saturating_mul(BYTES_PER_REFINED_FACE)
        };
        // The deepest level asked for that fits what is left of the budget.
        let asked = self.subdivision_levels;
        let fits = |levels: u32| {
            check_memory(
                || format!("{where_}: subdivision to level {levels}"),
                cost(levels),
            )
        };
        let levels = match fits(asked) {
            Ok(()) => asked,
            Err(e) => {
                let Some(levels) = (0..asked).rev().find(|&l| fits(l).is_ok()) else {
                    return Err(self.invalid(e.to_string()));
                };
                self.warn(format!("{e}; refined to level {levels} instead"));
                levels
            }
        };
        let sharpness = self.creases(path, polygons.points.len());
        if is_loop && !sharpness.is_empty() {
            self.warn(format!(
                "{where_}: creases are not applied to a Loop surface; it is smooth there"
            ));
        }
        let boundary = match self.get_token(path, "interpolateBoundary").as_deref() {
            Some("edgeOnly") => Boundary::EdgeOnly,
            _ => Boundary::EdgeAndCorner,
        };
        let corner_face: Vec<usize> = polygons
            .counts
            .iter()
            .enumerate()
            .flat_map(|(f, &c)| std::iter::repeat_n(f, c))
            .collect();
        let uvs = polygons.uvs.as_ref().map(|uvs| {
            (0..polygons.indices.len())
                .map(|c| pick(uvs, c, corner_face[c], polygons.indices[c]).unwrap_or(Vec2::ZERO))
                .collect()
        });
        let cage = Cage {
            points: polygons.points.clone(),
            counts: polygons.counts.clone(),
            indices: polygons.indices.clone(),
            uvs,
            origin: (0..polygons.counts.len()).collect(),
            sharpness,
        };
        let refined = if is_loop {
            loop_subdivision(&cage, boundary, levels)
        } else {
            catmull_clark(&cage, boundary, levels)
        };
        let per_face = |values: &Option<(Vec<Vec3>, Interpolation)>| {
            values.as_ref().map(|v| match v.1 {
                Interpolation::Constant | Interpolation::Uniform => v.clone(),
                // Each face takes the value at its first corner.
                _ => (
                    polygons
                        .counts
                        .iter()
                        .scan(0, |first, &count| {
                            let corner = *first;
                            *first += count;
                            Some(corner)
                        })
                        .enumerate()
                        .map(|(f, first)| {
                            pick(v, first, f, polygons.indices[first]).unwrap_or(Vec3::ONE)
                        })
                        .collect(),
                    Interpolation::Uniform,
                ),
            })
        };
        let remap = |values: Option<(Vec<Vec3>, Interpolation)>| {
            values.map(|(v, i)| match i {
                Interpolation::Uniform => (
                    refined
                        .origin
                        .iter()
                        .map(|&f| v.get(f).copied().unwrap_or(Vec3::ONE))
                        .collect(),
                    Interpolation::Uniform,
                ),
                _ => (v, i),
            })
        };
        let opacity = polygons.display_opacity.clone().map(|(v, i)| match i {
            Interpolation::Constant => (v, i),
            _ => (
                vec![v.iter().copied().fold(1.0f32, f32::min)],
                Interpolation::Constant,
            ),
        });
        let mut refined_polygons = Polygons {
            normals: None,
            uvs: refined.uvs.map(|uvs| (uvs, Interpolation::FaceVarying)),
            display_colour: remap(per_face(&polygons.display_colour)),
            display_opacity: opacity,
            face_material: refined
                .origin
                .iter()
                .map(|&f| polygons.face_material[f])
                .collect(),
            left_handed: polygons.left_handed,
            double_sided: polygons.double_sided,
            points: refined.points,
            counts: refined.counts,
            indices: refined.indices,
        };
        refined_polygons.normals = Some((smooth_normals(&refined_polygons), Interpolation::Vertex));
        Ok(refined_polygons)
    }

    pub(super) fn add_mesh(&mut self, prim: &usd::Prim, world: Mat4) -> Result<(), LoadError> {
        let where_ = prim.path().as_str().to_string();
        let Some(mut polygons) = self.read_mesh(prim)? else {
            return Ok(());
        };
        // A skinned mesh is posed at the load time and placed by its skeleton.
        let mut world = world;
        if let Some((posed, skeleton)) = self.skinned(prim, &polygons.points)? {
            repose_normals(&mut polygons, &posed);
            polygons.points = posed;
            world = skeleton;
        }
        let scheme = self.get_token(prim.path(), "subdivisionScheme");
        let polygons = match scheme.as_deref() {
            Some("catmullClark") if self.subdivision_levels > 0 => {
                self.subdivide(prim.path(), polygons)?
            }
            Some("loop") if self.subdivision_levels > 0 => {
                if polygons.counts.iter().all(|&c| c == 3) {
                    self.subdivide(prim.path(), polygons)?
                } else {
                    self.warn(format!(
                        "{where_}: Loop subdivision needs triangles, and this mesh has other \
                         polygons; rendered as its control cage"
                    ));
                    polygons
                }
            }
            _ => polygons,
        };
        let meshes = self.emit(&where_, &polygons);
        self.place(&meshes, world, &where_);
        Ok(())
    }
}
