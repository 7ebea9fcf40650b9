//! UsdSkel linear blend skinning at the load time, through openusd's UsdSkel port: the
//! skeleton's joints posed by its `SkelAnimation` (joints it does not animate keep their
//! rest transform), skinning transforms `inverse(bind) · skel-space pose`, and each point
//! skinned by its `skel:jointIndices`/`jointWeights` after `geomBindTransform`. Skinned
//! points are in the skeleton's space, so a skinned mesh is placed by the skeleton's
//! transform, not its own (UsdSkel, "Skinning Semantics"). Blend shapes are not applied.
//! Every count and index is checked first: openusd's skinning functions assume them.

use glam::{Mat4, Vec3};
use openusd::schemas::skel::{
    AnimMapper, SkelAnimQuery, SkelBindingAPI, Skeleton, SkeletonResolver, SkinningResolver,
};
use openusd::{gf, sdf, usd};

use super::UsdLoader;
use super::value::as_ints;
use crate::load::LoadError;

/// A USD (row-vector) matrix as glam's column-vector one: the same numbers.
fn to_mat4(m: &gf::Matrix4d) -> Mat4 {
    Mat4::from_cols_array(&m.0.map(|v| v as f32))
}

impl UsdLoader {
    /// `points` of skinnable `prim` posed at the load time, and the skeleton's world
    /// transform that places them; `None` when the prim is not bound to a skeleton, or (with
    /// a warning) when its binding cannot be used, leaving the mesh in its bind pose.
    pub(super) fn skinned(
        &mut self,
        prim: &usd::Prim,
        points: &[Vec3],
    ) -> Result<Option<(Vec<Vec3>, Mat4)>, LoadError> {
        let path = prim.path().clone();
        let Some(binding) = SkelBindingAPI::get(&self.stage, path.clone())
            .ok()
            .flatten()
        else {
            return Ok(None);
        };
        let Some(skeleton_path) = binding.inherited_skeleton().ok().flatten() else {
            return Ok(None);
        };
        let where_ = path.as_str().to_string();
        match self.pose(&binding, &skeleton_path, points, &path) {
            Ok(posed) => {
                let world = self.world_transform(&skeleton_path)?;
                Ok(Some((posed, world)))
            }
            Err(why) => {
                self.warn(format!(
                    "{where_}: skinning to {} not applied ({why}); rendered in its bind pose",
                    skeleton_path.as_str()
                ));
                Ok(None)
            }
        }
    }

    fn pose(
        &self,
        binding: &SkelBindingAPI,
        skeleton_path: &sdf::Path,
        points: &[Vec3],
        prim: &sdf::Path,
    ) -> Result<Vec<Vec3>, String> {
        let skeleton = Skeleton::get(&self.stage, skeleton_path.clone())
            .ok()
            .flatten()
            .ok_or("the target is not a Skeleton")?;
        let resolver = SkeletonResolver::from_skeleton(&skeleton).map_err(|e| format!("{e:#}"))?;
        let joints = resolver.joint_order().len();
        if resolver.joint_world_bind_transforms().len() != joints {
            return Err(format!(
                "{} bindTransforms for {joints} joints",
                resolver.joint_world_bind_transforms().len()
            ));
        }
        let rest = resolver.rest_pose_local();
        if !rest.is_empty() && rest.len() != joints {
            return Err(format!("{} restTransforms for {joints} joints", rest.len()));
        }
        let local = self.joint_locals(skeleton_path, binding, &resolver)?;
        let skinning =
            resolver.compute_skinning_transforms_from_local(&local, gf::Matrix4d::IDENTITY);
        let query = SkinningResolver::from_binding(binding, resolver.joint_order())
            .map_err(|e| format!("{e:#}"))?;
        self.check_influences(&query, points.len(), prim)?;
        if query.is_rigidly_deformed() {
            let rigid = to_mat4(&query.compute_rigid_transform(&skinning));
            return Ok(points.iter().map(|&p| rigid.transform_point3(p)).collect());
        }
        let usd_points: Vec<gf::Vec3f> = points.iter().map(|p| gf::vec3f(p.x, p.y, p.z)).collect();
        Ok(query
            .compute_skinned_points(&usd_points, &skinning)
            .into_iter()
            .map(|p| Vec3::new(p.x, p.y, p.z))
            .collect())
    }

