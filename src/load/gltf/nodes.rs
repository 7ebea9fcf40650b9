//! The node hierarchy of the scene, posed at the asked time: world transforms (animated
//! translation, rotation and scale where an animation says so), then meshes placed as
//! instances — shared when drawn as stored, one posed copy per node when skinned or
//! morphed — cameras and lights.

use std::collections::HashMap;

use glam::{Affine3A, Mat4, Quat, Vec3};

use super::animation::{self, Pose};
use super::deform::Deformation;
use super::{GltfLoader, MAX_NODE_DEPTH, MAX_NODE_VISITS, instancing};
use crate::limits::check_memory;
use crate::load::LoadError;

/// A node with a mesh, found while walking the hierarchy.
struct MeshNode<'a> {
    node: gltf::Node<'a>,
    world: Mat4,
    source: String,
}

impl GltfLoader {
    /// Walks the default scene (or the first), posed at `self.time` if any.
    pub(super) fn load_scene(&mut self, document: &gltf::Document) -> Result<(), LoadError> {
        let scene = match document
            .default_scene()
            .or_else(|| document.scenes().next())
        {
            Some(s) => s,
            None => return Err(self.invalid("the file has no scene".into())),
        };
        let pose = self.pose(document)?;
        let mut globals: HashMap<usize, Mat4> = HashMap::new();
        let mut mesh_nodes = Vec::new();
        let mut stack: Vec<(gltf::Node, Mat4, usize)> =
            scene.nodes().map(|n| (n, Mat4::IDENTITY, 0)).collect();
        stack.reverse();
        let mut visits = 0;
        while let Some((node, parent, depth)) = stack.pop() {
            visits += 1;
            if depth > MAX_NODE_DEPTH || visits > MAX_NODE_VISITS {
                return Err(self.invalid(format!(
                    "node hierarchy too deep or too large at node {} (cyclic?)",
                    node.index()
                )));
            }
            let world = parent * local_transform(&node, &pose);
            if !world.is_finite() {
                return Err(
                    self.invalid(format!("node {} has a non-finite transform", node.index()))
                );
            }
            globals.insert(node.index(), world);
            let source = match node.name() {
                Some(name) => format!("node {} '{name}'", node.index()),
                None => format!("node {}", node.index()),
            };
            if let Some(camera) = node.camera() {
                self.add_camera(&camera, world, &source);
            }
            if let Some(light) = node.light() {
                self.add_light(&light, world, &source);
            }
            let children: Vec<_> = node.children().map(|c| (c, world, depth + 1)).collect();
            stack.extend(children.into_iter().rev());
            if node.mesh().is_some() {
                mesh_nodes.push(MeshNode {
                    node,
                    world,
                    source,
                });
            }
        }
        // Meshes last: a skin's joints may sit anywhere in the hierarchy.
        for mesh_node in mesh_nodes {
            self.place_mesh(document, &mesh_node, &pose, &globals)?;
        }
        Ok(())
    }

    /// The chosen animation's values at the asked time, or none (the file as stored).
    fn pose(&mut self, document: &gltf::Document) -> Result<Pose, LoadError> {
        let Some(time) = self.time else {
            return Ok(Pose::default());
        };
        let (chosen, note) =
            animation::choose(document, self.animation.as_deref()).map_err(|w| self.invalid(w))?;
        if let Some(note) = note {
            self.warn(note);
        }
        if chosen.is_empty() {
            self.warn(
                "a frame was asked for, but the file has no animation; rendering it as stored"
                    .into(),
            );
        }
        animation::evaluate(&chosen, time, &self.buffers).map_err(|w| self.invalid(w))
    }

    /// Instances of a node's mesh: one per `EXT_mesh_gpu_instancing` copy, posed by its
    /// skin and morph weights.
    fn place_mesh(
        &mut self,
        document: &gltf::Document,
        mesh_node: &MeshNode,
        pose: &Pose,
        globals: &HashMap<usize, Mat4>,
    ) -> Result<(), LoadError> {
        let MeshNode {
            node,
            world,
            source,
        } = mesh_node;
        let mesh = node.mesh().expect("mesh nodes have meshes");
        let weights: Vec<f32> = pose
            .weights
            .get(&node.index())
            .cloned()
            .or_else(|| node.weights().map(<[f32]>::to_vec))
            .or_else(|| mesh.weights().map(<[f32]>::to_vec))
            .unwrap_or_default();
        let joints = match node.skin() {
            Some(skin) => Some(self.joint_matrices(&skin, globals, source)?),
            None => None,
        };
        let deformation = Deformation {
            weights: &weights,
            joints: joints.as_deref(),
        };
        let ours = if deformation.is_rest() {
            self.meshes_of(document, &mesh)?
        } else if let Some(ours) = self.posed.get(&node.index()) {
            // The same node reached again through a shared parent has the same pose.
            ours.clone()
        } else {
            let ours = self.posed_meshes(document, &mesh, deformation)?;
            self.posed.insert(node.index(), ours.clone());
            self.account_for_posed(&ours, source)?;
            ours
        };
        // A skinned mesh is placed by its joints alone (glTF 2.0 §3.7.3.3).
        let world = if joints.is_some() {
            Mat4::IDENTITY
        } else {
            *world
        };
        let copies = instancing::instance_transforms(node, document, &self.buffers)
            .map_err(|why| self.invalid(format!("{source}: {why}")))?
            .unwrap_or_else(|| vec![Mat4::IDENTITY]);
        for (i, copy) in copies.iter().enumerate() {
            let placed = world * *copy;
            if !placed.is_finite() {
                return Err(
                    self.invalid(format!("{source}: instance {i} has a non-finite transform"))
                );
            }
            let name = if copies.len() > 1 {
                format!("{source} instance {i}")
            } else {
                source.clone()
            };
            for &our_mesh in &ours {
                self.builder
                    .add_instance(our_mesh, Affine3A::from_mat4(placed), name.clone());
            }
        }
        Ok(())
    }

