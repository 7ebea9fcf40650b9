//! How much of the view is empty background. A scene lit only by its own emissive
//! surfaces is either an interior those surfaces light (a room, a Cornell box: the camera
//! sees walls everywhere) or an object on nothing whose emitters are details (a product
//! model's headlights, screens or LEDs: the camera sees mostly background). The share of
//! pinhole camera rays that reach nothing tells the two apart. It is found by projecting
//! every triangle onto a coarse grid of ray positions, which needs no acceleration
//! structure: a grid built for this alone added 16 % to the peak memory of a large scene.

use glam::{Vec2, Vec3};

use super::RayGenerator;
use crate::scene::{Camera, Scene};

/// Rays per side of the grid of pixel-centred camera rays the share is measured with.
const GRID: usize = 32;

/// What a `GRID`×`GRID` grid of pinhole camera rays over the image meets, as shares of
/// the rays (alpha and occlusion ignored).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ViewCoverage {
    /// Rays that meet no geometry.
    pub empty: f32,
    /// Rays that meet an emissive triangle and no other.
    pub emitters: f32,
    /// Rays that meet a surface that does not emit.
    pub surfaces: f32,
}

/// Marks of a grid cell: an emissive triangle covers it, a non-emissive one does.
const EMITTER: u8 = 1;
const SURFACE: u8 = 2;

/// What pinhole camera rays over a `width`×`height` image at shutter open meet.
pub fn view_coverage(scene: &Scene, camera: &Camera, width: u32, height: u32) -> ViewCoverage {
    // A GRID×GRID image of the same aspect ratio: its pixel centres are the rays.
    let generator = RayGenerator::new(camera, width, height);
    let scale = Vec2::new(GRID as f32 / width as f32, GRID as f32 / height as f32);
    let camera_from_world = generator.camera_from_world();
    let near = generator.near().max(1e-6);
    let mut covered = vec![0u8; GRID * GRID];
    for instance in &scene.instances {
        let mesh = &scene.meshes[instance.mesh];
        let mark = if scene.materials[mesh.material].is_emissive() {
            EMITTER
        } else {
            SURFACE
        };
        let to_camera = camera_from_world * instance.world_from_object;
        for triangle in &mesh.indices {
            let corners = triangle.map(|i| to_camera.transform_point3(mesh.positions[i as usize]));
            let clipped = in_front(corners, near);
            let image: Vec<Vec2> = clipped
                .iter()
                .map(|&p| generator.image_position(p) * scale)
                .collect();
            for k in 1..image.len().saturating_sub(1) {
                cover([image[0], image[k], image[k + 1]], mark, &mut covered);
            }
        }
    }
    let share = |f: &dyn Fn(u8) -> bool| {
        covered.iter().filter(|&&c| f(c)).count() as f32 / (GRID * GRID) as f32
    };
    ViewCoverage {
        empty: share(&|c| c == 0),
        emitters: share(&|c| c == EMITTER),
        surfaces: share(&|c| c & SURFACE != 0),
    }
}

/// The part of a camera-space triangle in front of the near plane (z < −near), as a
/// polygon of up to four corners (Sutherland–Hodgman against one plane).
fn in_front(corners: [Vec3; 3], near: f32) -> Vec<Vec3> {
    let inside = |p: Vec3| p.z < -near;
    let mut out = Vec::with_capacity(4);
    for i in 0..3 {
        let (a, b) = (corners[i], corners[(i + 1) % 3]);
        if inside(a) {
            out.push(a);
        }
        if inside(a) != inside(b) {
            let t = (-near - a.z) / (b.z - a.z);
            out.push(a + t * (b - a));
        }
    }
    out
}

/// Marks the grid cells whose centres the image-space triangle covers (edges included,
/// either winding).
fn cover(t: [Vec2; 3], mark: u8, covered: &mut [u8]) {
    if t.iter().any(|p| !p.is_finite()) {
        return;
    }
    let edge = |a: Vec2, b: Vec2, p: Vec2| (b - a).perp_dot(p - a);
    let area = edge(t[0], t[1], t[2]);
    if area == 0.0 {
        return;
    }
    let min = t[0].min(t[1]).min(t[2]);
    let max = t[0].max(t[1]).max(t[2]);
    let first = |v: f32| (v - 0.5).ceil().clamp(0.0, GRID as f32) as usize;
    let last = |v: f32| ((v - 0.5).floor() + 1.0).clamp(0.0, GRID as f32) as usize;
    for j in first(min.y)..last(max.y) {
        for i in first(min.x)..last(max.x) {
            let p = Vec2::new(i as f32 + 0.5, j as f32 + 0.5);
            let w = [
                edge(t[1], t[2], p),
                edge(t[2], t[0], p),
                edge(t[0], t[1], p),
            ];
            if w.iter().all(|&w| w * area >= 0.0) {
                covered[j * GRID + i] |= mark;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::accel::{SceneAccel, TopLevel};
    use crate::scene::{Material, Projection, SceneBuilder};
    use glam::{Affine3A, Vec3};

    /// The projected coverage is what tracing the same rays finds, for a quad that fills
    /// part of the view and one that crosses the camera's plane.
    #[test]
    fn projected_coverage_matches_traced_rays() {
        let mut b = SceneBuilder::new();
        let m = b.add_material(Material::diffuse("grey", Vec3::splat(0.5)));
        let quad = |b: &mut SceneBuilder, c: [Vec3; 4]| {
            let mesh = b.add_mesh(
                "quad".to_string(),
                c.to_vec(),
                vec![[0, 1, 2], [0, 2, 3]],
                m,
            );
            b.add_instance(mesh, Affine3A::IDENTITY, "quad".to_string());
        };
        quad(
            &mut b,
            [
                Vec3::new(-1.0, -0.5, -4.0),
                Vec3::new(0.7, -0.5, -4.0),
                Vec3::new(0.7, 0.8, -4.0),
                Vec3::new(-1.0, 0.8, -4.0),
            ],
        );
        // A floor running from behind the camera to far in front of it.
        quad(
            &mut b,
            [
                Vec3::new(-5.0, -1.0, 3.0),
                Vec3::new(5.0, -1.0, 3.0),
                Vec3::new(5.0, -1.0, -30.0),
                Vec3::new(-5.0, -1.0, -30.0),
            ],
        );
        let scene = b.build();
        let camera = Camera {
            name: "test".into(),
            world_from_camera: Affine3A::IDENTITY,
            projection: Projection::Perspective {
                yfov: 0.9,
                aspect_ratio: None,
            },
            znear: 0.01,
            lens: None,
            focal_length: None,
            shutter: None,
            motion: None,
            source: "test".into(),
        };
        let (width, height) = (320, 200);
        let accel = SceneAccel::build_with(&scene, TopLevel::Automatic);
        let generator = RayGenerator::new(&camera, width, height);
        let mut empty = 0;
        for j in 0..GRID {
            for i in 0..GRID {
                let x = (i as f32 + 0.5) / GRID as f32 * width as f32;
                let y = (j as f32 + 0.5) / GRID as f32 * height as f32;
                if accel.intersect(&generator.generate(x, y)).is_none() {
                    empty += 1;
                }
            }
        }
        let traced = empty as f32 / (GRID * GRID) as f32;
        let projected = view_coverage(&scene, &camera, width, height).empty;
        assert!(traced > 0.1 && traced < 0.9, "{traced}");
        assert!(
            (projected - traced).abs() <= 2.0 / (GRID * GRID) as f32,
            "{projected} vs {traced}"
        );
    }
}
