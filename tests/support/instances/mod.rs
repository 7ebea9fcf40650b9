//! A field of instances for the top level's tests and benchmark: many copies of one mesh
//! over a ground placed once, and rays over it.

use glam::{Affine3A, Quat, Vec3};
use gridtrace::accel::Ray;
use gridtrace::render::sampling::Rng;
use gridtrace::scene::{Material, Motion, Scene, SceneBuilder};

/// A closed UV sphere of radius 1 as corner positions and triangles.
fn sphere(rings: u32, segments: u32) -> (Vec<Vec3>, Vec<[u32; 3]>) {
    let mut positions = Vec::new();
    for r in 0..=rings {
        for s in 0..segments {
            let theta = std::f32::consts::PI * r as f32 / rings as f32;
            let phi = std::f32::consts::TAU * s as f32 / segments as f32;
            positions.push(Vec3::new(
                theta.sin() * phi.cos(),
                theta.cos(),
                theta.sin() * phi.sin(),
            ));
        }
    }
    let at = |r: u32, s: u32| r * segments + s % segments;
    let mut indices = Vec::new();
    for r in 0..rings {
        for s in 0..segments {
            indices.push([at(r, s), at(r + 1, s), at(r + 1, s + 1)]);
            indices.push([at(r, s), at(r + 1, s + 1), at(r, s + 1)]);
        }
    }
    (positions, indices)
}

/// Half the side of the square a field of `count` instances covers (constant density).
pub fn half_side(count: usize) -> f32 {
    1.5 * (count as f32).sqrt()
}

/// `count` spheres on a jittered lattice over a ground square, of random sizes and
/// orientations (some mirrored), one of them moving over the shutter, plus the ground: a
/// mesh placed once (so its grid is in world space) whose bounds touch every cell.
pub fn field(count: usize, seed: u64) -> Scene {
    let mut rng = Rng::new(seed, 1);
    let mut b = SceneBuilder::new();
    let white = b.add_material(Material::diffuse("white", Vec3::splat(0.5)));
    let (positions, indices) = sphere(6, 12);
    let ball = b.add_mesh("ball", positions, indices, white);
    let h = half_side(count);
    let ground = b.add_mesh(
        "ground",
        vec![
            Vec3::new(-h, 0.0, -h),
            Vec3::new(h, 0.0, -h),
            Vec3::new(h, 0.0, h),
            Vec3::new(-h, 0.0, h),
        ],
        vec![[0, 2, 1], [0, 3, 2]],
        white,
    );
    b.add_instance(ground, Affine3A::IDENTITY, "ground");
    let per_row = (count as f32).sqrt().ceil() as usize;
    for i in 0..count {
        let lattice = Vec3::new((i % per_row) as f32, 0.0, (i / per_row) as f32) * 3.0;
        let jitter = Vec3::new(rng.uniform(), rng.uniform(), rng.uniform()) - 0.5;
        let at = Vec3::new(-h + 1.5, 1.0, -h + 1.5) + lattice + jitter;
        let mirror = if i % 7 == 0 { -1.0 } else { 1.0 };
        let scale = Vec3::new(mirror, 1.0, 1.0) * (0.5 + rng.uniform());
        let turn = Quat::from_euler(
            glam::EulerRot::YXZ,
            6.0 * rng.uniform(),
            rng.uniform(),
            rng.uniform(),
        );
        b.add_instance(
            ball,
            Affine3A::from_scale_rotation_translation(scale, turn, at),
            format!("ball {i}"),
        );
    }
    let mut scene = b.build();
    let last = scene.instances.len() - 1;
    let start = scene.instances[last].world_from_object;
    scene.instances[last].motion = Motion::from_keys(vec![
        start,
        Affine3A::from_translation(Vec3::new(2.0, 0.5, 0.0)) * start,
    ]);
    scene
}

/// Rays over the field: from above it, in every direction (some escape to the sky, some
/// run along the ground), at random shutter times.
pub fn rays(count: usize, n: usize, seed: u64) -> Vec<Ray> {
    let mut rng = Rng::new(seed, 2);
    let h = half_side(count);
    (0..n)
        .map(|_| {
            let origin = Vec3::new(
                (2.0 * rng.uniform() - 1.0) * h,
                0.05 + 4.0 * rng.uniform(),
                (2.0 * rng.uniform() - 1.0) * h,
            );
            let direction = loop {
                let d = Vec3::new(rng.uniform(), rng.uniform(), rng.uniform()) * 2.0 - 1.0;
                if d.length_squared() > 1e-3 && d.length_squared() <= 1.0 {
                    break d.normalize();
                }
            };
            Ray::new(origin, direction).at_time(rng.uniform())
        })
        .collect()
}