    /// Adds posed meshes to the running total of posed vertex data, refusing the scene once
    /// it passes the memory budget.
    fn account_for_posed(&mut self, ours: &[usize], source: &str) -> Result<(), LoadError> {
        for &m in ours {
            let mesh = self.builder.mesh(m);
            let vertex = std::mem::size_of::<Vec3>() * 2 + std::mem::size_of::<glam::Vec4>() * 2;
            let bytes = mesh.positions.len() * vertex + mesh.indices.len() * 12;
            self.posed_bytes = self.posed_bytes.saturating_add(bytes as u64);
        }
        check_memory(|| format!("{source}: posed meshes"), self.posed_bytes)
            .map_err(|e| self.invalid(e.to_string()))
    }

    /// Each joint's world transform times its inverse bind matrix.
    fn joint_matrices(
        &self,
        skin: &gltf::Skin,
        globals: &HashMap<usize, Mat4>,
        source: &str,
    ) -> Result<Vec<Mat4>, LoadError> {
        let what = |why: String| self.invalid(format!("{source}: skin {}: {why}", skin.index()));
        let joints: Vec<gltf::Node> = skin.joints().collect();
        let inverse_binds = match skin.inverse_bind_matrices() {
            Some(accessor) => {
                let m = super::accessor::read_floats(&accessor, &self.buffers).map_err(what)?;
                if m.components != 16 || m.len() < joints.len() {
                    return Err(what(format!(
                        "{} inverse bind matrices for {} joints",
                        m.len(),
                        joints.len()
                    )));
                }
                (0..joints.len())
                    .map(|j| Mat4::from_cols_array(&m.get::<16>(j)))
                    .collect()
            }
            None => vec![Mat4::IDENTITY; joints.len()],
        };
        joints
            .iter()
            .zip(inverse_binds)
            .map(|(joint, inverse_bind)| {
                globals
                    .get(&joint.index())
                    .map(|global| *global * inverse_bind)
                    .ok_or_else(|| {
                        what(format!("joint node {} is not in the scene", joint.index()))
                    })
            })
            .collect()
    }

    /// Our meshes for a glTF mesh drawn as stored, converted the first time it is used.
    pub(super) fn meshes_of(
        &mut self,
        document: &gltf::Document,
        mesh: &gltf::Mesh,
    ) -> Result<Vec<usize>, LoadError> {
        if let Some(ours) = self.meshes.get(&mesh.index()) {
            return Ok(ours.clone());
        }
        let ours = self.posed_meshes(document, mesh, Deformation::default())?;
        self.meshes.insert(mesh.index(), ours.clone());
        Ok(ours)
    }

    /// Our meshes for one posed copy of a glTF mesh.
    fn posed_meshes(
        &mut self,
        document: &gltf::Document,
        mesh: &gltf::Mesh,
        deformation: Deformation,
    ) -> Result<Vec<usize>, LoadError> {
        let mut ours = Vec::new();
        for primitive in mesh.primitives() {
            if let Some(m) = self.convert_primitive(document, mesh, &primitive, deformation)? {
                ours.push(self.builder.add_full_mesh(m));
            }
        }
        Ok(ours)
    }
}

/// A node's transform relative to its parent, with animated values in place of stored ones.
fn local_transform(node: &gltf::Node, pose: &Pose) -> Mat4 {
    let i = node.index();
    let animated = pose.translation.contains_key(&i)
        || pose.rotation.contains_key(&i)
        || pose.scale.contains_key(&i);
    if !animated {
        return Mat4::from_cols_array_2d(&node.transform().matrix());
    }
    let (t, r, s) = node.transform().decomposed();
    Mat4::from_scale_rotation_translation(
        pose.scale.get(&i).copied().unwrap_or(Vec3::from(s)),
        pose.rotation
            .get(&i)
            .copied()
            .unwrap_or(Quat::from_array(r)),
        pose.translation.get(&i).copied().unwrap_or(Vec3::from(t)),
    )
}
