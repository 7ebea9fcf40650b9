//! A primitive's vertices as posed: morph targets blended by their weights, then linear
//! blend skinning by the joints' matrices (glTF 2.0 §3.7.2.2 and §3.7.3). Normals follow
//! the inverse transpose of each vertex's blended matrix, tangents the matrix itself.

use glam::{Mat3, Mat4, Vec3, Vec4};

use super::primitive::VertexSource;

/// How one node's copy of a mesh is posed.
#[derive(Clone, Copy, Default)]
pub(super) struct Deformation<'a> {
    /// Morph-target weights (empty: none).
    pub weights: &'a [f32],
    /// Each joint's world transform times its inverse bind matrix (`None`: not skinned).
    pub joints: Option<&'a [Mat4]>,
}

impl Deformation<'_> {
    /// True when the mesh is drawn as stored.
    pub fn is_rest(&self) -> bool {
        self.joints.is_none() && self.weights.iter().all(|&w| w == 0.0)
    }
}

/// Poses `positions`, `normals` and `tangents` (per vertex, or empty) of `primitive`.
pub(super) fn apply(
    source: &mut VertexSource,
    primitive: &gltf::Primitive,
    deformation: Deformation,
    positions: &mut [Vec3],
    normals: &mut [Vec3],
    tangents: &mut [Vec4],
) -> Result<(), String> {
    for (i, target) in primitive.morph_targets().enumerate() {
        let weight = deformation.weights.get(i).copied().unwrap_or(0.0);
        if weight == 0.0 {
            continue;
        }
        let add = |accessor: Option<gltf::Accessor>, out: &mut dyn FnMut(usize, Vec3)| {
            let Some(accessor) = accessor else {
                return Ok(());
            };
            let deltas = source.read(&accessor)?;
            for v in 0..deltas.len() {
                out(v, weight * Vec3::from(deltas.get::<3>(v)));
            }
            Ok::<(), String>(())
        };
        let n = positions.len();
        let fits = |a: &Option<gltf::Accessor>| a.as_ref().is_none_or(|a| a.count() == n);
        if !(fits(&target.positions()) && fits(&target.normals()) && fits(&target.tangents())) {
            return Err(format!(
                "morph target {i} does not have one value per vertex"
            ));
        }
        add(target.positions(), &mut |v, d| positions[v] += d)?;
        if !normals.is_empty() {
            add(target.normals(), &mut |v, d| normals[v] += d)?;
        }
        if !tangents.is_empty() {
            add(target.tangents(), &mut |v, d| tangents[v] += d.extend(0.0))?;
        }
    }
    if let Some(joints) = deformation.joints {
        skin(source, joints, positions, normals, tangents)?;
    }
    Ok(())
}

/// Linear blend skinning over every `JOINTS_n`/`WEIGHTS_n` pair.
fn skin(
    source: &mut VertexSource,
    joints: &[Mat4],
    positions: &mut [Vec3],
    normals: &mut [Vec3],
    tangents: &mut [Vec4],
) -> Result<(), String> {
    let mut blended = vec![Mat4::ZERO; positions.len()];
    let mut total = vec![0.0f32; positions.len()];
    for set in 0.. {
        let (Some(indices), Some(weights)) = (
            source.attribute(&format!("JOINTS_{set}"))?,
            source.attribute(&format!("WEIGHTS_{set}"))?,
        ) else {
            if set == 0 {
                return Err("a skinned mesh without JOINTS_0 and WEIGHTS_0".into());
            }
            break;
        };
        if indices.len() != positions.len() || weights.len() != positions.len() {
            return Err(format!(
                "JOINTS_{set}/WEIGHTS_{set} do not have one value per vertex"
            ));
        }
        for v in 0..positions.len() {
            let (j, w) = (indices.get::<4>(v), weights.get::<4>(v));
            for k in 0..4 {
                if w[k] == 0.0 {
                    continue;
                }
                let joint = joints.get(j[k] as usize).ok_or_else(|| {
                    format!(
                        "JOINTS_{set} of vertex {v} names a joint past the skin's {}",
                        joints.len()
                    )
                })?;
                blended[v] += *joint * w[k];
                total[v] += w[k];
            }
        }
    }
    for v in 0..positions.len() {
        // Weights should sum to one; renormalise, and leave unweighted vertices in place.
        let m = if total[v] > 0.0 {
            blended[v] * (1.0 / total[v])
        } else {
            Mat4::IDENTITY
        };
        positions[v] = m.transform_point3(positions[v]);
        let linear = Mat3::from_mat4(m);
        if let Some(n) = normals.get_mut(v) {
            *n = (linear.inverse().transpose() * *n).normalize_or_zero();
        }
        if let Some(t) = tangents.get_mut(v) {
            *t = (linear * t.truncate()).normalize_or_zero().extend(t.w);
        }
    }
    Ok(())
}
