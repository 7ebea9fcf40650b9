//! UsdGeom meshes: topology checks, triangulation, primvars and per-face materials.

use std::collections::HashMap;

use glam::{Affine3A, Mat4, Vec2, Vec3};
use openusd::{sdf, usd};

use super::UsdLoader;
use super::value::{Interpolation, as_bool, as_ints, as_token, as_vec2s, as_vec3s};
use crate::load::LoadError;
use crate::load::polygon::{MAX_EAR_CLIPPED_CORNERS, fan, triangulate};
use crate::load::tangents::generate_tangents;
use crate::scene::Mesh;

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

    pub(super) fn add_mesh(&mut self, prim: &usd::Prim, world: Mat4) -> Result<(), LoadError> {
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
            let triangles = triangulate(&polygon).unwrap_or_else(|| {
                self.warn(format!(
                    "{where_}: face {face} is a concave polygon of {count} corners, more than \
                     {MAX_EAR_CLIPPED_CORNERS} are ear-clipped; covered by a fan, which may \
                     overlap itself"
                ));
                fan(polygon.len())
            });
            for [a, b, c] in triangles {
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
}
