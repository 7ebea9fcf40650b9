//! Small scenes built in code for integrator tests: quads, an inward-facing box, a UV sphere
//! and a camera on the Z axis.
#![allow(dead_code)]

use glam::{Affine3A, Vec3};
use gridtrace::scene::{Camera, Projection, SceneBuilder};

/// One two-triangle quad; the winding of `corners` sets its front face.
pub fn add_quad(b: &mut SceneBuilder, corners: [Vec3; 4], material: usize) {
    let mesh = b.add_mesh(
        "quad",
        corners.to_vec(),
        vec![[0, 1, 2], [0, 2, 3]],
        material,
    );
    b.add_instance(mesh, Affine3A::IDENTITY, "quad");
}

/// The six faces of the box [-1, 1]³, each wound to face outwards.
pub fn box_faces() -> [[Vec3; 4]; 6] {
    let v = |x: f32, y: f32, z: f32| Vec3::new(x, y, z);
    [
        [
            v(-1., -1., -1.),
            v(1., -1., -1.),
            v(1., -1., 1.),
            v(-1., -1., 1.),
        ],
        [
            v(-1., 1., -1.),
            v(-1., 1., 1.),
            v(1., 1., 1.),
            v(1., 1., -1.),
        ],
        [
            v(-1., -1., -1.),
            v(-1., -1., 1.),
            v(-1., 1., 1.),
            v(-1., 1., -1.),
        ],
        [
            v(1., -1., -1.),
            v(1., 1., -1.),
            v(1., 1., 1.),
            v(1., -1., 1.),
        ],
        [
            v(-1., -1., -1.),
            v(-1., 1., -1.),
            v(1., 1., -1.),
            v(1., -1., -1.),
        ],
        [
            v(-1., -1., 1.),
            v(1., -1., 1.),
            v(1., 1., 1.),
            v(-1., 1., 1.),
        ],
    ]
}

/// The box [-1, 1]³ as six quads facing inwards.
pub fn add_box_inside(b: &mut SceneBuilder, material: usize) {
    for [a, b1, c, d] in box_faces() {
        add_quad(b, [a, d, c, b1], material);
    }
}

/// The box [-1, 1]³ as one closed mesh facing outwards, placed by `transform`.
pub fn add_box_outside(b: &mut SceneBuilder, material: usize, transform: Affine3A) {
    let positions: Vec<Vec3> = box_faces().into_iter().flatten().collect();
    let triangles = (0..6u32)
        .flat_map(|f| [[4 * f, 4 * f + 1, 4 * f + 2], [4 * f, 4 * f + 2, 4 * f + 3]])
        .collect();
    let mesh = b.add_mesh("box", positions, triangles, material);
    b.add_instance(mesh, transform, "box");
}

/// A UV sphere, outward-facing, smooth normals.
pub fn add_sphere(b: &mut SceneBuilder, center: Vec3, radius: f32, material: usize) {
    let (rings, segments) = (16u32, 32u32);
    let mut positions = Vec::new();
    for r in 0..=rings {
        for s in 0..=segments {
            let theta = std::f32::consts::PI * r as f32 / rings as f32;
            let phi = std::f32::consts::TAU * s as f32 / segments as f32;
            positions.push(
                center
                    + radius
                        * Vec3::new(
                            theta.sin() * phi.cos(),
                            theta.cos(),
                            -theta.sin() * phi.sin(),
                        ),
            );
        }
    }
    let mut indices = Vec::new();
    let row = segments + 1;
    for r in 0..rings {
        for s in 0..segments {
            let (a, b2, c, d) = (
                r * row + s,
                (r + 1) * row + s,
                (r + 1) * row + s + 1,
                r * row + s + 1,
            );
            indices.push([a, b2, c]);
            indices.push([a, c, d]);
        }
    }
    let mesh = b.add_mesh("sphere", positions, indices, material);
    b.add_instance(mesh, Affine3A::IDENTITY, "sphere");
}

/// A perspective camera at (0, 0, `z`) looking down −Z.
pub fn camera_at(z: f32, yfov_degrees: f32) -> Camera {
    Camera {
        name: "test".into(),
        world_from_camera: Affine3A::from_translation(Vec3::new(0.0, 0.0, z)),
        projection: Projection::Perspective {
            yfov: yfov_degrees.to_radians(),
            aspect_ratio: None,
        },
        znear: 0.0,
        lens: None,
        focal_length: None,
        shutter: None,
        motion: None,
        source: "test".into(),
    }
}