    /// Joint-local transforms in the skeleton's joint order: the animation's where it
    /// animates a joint, else the rest transform (identity without one).
    fn joint_locals(
        &self,
        skeleton_path: &sdf::Path,
        binding: &SkelBindingAPI,
        resolver: &SkeletonResolver,
    ) -> Result<Vec<gf::Matrix4d>, String> {
        let joints = resolver.joint_order().len();
        let rest = resolver.rest_pose_local();
        let rest_of = |j: usize| rest.get(j).copied().unwrap_or(gf::Matrix4d::IDENTITY);
        // The animation bound to the skeleton itself, else one inherited by the mesh.
        let animation = SkelBindingAPI::get(&self.stage, skeleton_path.clone())
            .ok()
            .flatten()
            .and_then(|b| b.inherited_animation_source().ok().flatten())
            .or_else(|| binding.inherited_animation_source().ok().flatten());
        let Some(animation) = animation else {
            return Ok((0..joints).map(rest_of).collect());
        };
        let query = SkelAnimQuery::new(&self.stage, animation.clone())
            .map_err(|e| format!("{e:#}"))?
            .ok_or_else(|| format!("{} is not a SkelAnimation", animation.as_str()))?;
        let animated = query
            .compute_joint_local_transforms(&self.stage, self.time)
            .map_err(|e| format!("{e:#}"))?;
        let mapper = AnimMapper::new(query.joint_order(), resolver.joint_order());
        Ok((0..joints)
            .map(|j| {
                mapper
                    .source_index(j)
                    .and_then(|s| animated.get(s).copied())
                    .unwrap_or_else(|| rest_of(j))
            })
            .collect())
    }

    /// The joint influences agree with the points and the joints, as openusd's skinning
    /// functions assume.
    fn check_influences(
        &self,
        query: &SkinningResolver,
        points: usize,
        prim: &sdf::Path,
    ) -> Result<(), String> {
        let indices = self
            .get(prim, "primvars:skel:jointIndices")
            .as_ref()
            .and_then(as_ints)
            .unwrap_or_default();
        let weights = self
            .get(prim, "primvars:skel:jointWeights")
            .as_ref()
            .and_then(super::value::as_f64s)
            .unwrap_or_default();
        let influences = query.num_influences_per_component();
        let components = if query.is_rigidly_deformed() {
            1
        } else {
            points
        };
        if influences == 0 || indices.len() != components * influences {
            return Err(format!(
                "{} jointIndices for {components} points of {influences} influences",
                indices.len()
            ));
        }
        if weights.len() != indices.len() {
            return Err(format!(
                "{} jointWeights for {} jointIndices",
                weights.len(),
                indices.len()
            ));
        }
        let joints = query.joint_order_len();
        if let Some(bad) = indices.iter().find(|&&j| j < 0 || j as usize >= joints) {
            return Err(format!("joint index {bad} for {joints} joints"));
        }
        Ok(())
    }

    /// The world transform of the prim at `path`: the stage correction and every
    /// ancestor's local transform (a `resetXformStack` restarting it).
    pub(super) fn world_transform(&mut self, path: &sdf::Path) -> Result<Mat4, LoadError> {
        let mut chain = Vec::new();
        let mut at = Some(path.clone());
        while let Some(p) = at {
            if p.is_abs_root() {
                break;
            }
            at = p.parent();
            chain.push(p);
        }
        let mut world = self.stage_correction();
        for p in chain.into_iter().rev() {
            let prim = self.stage.prim(p);
            let (local, resets) = self.local_transform(&prim)?;
            world = if resets {
                self.stage_correction() * local
            } else {
                world * local
            };
        }
        Ok(world)
    }
}
