//! What the renderer needs to know about a hit point: position, normals, material.

use glam::{Mat3, Vec3};

use crate::accel::SceneHit;
use crate::scene::Scene;

/// The local geometry at a ray hit, in world space.
#[derive(Clone, Copy, Debug)]
pub struct Surface {
    /// Hit position.
    pub point: Vec3,
    /// Unit geometric normal on the side the mesh's winding calls front.
    pub geometric_normal: Vec3,
    /// Unit interpolated shading normal (not yet turned to any side).
    pub shading_normal: Vec3,
    /// Index into [`Scene::materials`].
    pub material: usize,
}

/// Per-instance data for turning object-space normals into world space.
#[derive(Clone, Copy, Debug)]
pub struct InstanceFrame {
    /// Inverse transpose of the linear part: normals transform by it.
    normal_matrix: Mat3,
}

impl InstanceFrame {
    /// Precomputes the normal matrix of every instance.
    pub fn for_scene(scene: &Scene) -> Vec<InstanceFrame> {
        scene
            .instances
            .iter()
            .map(|inst| InstanceFrame {
                normal_matrix: Mat3::from(inst.world_from_object.matrix3)
                    .inverse()
                    .transpose(),
            })
            .collect()
    }
}

/// The surface at `hit` of a ray with world-space point `point`.
pub fn surface_at(scene: &Scene, frames: &[InstanceFrame], hit: &SceneHit, point: Vec3) -> Surface {
    let inst = &scene.instances[hit.instance as usize];
    let frame = &frames[hit.instance as usize];
    let mesh = &scene.meshes[inst.mesh];
    let [a, b, c] = mesh.indices[hit.triangle as usize].map(|i| i as usize);
    let p = [a, b, c].map(|i| mesh.positions[i]);
    // The object-space face normal through the normal matrix keeps the file's notion of
    // front even under mirroring transforms.
    let geometric = (frame.normal_matrix * (p[1] - p[0]).cross(p[2] - p[0])).normalize_or_zero();
    let w = 1.0 - hit.u - hit.v;
    let interpolated = w * mesh.normals[a] + hit.u * mesh.normals[b] + hit.v * mesh.normals[c];
    let shading = (frame.normal_matrix * interpolated)
        .try_normalize()
        .unwrap_or(geometric);
    Surface {
        point,
        geometric_normal: geometric,
        shading_normal: shading,
        material: mesh.material,
    }
}
