//! `UsdGeomPointInstancer`: every instance a transform of one prototype's meshes, shared,
//! not copied. Instance `i` is placed by `translate(positions[i]) · rotate(orientations[i])
//! · scale(scales[i])` applied after the prototype root's own transform, as
//! `ComputeInstanceTransformsAtTime` does (UsdGeomPointInstancer, "Computing an Instance
//! Transform"); `invisibleIds` hide instances by id (by index without `ids`). Velocities
//! and accelerations, which extrapolate positions between samples for motion blur, are not
//! read: positions are interpolated between their time samples.

use std::collections::HashSet;

use glam::{Mat4, Quat, Vec3};
use openusd::{sdf, usd};

use super::UsdLoader;
use super::value::{as_ints, as_vec3s};
use crate::limits::memory_left;
use crate::load::LoadError;
use crate::scene::Instance;

/// Bytes one placed instance costs while the scene is built: the instance, its name, and
/// room for the list holding it to grow (which may briefly hold twice its length).
fn instance_bytes(name: &str) -> u64 {
    3 * (std::mem::size_of::<Instance>() + name.len()) as u64
}

impl UsdLoader {
    /// Places the instances of PointInstancer `prim` (whose instancer transform is `world`).
    pub(super) fn add_instancer(
        &mut self,
        prim: &usd::Prim,
        world: Mat4,
        depth: usize,
    ) -> Result<(), LoadError> {
        let path = prim.path().clone();
        let where_ = path.as_str().to_string();
        let prototypes = path
            .append_property("prototypes")
            .ok()
            .and_then(|rel| self.stage.relationship(rel).targets().ok())
            .unwrap_or_default();
        let proto_indices = self
            .get(&path, "protoIndices")
            .as_ref()
            .and_then(as_ints)
            .unwrap_or_default();
        let count = proto_indices.len();
        let positions = self
            .get(&path, "positions")
            .as_ref()
            .and_then(as_vec3s)
            .unwrap_or_default();
        if positions.len() != count {
            self.warn(format!(
                "{where_}: {} positions for {count} protoIndices; the instancer is skipped",
                positions.len()
            ));
            return Ok(());
        }
        let orientations = self.orientations(&path, count, &where_);
        let scales = self.optional_per_instance(&path, "scales", count, &where_);
        let hidden = self.hidden_instances(&path, count);
        let budget = memory_left() / instance_bytes(&where_);
        let mut parts = Vec::with_capacity(prototypes.len());
        for prototype in &prototypes {
            // A prototype holding its own instancer would instance itself without end.
            if where_ == prototype.as_str()
                || where_.starts_with(&format!("{}/", prototype.as_str()))
            {
                self.warn(format!(
                    "{where_}: prototype {} contains the instancer itself; left empty",
                    prototype.as_str()
                ));
                parts.push(Vec::new());
                continue;
            }
            let proto = self.stage.prim(prototype.clone());
            parts.push(self.collect_prototype(&proto, depth)?);
        }
        let mut bad_index = None;
        for (i, &proto) in proto_indices.iter().enumerate() {
            if hidden.contains(&i) {
                continue;
            }
            let Some(meshes) = usize::try_from(proto).ok().and_then(|p| parts.get(p)) else {
                bad_index.get_or_insert(proto);
                continue;
            };
            self.placed_by_instancers += meshes.len() as u64;
            if self.placed_by_instancers > budget {
                return Err(self.invalid(format!(
                    "{where_}: point instancers place more than {budget} instances, beyond the memory budget"
                )));
            }
            let rotation = orientations.as_ref().map_or(Quat::IDENTITY, |o| o[i]);
            let scale = scales.as_ref().map_or(Vec3::ONE, |s| s[i]);
            let instance =
                world * Mat4::from_scale_rotation_translation(scale, rotation, positions[i]);
            let meshes = meshes.clone();
            for (mesh, relative) in meshes {
                self.place(&[mesh], instance * relative, &where_);
            }
        }
        if let Some(index) = bad_index {
            self.warn(format!(
                "{where_}: protoIndices holds {index}, but there are {} prototypes; those instances are skipped",
                prototypes.len()
            ));
        }
        Ok(())
    }

