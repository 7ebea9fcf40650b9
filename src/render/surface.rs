//! What the renderer needs to know about a hit point: position with its rounding-error
//! bound, normals, material; and how to start new rays from it without hitting it again.

use glam::{Affine3A, Mat3, Mat3A, Vec3, Vec3A};

use crate::accel::SceneHit;
use crate::geometry::{interpolate_with_error, transform_points_with_error};
use crate::scene::Scene;

/// The local geometry at a ray hit, in world space.
#[derive(Clone, Copy, Debug)]
pub struct Surface {
    /// Hit position, interpolated from the triangle's world-space corners.
    pub point: Vec3,
    /// Bound on the absolute rounding error of `point`, per axis.
    pub point_error: Vec3,
    /// Unit geometric normal on the side the mesh's winding calls front.
    pub geometric_normal: Vec3,
    /// Unit interpolated shading normal (not yet turned to any side).
    pub shading_normal: Vec3,
    /// Index into [`Scene::materials`].
    pub material: usize,
    /// Index into [`Scene::instances`].
    pub instance: usize,
    /// The triangle's vertex indices in its mesh.
    pub vertices: [usize; 3],
    /// Barycentric weights of `vertices` at the hit.
    pub barycentrics: Vec3,
    /// Shutter time of the path that found it: the rays it spawns see the scene then too.
    pub time: f32,
}

/// Per-instance data for turning object-space geometry into world space.
#[derive(Clone, Copy, Debug)]
pub struct InstanceFrame {
    pub(super) world_from_object: Affine3A,
    /// Inverse transpose of the linear part: normals transform by it (in SIMD lanes).
    normal_matrix: Mat3A,
}

impl InstanceFrame {
    /// The frame of an instance placed by `world_from_object`.
    pub fn new(world_from_object: Affine3A) -> InstanceFrame {
        InstanceFrame {
            world_from_object,
            normal_matrix: Mat3A::from(Mat3::from(world_from_object.matrix3).inverse().transpose()),
        }
    }

    /// Precomputes the frame of every instance (at the frame's instant for moving ones,
    /// which [`surface_at`] places at each hit's time instead).
    pub fn for_scene(scene: &Scene) -> Vec<InstanceFrame> {
        scene
            .instances
            .iter()
            .map(|inst| InstanceFrame::new(inst.world_from_object))
            .collect()
    }
}

/// The surface at `hit`.
pub fn surface_at(scene: &Scene, frames: &[InstanceFrame], hit: &SceneHit) -> Surface {
    let inst = &scene.instances[hit.instance as usize];
    let moved;
    let frame = match &inst.motion {
        None => &frames[hit.instance as usize],
        Some(motion) => {
            moved = InstanceFrame::new(motion.at(hit.time));
            &moved
        }
    };
    let mesh = &scene.meshes[inst.mesh];
    let [a, b, c] = mesh.indices[hit.triangle as usize].map(|i| i as usize);
    let p = [a, b, c].map(|i| mesh.positions[i]);
    // The object-space face normal through the normal matrix keeps the file's notion of
    // front even under mirroring transforms.
    // (`Vec3A`: the same operations as `Vec3` in SIMD lanes.)
    let [p0, p1, p2] = p.map(Vec3A::from);
    let geometric = (frame.normal_matrix * (p1 - p0).cross(p2 - p0)).normalize_or_zero();
    let w = 1.0 - hit.u - hit.v;
    let corners = transform_points_with_error(&frame.world_from_object, p);
    let (point, point_error) = interpolate_with_error(corners, [w, hit.u, hit.v]);
    let shading = if mesh.normals.is_empty() {
        geometric
    } else {
        let [na, nb, nc] = [a, b, c].map(|i| Vec3A::from(mesh.normals[i]));
        let interpolated = w * na + hit.u * nb + hit.v * nc;
        (frame.normal_matrix * interpolated)
            .try_normalize()
            .unwrap_or(geometric)
    };
    Surface {
        point,
        point_error,
        geometric_normal: geometric.into(),
        shading_normal: shading.into(),
        material: mesh.material,
        instance: hit.instance as usize,
        vertices: [a, b, c],
        barycentrics: Vec3::new(w, hit.u, hit.v),
        time: hit.time,
    }
}
