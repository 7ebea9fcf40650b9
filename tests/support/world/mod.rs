//! A loaded scene's geometry in world space, for comparing two loads of the same scene
//! (a rewritten file against its original, a posed file against Blender's evaluation).
#![allow(dead_code)]

use glam::Vec3;
use gridtrace::scene::Scene;

/// Every triangle in world space, corners in file order, triangles sorted.
pub fn world_triangles(scene: &Scene) -> Vec<[[f32; 3]; 3]> {
    let mut triangles: Vec<[[f32; 3]; 3]> = scene
        .instances
        .iter()
        .flat_map(|instance| {
            let mesh = &scene.meshes[instance.mesh];
            mesh.indices.iter().map(move |t| {
                t.map(|v| {
                    instance
                        .world_from_object
                        .transform_point3(mesh.positions[v as usize])
                        .to_array()
                })
            })
        })
        .collect();
    triangles.sort_by(|a, b| a.partial_cmp(b).unwrap());
    triangles
}

/// The triangles of the instances whose source is `source`, in world space, in order.
pub fn source_triangles(scene: &Scene, source: &str) -> Vec<[Vec3; 3]> {
    scene
        .instances
        .iter()
        .filter(|i| i.source == source)
        .flat_map(|inst| {
            let mesh = &scene.meshes[inst.mesh];
            mesh.indices.iter().map(move |t| {
                t.map(|v| {
                    inst.world_from_object
                        .transform_point3(mesh.positions[v as usize])
                })
            })
        })
        .collect()
}

/// The points of every instance of the mesh named `name`, in world space.
pub fn mesh_points(scene: &Scene, name: &str) -> Vec<Vec3> {
    scene
        .instances
        .iter()
        .filter(|i| scene.meshes[i.mesh].name == name)
        .flat_map(|i| {
            scene.meshes[i.mesh]
                .positions
                .iter()
                .map(|&p| i.world_from_object.transform_point3(p))
        })
        .collect()
}

/// Two points equal within 10⁻⁵ in every coordinate.
pub fn close(a: Vec3, b: Vec3) -> bool {
    (a - b).abs().max_element() < 1e-5
}

/// Every corner of every triangle.
pub fn corners(triangles: &[[[f32; 3]; 3]]) -> Vec<Vec3> {
    triangles.iter().flatten().map(|&p| Vec3::from(p)).collect()
}

/// The largest distance from a point of `a` to the nearest point of `b`.
pub fn farthest(a: &[Vec3], b: &[Vec3]) -> f32 {
    a.iter()
        .map(|p| {
            b.iter()
                .map(|q| p.distance(*q))
                .fold(f32::INFINITY, f32::min)
        })
        .fold(0.0, f32::max)
}