    /// The meshes of the prototype rooted at `proto`, with their transforms relative to the
    /// prototype root's parent (so including the root's own transform). A prototype may sit
    /// under an `over`, as instancers' prototypes often do to stay undrawn elsewhere.
    fn collect_prototype(
        &mut self,
        proto: &usd::Prim,
        depth: usize,
    ) -> Result<Vec<(usize, Mat4)>, LoadError> {
        let outer = self.collecting.replace(Vec::new());
        let visited = self.visit(proto, Mat4::IDENTITY, depth + 1);
        let parts = std::mem::replace(&mut self.collecting, outer).unwrap_or_default();
        visited?;
        Ok(parts)
    }

    /// `orientations` (half precision, the schema's) or `orientationsf`; `None` when neither
    /// is authored or its length is wrong (with a warning). Not normalised: USD builds the
    /// rotation matrix from the quaternion as it is (`GfMatrix4d::SetRotate`), and a half
    /// precision quaternion is a few parts in 10⁴ off unit length.
    fn orientations(&mut self, path: &sdf::Path, count: usize, where_: &str) -> Option<Vec<Quat>> {
        let quats: Vec<Quat> = match self.get(path, "orientations") {
            Some(sdf::Value::QuathVec(q)) => q
                .iter()
                .map(|q| Quat::from_xyzw(q.x.to_f32(), q.y.to_f32(), q.z.to_f32(), q.w.to_f32()))
                .collect(),
            Some(sdf::Value::QuatfVec(q)) => q
                .iter()
                .map(|q| Quat::from_xyzw(q.x, q.y, q.z, q.w))
                .collect(),
            _ => match self.get(path, "orientationsf") {
                Some(sdf::Value::QuatfVec(q)) => q
                    .iter()
                    .map(|q| Quat::from_xyzw(q.x, q.y, q.z, q.w))
                    .collect(),
                _ => return None,
            },
        };
        if quats.len() != count {
            self.warn(format!(
                "{where_}: {} orientations for {count} instances; ignored",
                quats.len()
            ));
            return None;
        }
        Some(
            quats
                .into_iter()
                .map(|q| if q.is_finite() { q } else { Quat::IDENTITY })
                .collect(),
        )
    }

    /// A per-instance vector attribute, `None` when unauthored or of the wrong length.
    fn optional_per_instance(
        &mut self,
        path: &sdf::Path,
        name: &str,
        count: usize,
        where_: &str,
    ) -> Option<Vec<Vec3>> {
        let values = self.get(path, name).as_ref().and_then(as_vec3s)?;
        if values.len() != count {
            self.warn(format!(
                "{where_}: {} {name} for {count} instances; ignored",
                values.len()
            ));
            return None;
        }
        Some(values)
    }

    /// Indices of the instances `invisibleIds` hides: by `ids` where authored, else by index.
    fn hidden_instances(&self, path: &sdf::Path, count: usize) -> HashSet<usize> {
        let invisible: HashSet<i64> = self
            .get(path, "invisibleIds")
            .as_ref()
            .and_then(as_ints)
            .unwrap_or_default()
            .into_iter()
            .collect();
        if invisible.is_empty() {
            return HashSet::new();
        }
        match self.get(path, "ids").as_ref().and_then(as_ints) {
            Some(ids) if ids.len() == count => ids
                .iter()
                .enumerate()
                .filter(|(_, id)| invisible.contains(id))
                .map(|(i, _)| i)
                .collect(),
            _ => (0..count)
                .filter(|&i| invisible.contains(&(i as i64)))
                .collect(),
        }
    }
}
